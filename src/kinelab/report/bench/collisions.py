"""``kinelab bench --collisions``: what leaving collisions on costs, and how often it matters.

Per arm (panda, ur5, kinova by default), around a floor and a table (:data:`FLOOR_AND_TABLE`): n targets, each
the FK of a random configuration clear of both and of the arm itself. Each target goes to ``solve`` without and
with ``collisions=``, interleaved and blocked rounds alternating (:func:`kinelab.report.bench.protocol.rounds`),
seeds changing with the round. Figures: the median time per call of each (median over rounds, the spread
lowest–highest round) and their ratio; how many answers of the plain solve collide; how many targets the
collision-aware solve reaches clear; and the check's own cost per configuration (random configurations, and
clear ones).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.collision import Collisions, Environment, Obstacle, collision_model
from kinelab.ik.api import solve
from kinelab.report.bench.protocol import figures, warmed_rounds
from kinelab.robot import Chain, load

ROBOTS = ("panda", "ur5", "kinova")
FLOOR_AND_TABLE = Environment((Obstacle("plane", name="floor"),
                               Obstacle("box", size=(0.6, 0.8, 0.05), xyz=(0.5, 0.0, 0.2), name="table")))


def arm(robot: Chain, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """One arm's row (see the module's docstring)."""
    model = collision_model(robot, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(seed)
    configurations = [robot.random_q(rng) for _ in range(max(20 * n, 2000))]
    clear = [q for q in configurations if model.colliding_pair(q) is None]
    targets = [robot.fk(q) for q in clear[:n]]
    calls = {"plain": lambda t, s: solve(robot, t, solver="frdm", seed=s, time_budget=0.5),
             "collisions": lambda t, s: solve(robot, t, solver="frdm", seed=s, time_budget=0.5,
                                              collisions=FLOOR_AND_TABLE)}
    medians = warmed_rounds(targets, calls, repeats)
    ratio = [c / p for c, p in zip(medians["collisions"], medians["plain"], strict=True)]
    return {"robot": robot.name, "targets": len(targets), "pairs": len(model.pairs),
            "random_colliding": 1 - len(clear) / len(configurations),
            **figures(medians), "ratio": float(np.median(ratio)), "ratio_spread": (min(ratio), max(ratio)),
            **_answers(robot, model, targets, seed),
            "check_us": _check_cost(model, configurations[:1000]), "check_clear_us": _check_cost(model, clear[:1000])}


def _answers(robot: Chain, model: Any, targets: list[pin.SE3], seed: int) -> dict[str, float]:
    """How many plain answers collide (``plain_colliding``) and the share of targets solved clear of the floor and
    table (``clear_success``)."""
    plain = [solve(robot, t, solver="frdm", seed=seed + k, time_budget=0.5) for k, t in enumerate(targets)]
    aware = [solve(robot, t, solver="frdm", seed=seed + k, time_budget=0.5, collisions=FLOOR_AND_TABLE)
             for k, t in enumerate(targets)]
    return {"plain_colliding": sum(r.success and model.colliding_pair(r.q) is not None for r in plain),
            "clear_success": sum(r.success for r in aware) / len(targets)}


def _check_cost(model: Any, qs: list[np.ndarray]) -> float:
    """The median time of one check [µs] over these configurations."""
    times = []
    for q in qs:
        t0 = time.perf_counter()
        model.colliding_pair(q)
        times.append(time.perf_counter() - t0)
    return 1e6 * float(np.median(times))


def run(robots: list[str] | None = None, n: int = 100, seed: int = 0, repeats: int = 4,
        progress: bool = False) -> list[dict[str, Any]]:
    """A row per arm."""
    return [arm(load(name), n, seed, repeats)
            for name in tqdm(list(robots or ROBOTS), desc="bench --collisions", disable=not progress, unit="arm")]


def markdown(rows: list[dict[str, Any]]) -> str:
    """The rows as a Markdown table."""
    lines = ["| arm | pairs | random q colliding | plain solve | with collisions | ratio | plain answers colliding "
             "| clear success | check (random q) | check (clear q) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        (pl, ph), (cl, ch) = r["spread_us"]["plain"], r["spread_us"]["collisions"]
        lo, hi = r["ratio_spread"]
        lines.append(f"| {r['robot']} | {r['pairs']} | {100 * r['random_colliding']:.1f} % | "
                     f"{r['us']['plain']:.0f} µs [{pl:.0f}–{ph:.0f}] | "
                     f"{r['us']['collisions']:.0f} µs [{cl:.0f}–{ch:.0f}] "
                     f"| {r['ratio']:.2f}× [{lo:.2f}–{hi:.2f}] | {r['plain_colliding']} of {r['targets']} | "
                     f"{100 * r['clear_success']:.1f} % | {r['check_us']:.0f} µs | {r['check_clear_us']:.0f} µs |")
    return "\n".join(lines)

