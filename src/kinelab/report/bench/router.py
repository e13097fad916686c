"""``kinelab bench --router``: the prepared solver against the module function, side by side.

``kinelab.solve_batch``, ``solve_all`` and ``track`` are calls on a prepared ``kinelab.IK`` kept on the robot; a
user who builds the ``IK`` once calls the same route without the lookup. Per robot, solver and entry point, both
run the same problems with the same seeds: in each round every problem runs through both, the order turned each
round (function first, then the prepared solver first). A round's ratio is the function's median time per problem
over the prepared solver's: the prepared solver's throughput as a multiple of the function's. The goal: at least
0.95× in every round.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
from tqdm import tqdm

from kinelab.errors import KinelabError
from kinelab.ik.api import solve_all, solve_batch, track
from kinelab.ik.prepared import IK
from kinelab.report.bench.protocol import path_set
from kinelab.robot import Chain, load

ROBOTS = ("ur5", "panda", "kinova", "crx10ia", "era")
GOAL = 0.95  # the prepared solver's throughput over the function's, in every round
BATCH = 256  # targets per solve_batch problem
PROBLEMS = 8  # problems per entry point and round
ALL_BUDGET = 0.05  # [s] solve_all's multistart (its default)
REDUNDANCY = 16  # a 7R arm's solve_all with solver "analytic": every branch at this many values of its swept joint
Call = Callable[[Any, int], Any]  # a problem and a seed → an answer


def _solvers(robot: Chain) -> list[str]:
    """Every solver: FRDM, the biquaternion solver, DLS, the closed form where the robot has one, and "auto"."""
    try:
        IK(robot, solver="analytic")
    except KinelabError:
        return ["frdm", "biquat", "dls", "auto"]
    return ["frdm", "biquat", "dls", "analytic", "auto"]


def _problems(robot: Chain, seed: int) -> dict[str, list[Any]]:
    """Per entry point, its problems: batches of targets, single targets, paths of 100 tool poses (with the joint
    path's first configuration, where each starts)."""
    rng = np.random.default_rng(seed)
    poses = [robot.fk(q) for q in robot.random_qs(PROBLEMS * (BATCH + 1), rng)]
    batches = [np.stack([p.homogeneous for p in poses[k * BATCH:(k + 1) * BATCH]]) for k in range(PROBLEMS)]
    paths = [(path[0], [robot.fk(q) for q in path]) for path in path_set(robot, seed, PROBLEMS, samples=100)]
    return {"solve_batch": batches, "solve_all": poses[-PROBLEMS:], "track": paths}  # a path: (its start, its poses)


def _pairs(robot: Chain, solver: str) -> dict[str, tuple[Call, Call]]:
    """Per entry point: (the module function, the prepared solver's method), each called as (problem, seed)."""
    batch_ik = IK(robot, solver=solver, time_budget=None, start_outside_limits="refuse")
    all_ik = IK(robot, solver=solver, time_budget=ALL_BUDGET)
    swept = REDUNDANCY if solver == "analytic" and robot.n == 7 else None  # a 7R arm's closed form sweeps a joint
    pairs: dict[str, tuple[Call, Call]] = {
        "solve_batch": (lambda T, s: solve_batch(robot, T, solver=solver, seed=s),
                        lambda T, s: batch_ik.solve_batch(T, seed=s)),
        "solve_all": (lambda T, s: solve_all(robot, T, solver=solver, seed=s, time_budget=ALL_BUDGET,
                                             redundancy=swept),
                      lambda T, s: all_ik.solve_all(T, seed=s, redundancy=swept))}
    if solver == "frdm":
        path_ik = IK(robot, time_budget=None)
        pairs["track"] = (lambda P, s: track(robot, P[1], q0=P[0], seed=s),
                          lambda P, s: path_ik.track(P[1], q0=P[0], seed=s))
    return pairs


def _ratios(problems: list[Any], pair: tuple[Call, Call], repeats: int) -> list[float]:
    """Per round: the function's median time per problem over the prepared solver's."""
    for call in pair:  # first calls build what is kept (not timed)
        call(problems[0], 0)
    out = []
    for r in range(repeats):
        times: tuple[list[float], list[float]] = ([], [])
        for k, problem in enumerate(problems):
            for which in ((0, 1) if r % 2 == 0 else (1, 0)):
                t0 = time.perf_counter()
                pair[which](problem, r * len(problems) + k)
                times[which].append(time.perf_counter() - t0)
        out.append(float(np.median(times[0]) / np.median(times[1])))
    return out


def run(robots: list[str] | None = None, seed: int = 0, repeats: int = 5,
        progress: bool = False) -> list[dict[str, Any]]:
    """One row per (robot, solver, entry point): the ratios' median and spread over ``repeats`` rounds (≥ 2), with
    a progress bar per robot when ``progress``."""
    rows = []
    for name in tqdm(robots or ROBOTS, desc="bench --router", disable=not progress):
        robot = load(name)
        problems = _problems(robot, seed)
        for solver in _solvers(robot):
            for entry, pair in _pairs(robot, solver).items():
                ratios = _ratios(problems[entry], pair, max(repeats, 2))
                rows.append({"robot": name, "solver": solver, "entry": entry, "ratio": float(np.median(ratios)),
                             "lowest": min(ratios), "highest": max(ratios)})
    return rows


def markdown(rows: list[dict[str, Any]]) -> str:
    """The table: the prepared solver's throughput over the function's, median and spread, and the verdict (met when
    every round is at least the goal)."""
    lines = [f"Prepared solver against the module function (throughput ratio, goal ≥ {GOAL}× in every round):", "",
             "| robot | solver | entry point | ratio (median) | rounds | goal |", "|---|---|---|---|---|---|"]
    for r in rows:
        verdict = "met" if r["lowest"] >= GOAL else ("median met" if r["ratio"] >= GOAL else "missed")
        lines.append(f"| {r['robot']} | {r['solver']} | {r['entry']} | {r['ratio']:.2f}× | "
                     f"{r['lowest']:.2f}–{r['highest']:.2f}× | {verdict} |")
    return "\n".join(lines)
