"""``kinelab bench --startup``: how long a command takes from the shell, against ``python -c "import pinocchio"``.

Each command runs as a user runs it: the ``kinelab`` script installed beside this Python (else ``python -m
kinelab.cli``), a new process each time, its output discarded. A round runs the Pinocchio import and every command
once, in an order turned by one place each round (no command always follows the same one); the first round warms
the file caches (and writes the byte code a fresh install has not compiled yet) and is not counted. Per command:
its best time [ms] over the rounds, the ratio of that best to the import's best, the ratio of the medians, and
the spread of the per-round ratios (each round's command over the same round's import). The goals: ``--help``,
``robots`` and ``fk`` within 1.3× the import, ``ik`` and ``info`` within 1.6×.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from kinelab.errors import KinelabError

UR5_Q = ("0", "-1.57", "1.57", "0", "0", "0")
COMMANDS = (  # (name, arguments, goal: at most this times the import)
    ("kinelab --help", ("--help",), 1.3),
    ("kinelab robots", ("robots",), 1.3),
    ("kinelab fk ur5 Q", ("fk", "ur5", *UR5_Q), 1.3),
    ("kinelab info ur5", ("info", "ur5"), 1.6),
    ("kinelab ik ur5 --target-q Q", ("ik", "ur5", "--target-q", *UR5_Q), 1.6),
)
BASELINE = 'python -c "import pinocchio"'


def _kinelab() -> list[str]:
    """How the shell runs kinelab here: the installed script, else the module."""
    script = Path(sys.executable).with_name("kinelab")
    return [str(script)] if script.exists() else [sys.executable, "-m", "kinelab.cli"]


def _seconds(argv: list[str], env: dict[str, str]) -> float:
    """One run's wall time [s]; a command that fails is an error (its time would mean nothing)."""
    t0 = time.perf_counter()
    done = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, check=False)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise KinelabError(f"bench --startup: {' '.join(argv)} exited with {done.returncode}: "
                           f"{done.stderr.decode(errors='replace').strip()[-200:]}")
    return seconds


def run(rounds: int = 7) -> dict[str, Any]:
    """Every command's best time and ratios to the import over ``rounds`` counted rounds (≥ 2)."""
    kinelab = _kinelab()
    runs = [(BASELINE, [sys.executable, "-c", "import pinocchio"])] + \
        [(name, kinelab + list(args)) for name, args, _ in COMMANDS]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as an installed kinelab runs
    times: dict[str, list[float]] = {name: [] for name, _ in runs}
    for r in range(max(rounds, 2) + 1):
        order = runs[r % len(runs):] + runs[:r % len(runs)]
        for name, argv in order:
            seconds = _seconds(argv, env)
            if r > 0:
                times[name].append(seconds)
    base = times[BASELINE]
    rows = []
    for name, _, goal in COMMANDS:
        ratios = [t / b for t, b in zip(times[name], base, strict=True)]
        rows.append({"command": name, "best_ms": 1e3 * min(times[name]), "ratio": min(times[name]) / min(base),
                     "median_ratio": statistics.median(times[name]) / statistics.median(base),
                     "lowest": min(ratios), "highest": max(ratios), "goal": goal})
    return {"baseline": BASELINE, "baseline_ms": 1e3 * min(base), "rounds": len(base), "commands": rows}


def markdown(result: dict[str, Any]) -> str:
    """The table: best time, best over best, median over median, the per-round ratios' spread, and the goal: "met"
    where every round meets it, "best and median met" or "best met" where only those do, else "missed"."""
    lines = [f"Start-up, best of {result['rounds']} rounds; {result['baseline']}: {result['baseline_ms']:.0f} ms.",
             "", "| command | best | best / import's best | median / import's median | per round | goal |",
             "|---|---|---|---|---|---|"]
    for r in result["commands"]:
        median = r.get("median_ratio", float("nan"))
        verdict = "met" if r["highest"] <= r["goal"] else ("missed" if r["ratio"] > r["goal"] else
                                                          "best and median met" if median <= r["goal"] else "best met")
        lines.append(f"| `{r['command']}` | {r['best_ms']:.0f} ms | {r['ratio']:.2f}× | {median:.2f}× | "
                     f"{r['lowest']:.2f}–{r['highest']:.2f}× | ≤ {r['goal']}× ({verdict}) |")
    return "\n".join(lines)
