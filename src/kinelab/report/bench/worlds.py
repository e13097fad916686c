"""``kinelab bench --worlds``: many worlds a step (``WholeBody.step_batch``), steps per second.

The whole-body bench's scenarios (:mod:`kinelab.report.bench.steppers`): the Panda's tool with a posture (1,024
worlds), G1's two hands and two feet with the centre of mass and a posture (256 worlds); pink's costs squared as
kinelab's weights, position and velocity limits (the file's), DAQP. Every world starts at the bench's start and has
its own targets: each moving frame's start pose shifted by a seeded uniform offset of up to 5 cm per axis. A round
is 20 calls of ``step_batch`` at dt = 5 ms, each from the last call's answers; steps per second = worlds × calls /
the round's wall time. Beside it, the same problem's single ``WholeBody.step`` in a Python loop over one world, the
rate a user gets without the batch. Worlds whose QP did not solve are counted.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from kinelab.errors import KinelabError
from kinelab.report.bench.steppers import POSTURE_COST, SCENARIOS, start_of, whole
from kinelab.wholebody import ComTask, FrameTask, PostureTask, WholeBody

WORLDS = {"panda": 1024, "g1": 256}
CALLS = 20
DT = 0.005


def problem(name: str) -> tuple[WholeBody, list[tuple[FrameTask, np.ndarray]], np.ndarray]:
    """The scenario's prepared problem, each moving frame's per-world targets, the worlds' start rows."""
    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    q0, n = start_of(robot), WORLDS[name]
    frames = [FrameTask(f, robot.frame_placement(q0, f)) for f in scenario.moving + scenario.held]
    tasks: list[Any] = [*frames, *([ComTask(robot.com(q0))] if scenario.com else []),
                        PostureTask(q0, weight=POSTURE_COST ** 2)]
    rng = np.random.default_rng(0)
    moving = []
    for task in frames[:len(scenario.moving)]:
        H = np.repeat(task.target.homogeneous[None], n, axis=0)
        H[:, :3, 3] += rng.uniform(-0.05, 0.05, (n, 3))
        moving.append((task, H))
    return WholeBody(robot, tasks), moving, np.repeat(q0[None], n, axis=0)


def run(robots: list[str] | None = None, rounds: int = 3) -> dict[str, Any]:
    """Steps per second of every scenario, per round.

    Raises:
        KinelabError: a robot without a scenario here (the valid names listed).
    """
    names = list(robots or WORLDS)
    unknown = [n for n in names if n not in WORLDS]
    if unknown:
        raise KinelabError(f"no worlds scenario for {unknown[0]!r}; the scenarios: {', '.join(WORLDS)}")
    rows = [_measure(name, rounds) for name in names]
    return {"rows": rows, "protocol": {"calls": CALLS, "dt_s": DT, "rounds": rounds, "worlds": WORLDS}}


def _measure(name: str, rounds: int) -> dict[str, Any]:
    """One scenario: each round's batched rate and the single-step loop's, interleaved round by round."""
    prob, moving, Q0 = problem(name)
    prob.step_batch(Q0, DT, targets=moving)  # the threads and their trees made before the clock runs
    batched, single, unsolved = [], [], 0
    for _ in range(rounds):
        Q, t0 = Q0, time.perf_counter()
        for _ in range(CALLS):
            res = prob.step_batch(Q, DT, targets=moving)
            Q, unsolved = res.q, unsolved + int((~res.solved).sum())
        batched.append(CALLS * Q0.shape[0] / (time.perf_counter() - t0))
        q, t0 = Q0[0], time.perf_counter()
        for _ in range(CALLS * 10):
            q = prob.step(q, DT).q
        single.append(CALLS * 10 / (time.perf_counter() - t0))
    return {"robot": name, "worlds": int(Q0.shape[0]), "compiled": prob.compiled,
            "steps_per_s": float(np.median(batched)), "lowest": float(min(batched)), "highest": float(max(batched)),
            "single_loop_per_s": float(np.median(single)), "unsolved": unsolved}


def markdown(result: dict[str, Any]) -> str:
    """The table."""
    lines = ["| robot | worlds | steps/s (median of rounds) | spread | one world in a Python loop | unsolved |",
             "|---|---:|---:|---|---:|---:|"]
    for r in result["rows"]:
        lines.append(f"| {r['robot']} | {r['worlds']} | {r['steps_per_s']:,.0f} | {r['lowest']:,.0f}–"
                     f"{r['highest']:,.0f} | {r['single_loop_per_s']:,.0f}/s | {r['unsolved']} |")
    return "\n".join(lines)
