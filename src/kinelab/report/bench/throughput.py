"""``kinelab bench --throughput``: targets per second of one ``solve_batch`` call, in the GPU libraries' protocol.

Per arm and round, TARGETS random targets (the tool poses of configurations drawn within the limits from the round's
seed), solved by :func:`kinelab.solve_batch` (FRDM) on every core, twice — the first starts from the robot's start
table (:mod:`kinelab.ik.starts`) and from random draws — in an order that alternates between rounds; an arm with a
closed form also by ``solve_batch(..., solver="analytic")``, each row the branch nearest a random start, one
compiled call on every core (a 7R arm with a swept form, the Panda: its six in closed form with the swept joint held
at the start's value, else at samples of its range, :mod:`kinelab.ik.analytic.held`). Every answer is judged by the
batch's own judge (Pinocchio's FK or the compiled FK certified equal to it). Reported: targets/s and the time per
target (the call's wall time, judging included, over the targets), median and spread over the rounds, and the
success rate at kinelab's tolerance (1e-6 m, 1e-6 rad) and at the GPU libraries' (5 mm, 0.05 rad); the table's build
time and memory. The peers' published figures are reference rows, not measured here.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.collision import Collisions, collision_model
from kinelab.ik.analytic import held
from kinelab.ik.analytic.classify import classify
from kinelab.ik.api import solve_batch
from kinelab.ik.starts import start_table
from kinelab.report.bench.collisions import FLOOR_AND_TABLE
from kinelab.robot import Chain, load

TARGETS = 2000
ARMS = ("panda", "ur5", "xarm7", "youbot")
LOOSE = (5e-3, 0.05)  # [m, rad] the GPU libraries' success thresholds
PUBLISHED = (  # (library, hardware, what, targets/s): their own papers' figures, not measured here
    ("PyRoki", "RTX 4090", "2,000 random Franka targets in 28.6–29.8 ms, 5 mm / 0.05 rad", "67,000–70,000"),
    ("cuRobo v2", "RTX 4090", "100 Franka targets in 2.60 ms, 100 % solved", "≈ 38,000"),
    ("cuRobo", "RTX 4090", "collision-free IK queries", "> 7,000"),
)


def _round(robot: Chain, seed: int, first: str, closed: bool) -> dict[str, dict[str, float]]:
    """One round: the two start modes on one set of targets, ``first`` first, then (``closed``) the closed form's
    branch nearest a random start per target."""
    rng = np.random.default_rng(seed)
    targets = robot.fk_batch(robot.random_qs(TARGETS, rng))
    starts = robot.random_qs(TARGETS, rng)
    found = {}
    for mode in (first, "random" if first == "table" else "table", *(("closed form",) if closed else ())):
        t0 = time.perf_counter()
        res = solve_batch(robot, targets, solver="analytic", q0=starts) if mode == "closed form" else \
            solve_batch(robot, targets, q0=mode, seed=seed)
        seconds = time.perf_counter() - t0
        loose = (res.position_error <= LOOSE[0]) & (res.rotation_error <= LOOSE[1])
        found[mode] = {"per_second": TARGETS / seconds, "us_per_target": 1e6 * seconds / TARGETS,
                       "success": float(res.success.mean()), "success_loose": float(np.nanmean(loose))}
    return found


def measure(robot: Chain, rounds: int, seed: int) -> dict[str, Any]:
    """The arm's row: per start mode, each round's figures; the table's build time [ms] and size [MB]."""
    t0 = time.perf_counter()
    table = start_table(robot)
    build_ms = 1e3 * (time.perf_counter() - t0)
    solve_batch(robot, robot.fk_batch(robot.random_qs(50, np.random.default_rng(seed))), seed=seed)  # warm-up
    closed = classify(robot).arm is not None or held.applies(robot)  # a 7R arm: its six at the start's held value
    per_round = [_round(robot, seed + 1000 * r, "table" if r % 2 == 0 else "random", closed) for r in range(rounds)]
    modes = {mode: {key: [r[mode][key] for r in per_round] for key in per_round[0][mode]} for mode in per_round[0]}
    return {"robot": robot.name, "dof": robot.n, "targets": TARGETS, "rounds": rounds, "table_ms": build_ms,
            "table_mb": table.nbytes / 2**20, "modes": modes}


def collision_free(robot: Chain, rounds: int, seed: int) -> dict[str, Any]:
    """Collision-free batches: per round TARGETS targets, each the tool pose of a random configuration clear of the
    arm itself and of a floor and a table, solved by ``solve_batch(..., collisions=)``; targets/s, the success rate,
    and how many successes Pinocchio's ``computeCollisions`` finds colliding (:func:`_by_pinocchio`)."""
    model = collision_model(robot, Collisions(environment=FLOOR_AND_TABLE))
    per_second, success, colliding = [], [], 0
    for r in range(rounds):
        Q = robot.random_qs(4 * TARGETS, np.random.default_rng(seed + 7000 + r))
        clear = np.array([q for q in Q if model.colliding_pair(q) is None])[:TARGETS]
        targets = robot.fk_batch(clear)
        t0 = time.perf_counter()
        res = solve_batch(robot, targets, seed=seed + r, collisions=FLOOR_AND_TABLE)
        per_second.append(len(targets) / (time.perf_counter() - t0))
        success.append(float(res.success.mean()))
        colliding += _by_pinocchio(robot, model.geom, res.q[res.success])
    return {"robot": robot.name, "pairs": len(model.pairs), "targets": TARGETS, "per_second": per_second,
            "success": success, "colliding": int(colliding)}


def _by_pinocchio(robot: Chain, geom: Any, Q: np.ndarray) -> int:
    """How many configurations of Q Pinocchio's ``computeCollisions`` finds colliding: the geometry's pairs on
    geometry data of its own (no margin, none of the batch's checks' history)."""
    data, gdata = robot.model.createData(), pin.GeometryData(geom)
    return sum(bool(pin.computeCollisions(robot.model, data, geom, gdata, robot.to_pin_q(q), True)) for q in Q)


def run(robots: list[str] | None, seed: int = 0, repeats: int = 3, progress: bool = False) -> dict[str, Any]:
    """Every arm's row (default ARMS), and the Panda's collision-free batches."""
    names = list(robots or ARMS)
    rows = [measure(load(name), max(repeats, 1), seed)
            for name in tqdm(names, desc="bench --throughput", disable=not progress, unit="arm")]
    return {"arms": rows, "collision_free": collision_free(load("panda"), max(repeats, 1), seed)}


def _spread(values: list[float], digits: str = ",.0f") -> str:
    return f"{np.median(values):{digits}} [{min(values):{digits}}–{max(values):{digits}}]"


def markdown(result: dict[str, Any]) -> str:
    """The tables (median [lowest–highest round]) and the published reference rows."""
    rows, clear = result["arms"], result.get("collision_free")
    lines = ["| arm (DoF) | first starts | targets/s | µs per target | solved at 1e-6 | solved at 5 mm / 0.05 rad "
             "| table build, size |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        for mode, m in r["modes"].items():
            lines.append(f"| {r['robot']} ({r['dof']}) | {mode} | {_spread(m['per_second'])} | "
                         f"{_spread(m['us_per_target'], '.1f')} | {100 * min(m['success']):.2f} % | "
                         f"{100 * min(m['success_loose']):.2f} % | "
                         f"{r['table_ms']:.0f} ms, {r['table_mb']:.1f} MB |")
    if clear:
        lines += ["", "| collision-free batch | pairs checked | targets/s | solved | successes colliding |",
                  "|---|---|---|---|---|",
                  f"| {clear['robot']}, self and a floor and a table | {clear['pairs']} | "
                  f"{_spread(clear['per_second'])} | {100 * min(clear['success']):.2f} % | {clear['colliding']} |"]
    lines += ["", "Published, not measured here:", "", "| library | hardware | what | targets/s |", "|---|---|---|---|"]
    lines += [f"| {name} | {hw} | {what} | {rate} |" for name, hw, what, rate in PUBLISHED]
    return "\n".join(lines)
