"""``kinelab bench --loops``: the loops users run. Throughput (a Python loop of ``solve`` against one
``solve_batch`` call, and roboticstoolbox's ``ik_LM`` in a loop when installed) and tracking (smooth
joint-space paths, each sample warm-started from the previous answer: ``track`` in its two modes against
an ``ik_LM`` loop of one search per sample). Every answer is judged by Pinocchio here; the contenders run
in interleaved blocks, ``repeats`` times, and the figures keep the best block and the spread.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.collision.model import CollisionError, Collisions, collision_model
from kinelab.errors import KinelabError
from kinelab.ik.analytic.redundancy import has_swept_form
from kinelab.ik.analytic.sew import SEW
from kinelab.ik.api import solve, solve_all, solve_all_batch, solve_batch, track
from kinelab.ik.prepared import IK
from kinelab.ik.request import unmeetable_tolerances
from kinelab.report.bench import peers
from kinelab.report.bench.protocol import DEFAULT_ROBOTS, TOL_POS, TOL_ROT, cases, path_set
from kinelab.robot import Chain, load

Runner = Callable[[], tuple[np.ndarray, float]]  # → (answers (N, n), seconds)
RESTARTS = 50  # throughput: the same search effort per target in the loop (5 ms budget too) and the batch


def _judge(robot: Chain, Q: np.ndarray, targets: list[pin.SE3]) -> np.ndarray:
    """Per answer: Pinocchio confirms both tolerances within the limits."""
    ok = np.zeros(len(targets), dtype=bool)
    for k, (q, target) in enumerate(zip(Q, targets, strict=True)):
        if np.all(np.isfinite(q)):
            dp, dr = robot.tool_error(q, target)
            ok[k] = dp <= TOL_POS and dr <= TOL_ROT and robot.within_limits(q)
    return ok


def _blocks(runners: dict[str, Runner], repeats: int) -> dict[str, list[tuple[np.ndarray, float]]]:
    """Each runner once per round, the order rotating between rounds."""
    names = list(runners)
    out: dict[str, list[tuple[np.ndarray, float]]] = {name: [] for name in names}
    for r in range(repeats):
        k = r % len(names)
        for name in names[k:] + names[:k]:
            out[name].append(runners[name]())
    return out


def throughput(robot: Chain, n: int = 2000, seed: int = 0, start: str = "warm", sigma: float = 0.02,
               repeats: int = 3) -> list[dict[str, Any]]:
    """Solves per second of a solve() loop, solve_batch and (if installed) an ik_LM loop on n problems."""
    problems = cases(robot, n, seed, start, sigma)
    targets = [c.oMtarget for c in problems]
    starts = np.array([c.q_start for c in problems])
    H = np.array([t.homogeneous for t in targets])

    def loop() -> tuple[np.ndarray, float]:
        t0 = time.perf_counter()
        Q = np.array([solve(robot, t, solver="frdm", q0=q, seed=seed + k, time_budget=0.005, max_restarts=RESTARTS).q
                      for k, (t, q) in enumerate(zip(targets, starts, strict=True))])
        return Q, time.perf_counter() - t0

    def batch() -> tuple[np.ndarray, float]:
        t0 = time.perf_counter()
        res = solve_batch(robot, H, solver="frdm", q0=starts, seed=seed, max_restarts=RESTARTS)
        return res.q, time.perf_counter() - t0

    runners: dict[str, Runner] = {"frdm solve() loop": loop, "frdm solve_batch": batch}
    with contextlib.suppress(ImportError, peers.PeerDeclinedError):
        ets = peers.rtb_ets(robot)

        def lm_loop() -> tuple[np.ndarray, float]:
            t0 = time.perf_counter()
            Q = np.array([ets.ik_LM(h, q0=q, tol=5e-13, joint_limits=True).q
                          for h, q in zip(H, starts, strict=True)])
            return Q, time.perf_counter() - t0

        runners["rtb ik_LM loop"] = lm_loop
    for run in runners.values():  # warm-up: compilation, caches
        run()
    rows = []
    for name, results in _blocks(runners, repeats).items():
        rates = np.array([n / seconds for _, seconds in results])
        rows.append({"robot": robot.name, "loop": name, "start": start, "sigma": sigma if start == "warm" else None,
                     "solves_per_s": float(rates.max()), "spread": float(rates.max() / rates.min()),
                     "success_pct": 100.0 * float(_judge(robot, results[int(rates.argmax())][0], targets).mean())})
    return rows


def tracking(robot: Chain, seed: int = 0, paths: int = 20, samples: int = 200,
             repeats: int = 3) -> list[dict[str, Any]]:
    """Generated smooth paths (:func:`~kinelab.report.bench.protocol.path_set`: cosine blends and sinusoids)
    followed by track() and, if installed, a loop of one ik_LM search per sample from the previous answer
    (its answer kept only when Pinocchio confirms it). Per tracker: samples reached of all, paths with a branch
    jump (a joint step above 3× the path's largest), the per-sample median time over paths (best of the
    rounds) and its spread."""
    Q_paths = path_set(robot, seed, paths, samples)
    target_sets = [[robot.fk(q) for q in Q] for Q in Q_paths]
    runners: dict[str, Callable[[np.ndarray, list[pin.SE3]], np.ndarray]] = {
        "frdm track": lambda Q, targets: track(robot, targets, q0=Q[0], seed=seed).q}
    with contextlib.suppress(ImportError, peers.PeerDeclinedError):
        ets = peers.rtb_ets(robot)

        def lm_loop(Q: np.ndarray, targets: list[pin.SE3]) -> np.ndarray:
            q, rows = Q[0].copy(), []
            for t in targets:
                sol = ets.ik_LM(t.homogeneous, q0=q, slimit=1, tol=5e-13, joint_limits=True)
                found = np.asarray(sol.q, dtype=float)
                if sol.success and _judge(robot, found[None], [t])[0]:
                    q = found
                rows.append(q)
            return np.array(rows)

        runners["rtb ik_LM loop (one search)"] = lm_loop
    rows = []
    for name, follow in runners.items():
        follow(Q_paths[0][:2], target_sets[0][:2])  # compile or load outside the figures
        per_sample = np.empty((repeats, paths))
        reached = jumps = 0
        for r in range(repeats):
            for k, (Q, targets) in enumerate(zip(Q_paths, target_sets, strict=True)):
                t0 = time.perf_counter()
                answers = follow(Q, targets)
                per_sample[r, k] = (time.perf_counter() - t0) / samples
                if r == 0:
                    reached += int(_judge(robot, answers, targets).sum())
                    steps = np.abs(np.diff(np.vstack([Q[0], answers]), axis=0)).max()
                    jumps += bool(steps > 3 * np.abs(np.diff(Q, axis=0)).max())
        medians = np.median(per_sample, axis=1)
        rows.append({"robot": robot.name, "tracker": name, "paths": paths, "samples": paths * samples,
                     "reached": reached, "paths_with_jump": jumps, "us_per_sample": float(medians.min() * 1e6),
                     "spread": float(medians.max() / medians.min())})
    return rows


def budgets(robot: Chain, budget: float = 0.005, n: int = 200, seed: int = 0,
            solvers: tuple[str, ...] = ("frdm", "biquat", "dls")) -> list[dict[str, Any]]:
    """How well every path keeps ``time_budget`` [s] the way a program meets it: each path in a fresh process
    (:func:`path_times`), its first call included, n calls that cannot succeed (tolerances of 1e-300) from random
    starts; the wall time of each call, outside kinelab. The paths: each solver's ``solve``, the prepared
    ``IK.solve``, FRDM's ``solve_batch`` of 64 targets, ``solve_all``, ``solve(prefer=)``,
    ``solve(collisions="self")`` (arms with collision geometry), ``track`` of 50 samples and the closed form's."""
    rows = []
    allowed, loose = budget * 1.05 + 1e-4, budget * 1.10 + 2e-3
    for name in _budget_paths(robot, budget, solvers):
        t = np.array(_fresh(robot.name, name, budget, n, seed, solvers))
        rows.append({"robot": robot.name, "solver": name, "budget_ms": budget * 1e3,
                     "first_ms": float(t[0] * 1e3), "p50_ms": float(np.percentile(t, 50) * 1e3),
                     "p99_ms": float(np.percentile(t, 99) * 1e3), "max_ms": float(np.max(t) * 1e3),
                     "kept": bool(np.percentile(t, 99) <= allowed), "kept_loose": bool(np.percentile(t, 99) <= loose)})
    return rows


def _fresh(robot: str, path: str, budget: float, n: int, seed: int, solvers: tuple[str, ...]) -> list[float]:
    """:func:`path_times` in a process of its own (a fresh interpreter: nothing imported, prepared or cached)."""
    import json
    import subprocess
    import sys

    args = json.dumps([robot, path, budget, n, seed, list(solvers)])
    out = subprocess.run([sys.executable, "-c", "import sys, json; from kinelab.report.bench.loops import "
                          "path_times; print(json.dumps(path_times(*json.loads(sys.argv[1]))))", args],
                         capture_output=True, text=True, timeout=3600, check=False)
    if out.returncode != 0:
        raise KinelabError(f"the budget of {path!r} on {robot} could not be measured: "
                           f"{' '.join(out.stderr.strip().splitlines()[-1:])}")
    times: list[float] = json.loads(out.stdout)
    return times


def path_times(robot_name: str, path: str, budget: float, n: int, seed: int, solvers: list[str]) -> list[float]:
    """The wall time [s] of each of n calls of one budget path on a robot loaded here, the first call of the
    process first (nothing run before it but the robot's load)."""
    robot = load(robot_name)
    call = _budget_paths(robot, budget, tuple(solvers), probe=False)[path]
    times = []
    with unmeetable_tolerances():
        for k, case in enumerate(cases(robot, n, seed)):
            t0 = time.perf_counter()
            call(case, seed + k, 1e-300)
            times.append(time.perf_counter() - t0)
    return times


def _budget_paths(robot: Chain, budget: float, solvers: tuple[str, ...],
                  probe: bool = True) -> dict[str, Callable[..., Any]]:
    """One call per path, (case, seed, tolerance) → anything, each with ``budget`` (``probe``: the closed form's
    paths where :func:`_analytic_paths` finds them by preparing one; else where the robot's class says so, nothing
    prepared before the first call)."""
    def single(name: str) -> Callable[..., Any]:
        return lambda case, seed, tol: solve(robot, case.oMtarget, solver=name, q0=case.q_start, seed=seed,
                                             tol_pos=tol, tol_rot=tol, time_budget=budget)

    paths = {name: single(name) for name in solvers}
    prepared: dict[float, IK] = {}

    def ik_solve(case: Any, seed: int, tol: float) -> Any:
        if tol not in prepared:  # built inside the call's tolerance context, once per tolerance
            prepared[tol] = IK(robot, solver="frdm", tol_pos=tol, tol_rot=tol, time_budget=budget)
        return prepared[tol].solve(case.oMtarget, q0=case.q_start, seed=seed)

    paths["frdm IK.solve"] = ik_solve
    paths["frdm batch of 64"] = lambda case, seed, tol: solve_batch(
        robot, [case.oMtarget] * 64, solver="frdm", seed=seed, tol_pos=tol, tol_rot=tol, time_budget=budget)
    paths["frdm solve_all"] = lambda case, seed, tol: solve_all(robot, case.oMtarget, solver="frdm", seed=seed,
                                                                tol_pos=tol, tol_rot=tol, time_budget=budget)
    paths["frdm prefer="] = lambda case, seed, tol: solve(robot, case.oMtarget, solver="frdm", seed=seed, tol_pos=tol,
                                                         tol_rot=tol, time_budget=budget, prefer=case.q_start)
    if _has_collision_geometry(robot):
        paths["frdm collisions"] = lambda case, seed, tol: solve(
            robot, case.oMtarget, q0=case.q_start, seed=seed, tol_pos=tol, tol_rot=tol, time_budget=budget,
            collisions="self")
    paths["frdm track of 50"] = lambda case, seed, tol: track(
        robot, [case.oMtarget] * 50, q0=case.q_start, tol_pos=tol, tol_rot=tol, time_budget=budget)
    paths.update(_analytic_paths(robot, budget, probe))
    return paths


def _analytic_paths(robot: Chain, budget: float, probe: bool = True) -> dict[str, Callable[..., Any]]:
    """The closed form's paths where the robot has one: ``solve`` and a batch of 100 with solver "analytic",
    ``solve_all_batch`` of 1,000 (a 6R chain in a class), and ``solve_all`` with ``redundancy=`` 64 samples and a
    SEW angle (a 7R arm with a swept form). ``probe`` False: every path named, nothing prepared (a child process
    measuring its first call, told the path by a parent that probed)."""
    if probe:
        try:
            IK(robot, solver="analytic")
        except KinelabError:
            return {}
    paths: dict[str, Callable[..., Any]] = {
        "analytic solve": lambda case, seed, tol: solve(robot, case.oMtarget, solver="analytic", q0=case.q_start,
                                                        tol_pos=tol, tol_rot=tol, time_budget=budget),
        "analytic batch of 100": lambda case, seed, tol: solve_batch(
            robot, [case.oMtarget] * 100, solver="analytic", q0=case.q_start, tol_pos=tol, tol_rot=tol,
            time_budget=budget)}
    if robot.n == 7 and (not probe or has_swept_form(robot)):
        paths["solve_all K=64"] = lambda case, seed, tol: solve_all(robot, case.oMtarget, redundancy=64,
                                                                    tol_pos=tol, tol_rot=tol, time_budget=budget)
        paths["solve_all SEW"] = lambda case, seed, tol: solve_all(
            robot, case.oMtarget, redundancy=SEW(0.3), tol_pos=tol, tol_rot=tol, time_budget=budget)
    if robot.n != 7 or not probe:
        paths["solve_all_batch of 1000"] = lambda case, seed, tol: solve_all_batch(
            robot, [case.oMtarget] * 1000, tol_pos=tol, tol_rot=tol, time_budget=budget)
    return paths


BUDGET_ROBOTS = ("ur5", "crx10ia", "panda", "baxter_left", "tiago")  # a closed form, a search, three held 7R arms


def budgets_run(robots: list[str] | None, seed: int = 0, n: int = 200,
                progress: bool = False) -> list[dict[str, Any]]:
    """``kinelab bench --budgets``: :func:`budgets` at 5 ms on each robot (default :data:`BUDGET_ROBOTS`)."""
    rows: list[dict[str, Any]] = []
    for name in tqdm(list(robots or BUDGET_ROBOTS), desc="budgets", disable=not progress, unit="robot"):
        rows += budgets(load(name), n=n, seed=seed)
    return rows


def _has_collision_geometry(robot: Chain) -> bool:
    """The robot's files give it collision geometry (the self-collision check can run)."""
    try:
        collision_model(robot, Collisions())
    except CollisionError:
        return False
    return True


def run(robots: list[str] | None, seed: int = 0, repeats: int = 3, n: int = 2000,
        progress: bool = False) -> dict[str, list[dict[str, Any]]]:
    """Both protocols on each robot (default: the bench's ten arms): throughput warm (σ = 0.02) and random,
    and tracking one smooth path."""
    out: dict[str, list[dict[str, Any]]] = {"throughput": [], "tracking": [], "budgets": []}
    for name in tqdm(list(robots or DEFAULT_ROBOTS), desc="loops", disable=not progress, unit="robot"):
        robot = load(name)
        out["throughput"] += throughput(robot, n, seed, "warm", 0.02, repeats)
        out["throughput"] += throughput(robot, n, seed, "random", 0.2, repeats)
        out["tracking"] += tracking(robot, seed, repeats=repeats)
        out["budgets"] += budgets(robot, seed=seed)
    return out


def budget_markdown(rows: list[dict[str, Any]]) -> str:
    """The budget table: per robot and entry point, p50, p99 and the largest wall time of a call that cannot
    succeed, against two bars."""
    lines = ["| robot | entry point | budget | first call | p50 | p99 | max | p99 ≤ budget + 5 % + 0.1 ms | "
             "≤ + 10 % + 2 ms |", "|---|---|---:|---:|---:|---:|---:|---|---|"]
    for r in rows:
        lines.append(f"| {r['robot']} | {r['solver']} | {r['budget_ms']:.1f} ms | {r['first_ms']:.2f} ms | "
                     f"{r['p50_ms']:.2f} ms | {r['p99_ms']:.2f} ms | {r['max_ms']:.2f} ms | "
                     f"{'yes' if r['kept'] else 'NO'} | {'yes' if r.get('kept_loose', r['kept']) else 'NO'} |")
    return "\n".join(lines) + ("\n\nEach entry point in a fresh process, its first call included in the "
                               "percentiles (nothing before it but the robot's load).")


def markdown(throughput_rows: list[dict[str, Any]], tracking_rows: list[dict[str, Any]],
             budget_rows: list[dict[str, Any]] | None = None) -> str:
    """The tables: throughput, tracking and (if given) budgets."""
    lines = ["| robot | loop | start | solves/s (best) | spread | success % |", "|---|---|---|---:|---:|---:|"]
    for r in throughput_rows:
        start = r["start"] + (f" σ={r['sigma']}" if r["sigma"] else "")
        lines.append(f"| {r['robot']} | {r['loop']} | {start} | {r['solves_per_s']:,.0f} | {r['spread']:.2f} | "
                     f"{r['success_pct']:.1f} |")
    lines += ["", "| robot | tracker | reached | paths with a branch jump | µs per sample (median, best round) | "
              "spread |", "|---|---|---:|---:|---:|---:|"]
    for r in tracking_rows:
        lines.append(f"| {r['robot']} | {r['tracker']} | {r['reached']}/{r['samples']} | "
                     f"{r['paths_with_jump']}/{r['paths']} | {r['us_per_sample']:.1f} | {r['spread']:.2f} |")
    if budget_rows:
        lines += ["", budget_markdown(budget_rows)]
    return "\n".join(lines)
