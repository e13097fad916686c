"""``kinelab bench --first-call``: a process's first ``solve``, ``solve_batch`` and ``solve_all`` against later ones.

Each measurement is a new process, as a user's script meets it: ``kinelab.load(robot)`` (which readies the default
calls, :mod:`kinelab.wholebody.ready`), then the entry point's first call on a seeded random target, then 20 more
calls on other targets. A round runs every (robot, entry point) once, in an order turned by one place each round;
the first round warms the file caches and the byte code and is not counted. Per row: the first call's median over
the rounds [ms] and its range, the later calls' median, and the goal — first ≤ 2 × later + 5 ms — met in how many
rounds. The load's own time is reported beside it (with ``prepare=False`` too): the one-off work moved there, not
removed.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
from typing import Any

from kinelab.errors import KinelabError

ROBOTS = ("ur5", "panda")
ENTRIES = ("solve", "solve_batch", "solve_all")
LATER = 20  # later calls per process

_SCRIPT = r"""
import json, sys, time
import numpy as np
import kinelab
name, entry, prepare = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
t0 = time.perf_counter()
arm = kinelab.load(name, prepare=prepare)
load = time.perf_counter() - t0
qs = arm.random_qs(LATER + 1, np.random.default_rng(71))
targets = [arm.fk(q) for q in qs]
calls = {"solve": lambda t: kinelab.solve(arm, t, seed=0),
         "solve_batch": lambda t: kinelab.solve_batch(arm, [t] * 8, seed=0),
         "solve_all": lambda t: kinelab.solve_all(arm, t, seed=0)}
call = calls[entry]
seconds = []
for t in targets:
    t0 = time.perf_counter()
    call(t)
    seconds.append(time.perf_counter() - t0)
print(json.dumps({"load": load, "first": seconds[0], "later": seconds[1:]}))
""".replace("LATER", str(LATER))


def _one(robot: str, entry: str, prepare: bool, env: dict[str, str]) -> dict[str, Any]:
    """One fresh process's times [s]."""
    done = subprocess.run([sys.executable, "-c", _SCRIPT, robot, entry, "1" if prepare else "0"],
                          capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        raise KinelabError(f"bench --first-call: {robot} {entry} exited with {done.returncode}: "
                           f"{done.stderr.strip()[-200:]}")
    found: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return found


def run(robots: list[str] | None = None, rounds: int = 5) -> dict[str, Any]:
    """Every (robot, entry point)'s first and later calls over ``rounds`` counted rounds of fresh processes, each
    with ``kinelab.load``'s preparation and without it."""
    cases = [(r, e, p) for r in (robots or ROBOTS) for e in ENTRIES for p in (True, False)]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as an installed kinelab runs
    seen: dict[tuple[str, str, bool], list[dict[str, Any]]] = {c: [] for c in cases}
    for r in range(max(rounds, 1) + 1):
        order = cases[r % len(cases):] + cases[:r % len(cases)]
        for case in order:
            found = _one(*case, env)
            if r > 0:
                seen[case].append(found)
    return {"rounds": max(rounds, 1), "later_calls": LATER, "rows": [_row(c, seen[c]) for c in cases]}


def _row(case: tuple[str, str, bool], runs: list[dict[str, Any]]) -> dict[str, Any]:
    """One row's figures [ms] over its rounds."""
    robot, entry, prepare = case
    firsts = [1e3 * x["first"] for x in runs]
    laters = [1e3 * statistics.median(x["later"]) for x in runs]
    met = sum(f <= 2 * later + 5 for f, later in zip(firsts, laters, strict=True))
    return {"robot": robot, "entry": entry, "prepare": prepare, "first_ms": statistics.median(firsts),
            "first_low": min(firsts), "first_high": max(firsts), "later_ms": statistics.median(laters),
            "load_ms": statistics.median(1e3 * x["load"] for x in runs), "met": met, "rounds": len(runs)}


def markdown(result: dict[str, Any]) -> str:
    """The table: per robot, entry point and load setting, the first call against the later ones and the goal."""
    lines = [f"First call of a process, {result['rounds']} rounds of fresh processes (median, range); later: the "
             f"median of {result['later_calls']} calls; goal: first ≤ 2 × later + 5 ms.", "",
             "| robot | call | load | load time | first call | later call | goal met |",
             "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        load = "kinelab.load" if r["prepare"] else "prepare=False"
        lines.append(f"| {r['robot']} | {r['entry']} | {load} | {r['load_ms']:.0f} ms | {r['first_ms']:.1f} ms "
                     f"({r['first_low']:.1f}–{r['first_high']:.1f}) | {r['later_ms']:.2f} ms | "
                     f"{r['met']}/{r['rounds']} rounds |")
    return "\n".join(lines)
