"""``kinelab bench --standing-solve``: the converged whole-body solve from where a humanoid stands.

Per humanoid — TALOS from its SRDF's half-sitting, G1 from its file's keyframe, iCub and Romeo (Romeo used in no
tuning; its fingers are 22 folded mimic joints) from ``robot.standing()`` — ``--n`` targets, each the hands' and
feet's placements and the centre of mass of a seeded random configuration (its base where :meth:`random_q` puts
it, not the start's), solved by :func:`kinelab.solve` from the standing pose with a posture at weight 1e-6 and a
1 s budget, judged by Pinocchio (1e-6 m, 1e-6 rad).
Per robot: the share met, the share met without a random restart (the answer continuous with the start), the
median and 95th-percentile time, and how the misses ended.
"""

from __future__ import annotations

import time
from collections import Counter
from typing import Any

import numpy as np
from tqdm import tqdm

from kinelab.report.bench.steppers import SCENARIOS, Scenario, whole
from kinelab.wholebody.api import solve
from kinelab.wholebody.tasks import ComTask, FrameTask, PostureTask, Task

HUMANOIDS = {"talos": SCENARIOS["talos"], "g1": SCENARIOS["g1"],
             "icub": Scenario("icub", ("l_hand", "r_hand"), ("l_sole", "r_sole"), True),
             "romeo": Scenario("romeo", ("LWristYawLink", "RWristYawLink"), ("l_sole", "r_sole"), True)}
BUDGET = 1.0  # [s] per target


def run(robots: list[str] | None = None, count: int = 200, seed: int = 0, progress: bool = False) -> dict[str, Any]:
    """Every humanoid's figures on ``count`` targets (see the module's docstring)."""
    names = [r for r in (robots or list(HUMANOIDS)) if r in HUMANOIDS] or list(HUMANOIDS)
    return {"budget_s": BUDGET, "rows": [_robot(name, count, seed, progress) for name in names]}


def _robot(name: str, count: int, seed: int, progress: bool) -> dict[str, Any]:
    """One humanoid's row."""
    scenario, robot = HUMANOIDS[name], whole(HUMANOIDS[name].robot)
    frames = scenario.moving + scenario.held
    start = robot.standing()
    rng = np.random.default_rng(seed)
    met, continuous, seconds = 0, 0, []
    misses: Counter[str] = Counter()
    for k in tqdm(range(count), desc=f"standing {name}", disable=not progress, unit="target"):
        q_true = robot.random_q(rng)
        tasks: list[Task] = [FrameTask(f, M) for f, M in zip(frames, robot.frame_placements(q_true, frames),
                                                              strict=True)]
        tasks += ([ComTask(robot.com(q_true))] if scenario.com else []) + [PostureTask(start, weight=1e-6)]
        t0 = time.perf_counter()
        res = solve(robot, tasks, q0=start, seed=seed + k, time_budget=BUDGET)
        seconds.append(time.perf_counter() - t0)
        met += bool(res.success)
        continuous += bool(res.success) and res.restarts == 0
        if not res.success:
            misses[res.status.value] += 1
    return {"robot": name, "targets": count, "met_pct": 100.0 * met / count,
            "without_restart_pct": 100.0 * continuous / count, "median_ms": 1e3 * float(np.median(seconds)),
            "p95_ms": 1e3 * float(np.percentile(seconds, 95)), "misses": dict(misses)}


def markdown(result: dict[str, Any]) -> str:
    """The table, with the goals: ≥ 99.9 % met, median ≤ 20 ms, ≥ 95 % without a restart."""
    lines = [f"The converged solve from where each humanoid stands, {result['budget_s']:g} s budget a target; goals: "
             "≥ 99.9 % met, median ≤ 20 ms, ≥ 95 % met without a restart.", "",
             "| robot | targets | met | met without a restart | median | p95 | misses |",
             "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        misses = ", ".join(f"{k} {v}" for k, v in r["misses"].items()) or "none"
        lines.append(f"| {r['robot']} | {r['targets']} | {r['met_pct']:.1f} % | {r['without_restart_pct']:.1f} % | "
                     f"{r['median_ms']:.0f} ms | {r['p95_ms']:.0f} ms | {misses} |")
    return "\n".join(lines)
