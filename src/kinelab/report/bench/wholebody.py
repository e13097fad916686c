"""``kinelab bench --whole-body``: the differential step side by side with pink (Pinocchio) and mink (MuJoCo), and
the converged solve against pink iterated.

The step. Each robot follows the same moving targets with the same tasks and limits in the three libraries: the
Panda's tool (frame + posture), Baxter's two grippers (+ posture), TALOS's and G1's two hands with their feet held,
the centre of mass and a posture on a free-flyer. Each hand turns on a 5 cm circle (one turn in 2 s), dt = 5 ms,
from a start within the limits. Costs are pink's (frame 1/m and 1/rad, CoM 1/m, posture 1e-3 per joint; kinelab's
weights are their squares), damping 1e-12, every library's QP DAQP, position and velocity limits (the file's). The
libraries are interleaved per step, in a rotating order; each keeps its own configuration. Per step: the wall time
of the library's step and integration (outside it), its limit violations (a position beyond 1e-9, a velocity beyond
1e-9 of its limit) and its tracking error judged by Pinocchio's FK (mink's configuration mapped by joint name).
MuJoCo's model is compiled from the same URDF with its meshes left out and its fixed links kept as bodies.

The converged solve. Targets from random configurations of the whole robot; kinelab's two solvers and pink's step
iterated at dt = 1 s until every frame is within 1e-6 m / 1e-6 rad (at most 200 steps); success and time.
"""

from __future__ import annotations

import importlib.util
import time
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.errors import KinelabError
from kinelab.report.bench.peers import PeerFailedError, last_line
from kinelab.report.bench.steppers import (
    DT,
    PEER_MODULES,
    PERIOD,
    RADIUS,
    SCENARIOS,
    STEPPERS,
    start_of,
    targets_at,
    whole,
)
from kinelab.robot.tree import Robot
from kinelab.wholebody import ComTask, FrameTask, PostureTask
from kinelab.wholebody.solve import solve


def run_steps(name: str, steps: int = 1000, rounds: int = 3, progress: bool = False, standing: bool = False
              ) -> list[dict[str, Any]]:
    """The step protocol on one robot: a row per library with its times (median, p95, p99 over every step of every
    round, and each round's median), its violations and its largest tracking error. ``standing``: from where the
    robot stands (``robot.standing()``: its SRDF's half-sitting, its file's keyframe) instead of the bent start."""
    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    q0 = robot.standing() if standing else start_of(robot)
    frames = scenario.moving + scenario.held
    start = robot.frame_placements(q0, frames)
    records: dict[str, dict[str, list[float]]] = {k: {"times": [], "medians": [], "violations": [], "errors": []}
                                                  for k in STEPPERS}
    for _ in tqdm(range(rounds), desc=f"whole-body {name}", disable=not progress, unit="round"):
        steppers = _steppers(robot, scenario, q0)
        round_times: dict[str, list[float]] = {k: [] for k in steppers}
        order = list(steppers)
        for k in range(steps):
            targets = targets_at(start, (k + 1) * DT, len(scenario.moving))
            for key in order[k % len(order):] + order[:k % len(order)]:
                round_times[key].append(_timed_step(steppers[key], targets))
                _judge(robot, steppers[key], targets, frames, records[key])
        for key, times in round_times.items():
            records[key]["times"] += times
            records[key]["medians"].append(float(np.median(times)))
    return [_row(name, key, rec) for key, rec in records.items() if rec["times"]]


def _steppers(robot: Robot, scenario: Any, q0: np.ndarray) -> dict[str, Any]:
    """A fresh stepper per library of STEPPERS at q0 (a peer not installed, the bench extra, left out).

    Raises:
        PeerFailedError: an installed peer that fails to set up (its last line named).
    """
    steppers: dict[str, Any] = {}
    for key, make in STEPPERS.items():
        if key in not_installed():
            continue
        try:
            steppers[key] = make(robot, scenario, q0)
        except Exception as exc:  # noqa: BLE001 - an installed peer that breaks stops the bench, named
            if key == "kinelab":
                raise
            raise PeerFailedError(f"{key} failed on {robot.name}: {last_line(exc)}") from exc
    return steppers


def not_installed() -> dict[str, str]:
    """The peers of the whole-body bench that are not installed, each with the install hint."""
    return {key: f"not installed ({', '.join(m for m in mods if importlib.util.find_spec(m) is None)}): "
                 "pip install -e '.[bench]'"
            for key, mods in PEER_MODULES.items() if any(importlib.util.find_spec(m) is None for m in mods)}


def _timed_step(stepper: Any, targets: list[pin.SE3]) -> float:
    """One step towards the targets; its time [s]."""
    t0 = time.perf_counter()
    stepper.step(targets)
    return time.perf_counter() - t0


def _judge(robot: Robot, stepper: Any, targets: list[pin.SE3], frames: tuple[str, ...], record: dict[str, Any]) -> None:
    """The stepper's violations and tracking error at its new configuration, by Pinocchio."""
    q = stepper.pinocchio_q()
    past = np.maximum(robot.lower - q, q - robot.upper)
    vmax = robot.velocity_limit
    finite = np.isfinite(vmax)
    v = np.asarray(stepper.v, dtype=float)
    over = np.abs(v[finite]) / vmax[finite] - 1.0 if v.shape == vmax.shape else np.zeros(1)
    record["violations"].append(int((past > 1e-9).sum() + (over > 1e-9).sum()))
    placed = robot.frame_placements(q, frames)
    record["errors"].append(max(float(np.linalg.norm(M.translation - T.translation))
                                for M, T in zip(placed, targets, strict=True)))


def _row(robot: str, key: str, rec: dict[str, Any]) -> dict[str, Any]:
    t = np.array(rec["times"]) * 1e6
    medians = np.array(rec["medians"]) * 1e6
    return {"robot": robot, "library": key, "steps": len(t), "median_us": float(np.median(t)),
            "p95_us": float(np.percentile(t, 95)), "p99_us": float(np.percentile(t, 99)),
            "round_medians_us": medians.tolist(), "violations": int(sum(rec["violations"])),
            "max_tracking_error_m": float(max(rec["errors"]))}


def ratios(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """kinelab's median step against each peer's, round by round: the ratio of the medians and its spread."""
    mine = {r["robot"]: r for r in rows if r["library"] == "kinelab"}
    return [_ratio(mine[peer["robot"]], peer) for peer in sorted(rows, key=lambda r: r["robot"])
            if peer["library"] != "kinelab" and peer["robot"] in mine]


def _ratio(mine: dict[str, Any], peer: dict[str, Any]) -> dict[str, Any]:
    """kinelab's round medians over the peer's: the median ratio and its spread."""
    per_round = np.array(mine["round_medians_us"]) / np.array(peer["round_medians_us"])
    return {"robot": mine["robot"], "peer": peer["library"], "ratio": float(np.median(per_round)),
            "ratio_min": float(per_round.min()), "ratio_max": float(per_round.max())}


def converged(name: str, count: int = 50, seed: int = 0, progress: bool = False) -> list[dict[str, Any]]:
    """The converged solve on ``count`` targets from random configurations: kinelab's step and FRDM, pink iterated;
    success (every frame within 1e-6 m, 1e-6 rad, judged by Pinocchio) and the median time."""
    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    frames = scenario.moving + scenario.held
    rng = np.random.default_rng(seed)
    rows: dict[str, dict[str, list[float]]] = {k: {"ok": [], "time": []} for k in ("step", "frdm", "pink iterated")}
    for k in tqdm(range(count), desc=f"solve {name}", disable=not progress, unit="target"):
        q_true = robot.random_q(rng)
        placed = robot.frame_placements(q_true, frames)
        start = start_of(robot)
        if robot.floating:
            start[:7] = q_true[:7]
        tasks: list[Any] = [FrameTask(f, M) for f, M in zip(frames, placed, strict=True)]
        tasks += ([ComTask(robot.com(q_true))] if scenario.com else []) + [PostureTask(start, weight=1e-6)]
        for solver in ("step", "frdm"):
            t0 = time.perf_counter()
            res = solve(robot, tasks, q0=start, solver=solver, seed=k, time_budget=2.0)
            rows[solver]["time"].append(time.perf_counter() - t0)
            rows[solver]["ok"].append(float(res.success))
        com = robot.com(q_true) if scenario.com else None
        ok, seconds = _pink_iterated(robot, frames, placed, com, start)
        if ok is not None:
            rows["pink iterated"]["ok"].append(float(ok))
            rows["pink iterated"]["time"].append(seconds)
    return [{"robot": name, "solver": key, "targets": len(r["ok"]), "success_pct": 100.0 * float(np.mean(r["ok"])),
             "median_ms": float(np.median(r["time"]) * 1e3)} for key, r in rows.items() if r["ok"]]


def _pink_iterated(robot: Robot, frames: tuple[str, ...], placed: list[pin.SE3], com: np.ndarray | None,
                   start: np.ndarray) -> tuple[bool | None, float]:
    """pink's step at dt = 1 s (the frames at ``placed``, the centre of mass at ``com`` [m] unless None), iterated
    until every frame is within 1e-6 m / 1e-6 rad (200 steps at most)."""
    try:
        import pink
        from pink.limits import ConfigurationLimit
        from pink.tasks import ComTask as PinkCom
        from pink.tasks import FrameTask as PinkFrame
    except ImportError:
        return None, 0.0
    configuration = pink.Configuration(robot.model, robot.model.createData(), start.copy())
    pink_tasks: list[Any] = []
    for f, M in zip(frames, placed, strict=True):
        task = PinkFrame(f, position_cost=1.0, orientation_cost=1.0)
        task.set_target(M)
        pink_tasks.append(task)
    if com is not None:
        task = PinkCom(cost=1.0)
        task.set_target(com)
        pink_tasks.append(task)
    limits = [ConfigurationLimit(robot.model)]
    t0 = time.perf_counter()
    for _ in range(200):
        v = pink.solve_ik(configuration, pink_tasks, 1.0, solver="daqp", damping=1e-12, limits=limits,
                          safety_break=False)
        configuration.integrate_inplace(v, 1.0)
        q = np.asarray(configuration.q)
        now = robot.frame_placements(q, frames)
        if all(np.linalg.norm(N.translation - M.translation) <= 1e-6
               and np.linalg.norm(pin.log3(N.rotation.T @ M.rotation)) <= 1e-6
               for N, M in zip(now, placed, strict=True)):
            return True, time.perf_counter() - t0
    return False, time.perf_counter() - t0


def run(robots: list[str] | None = None, steps: int = 1000, rounds: int = 3, solves: int = 50, seed: int = 0,
        progress: bool = False, standing: bool = False) -> dict[str, Any]:
    """Both protocols on each robot (default: the four scenarios); ``standing``: the steps from where each robot
    stands (:func:`run_steps`).

    Raises:
        KinelabError: a robot without a whole-body scenario (the valid names listed).
    """
    names = list(robots or SCENARIOS)
    unknown = [n for n in names if n not in SCENARIOS]
    if unknown:
        raise KinelabError(f"no whole-body scenario for {unknown[0]!r}; the scenarios: {', '.join(SCENARIOS)}")
    rows, solved = [], []
    for name in names:
        rows += run_steps(name, steps, rounds, progress, standing)
        if solves:
            solved += converged(name, solves, seed, progress)
    return {"steps": rows, "ratios": ratios(rows), "solves": solved, "not_run": not_installed(),
            "protocol": {"dt_s": DT, "steps": steps, "rounds": rounds, "radius_m": RADIUS, "period_s": PERIOD,
                         "start": "standing" if standing else "bent"}}


def markdown(result: dict[str, Any]) -> str:
    """The tables."""
    start = result.get("protocol", {}).get("start", "bent")
    lines = [f"Steps from the {'standing' if start == 'standing' else 'bent'} start.", "",
             "| robot | library | median | p95 | p99 | violations | largest tracking error |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for r in result["steps"]:
        lines.append(f"| {r['robot']} | {r['library']} | {r['median_us']:.1f} µs | {r['p95_us']:.1f} µs | "
                     f"{r['p99_us']:.1f} µs | {r['violations']} | {r['max_tracking_error_m']:.2e} m |")
    lines += ["", "| robot | kinelab / peer (median step) | spread over rounds |", "|---|---:|---|"]
    for r in result["ratios"]:
        lines.append(f"| {r['robot']} | {r['ratio']:.3f} × {r['peer']} | {r['ratio_min']:.3f}–{r['ratio_max']:.3f} |")
    if result["solves"]:
        lines += ["", "| robot | converged solve | success | median time |", "|---|---|---:|---:|"]
        for r in result["solves"]:
            lines.append(f"| {r['robot']} | {r['solver']} | {r['success_pct']:.1f} % of {r['targets']} | "
                         f"{r['median_ms']:.2f} ms |")
    if result.get("not_run"):
        lines += ["", "Not run: " + "; ".join(f"{k} ({why})" for k, why in result["not_run"].items())]
    return "\n".join(lines)
