"""CI's bench job: the bench extra's requirements, and a short bench run that must show every peer's row.

    python tools/bench_peers.py requirements   # the bench extra, one requirement a line (for pip install)
    python tools/bench_peers.py check          # the arm bench (ur5, panda) and the whole-body bench (panda)

``check`` exits 1 naming each peer whose row is missing: a peer that is installed is in the table, or the bench
failed (exit ≠ 0) with its reason; "Not run" is only for a peer that does not take the task.
"""

import json
import subprocess
import sys
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
ARM_PEERS = ("rtb-ik_LM", "trac-ik", "ikpy", "pink")
WHOLE_BODY_PEERS = ("kinelab", "pink", "mink")


def requirements() -> list[str]:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["bench"]


def bench(*words: str) -> dict:
    kinelab = Path(sys.executable).with_name("kinelab")
    out = subprocess.run([str(kinelab), "bench", *words, "--json"], capture_output=True, text=True, timeout=1800)
    if out.returncode != 0:
        sys.exit(f"kinelab bench {' '.join(words)} exited {out.returncode}: {out.stderr.strip()[-600:]}")
    return json.loads(out.stdout)


def check() -> int:
    arm = bench("--robots", "ur5", "panda", "--n", "5", "--repeats", "1")
    rows = {(r["robot"], r["solver"]) for r in arm["rows"]}
    missing = [f"{peer} on {robot}" for robot in ("ur5", "panda") for peer in ARM_PEERS if (robot, peer) not in rows]
    whole = bench("--whole-body", "--robots", "panda", "--n", "2", "--repeats", "1")["whole_body"]
    libraries = {r["library"] for r in whole["steps"]}
    missing += [f"{peer}'s whole-body step" for peer in WHOLE_BODY_PEERS if peer not in libraries]
    if missing:
        print(f"bench rows missing: {'; '.join(missing)} (not run: {arm['not_run']} {whole.get('not_run')})")
        return 1
    print(f"bench: every peer's row is there ({len(arm['rows'])} arm rows, {len(whole['steps'])} whole-body rows)")
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["requirements"]:
        print("\n".join(requirements()))
    elif sys.argv[1:] == ["check"]:
        sys.exit(check())
    else:
        sys.exit(__doc__)
