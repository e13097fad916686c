"""``kinelab bench --versus``: kinelab's calls against roboticstoolbox's ``ik_LM`` where users measure.

Per arm and protocol (floor: the start is the answer; warm: the answer plus N(0, σ) per joint, σ = 0.02 and
0.2 rad, clipped to the limits; random: a uniform start), the same n seeded problems go to the prepared
solver (``kinelab.IK(...).solve``), the plain call (``kinelab.solve``), the prepared biquaternion solver, the
closed form's nearest branch where the arm has one, and ``ets.ik_LM`` (its C++
Levenberg–Marquardt with its own restarts). Every answer is judged here by Pinocchio (1e-6 m, 1e-6 rad,
within the limits). Rounds alternate two schedules — interleaved (the solvers on each problem in turn,
the order rotating) and blocked (each solver over the whole set) — and kinelab's seeds change with the round,
as ik_LM's own restarts do. A ratio is kinelab's median time over ik_LM's, per round; the figures are the
median over rounds and the spread (lowest, highest round).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.ik.analytic.classify import classify
from kinelab.ik.api import solve
from kinelab.ik.prepared import IK
from kinelab.report.bench import peers
from kinelab.report.bench.protocol import DEFAULT_ROBOTS, TOL_POS, TOL_ROT, round_plan
from kinelab.robot import Chain, load

PROTOCOLS = (("floor", 0.0), ("warm", 0.02), ("warm", 0.2), ("random", 0.0))
BUDGET = 0.005  # [s] per solve, kinelab's; ik_LM runs its own default search limit
Solver = Callable[[pin.SE3, np.ndarray, int], np.ndarray]


def problems(robot: Chain, n: int, seed: int, start: str, sigma: float) -> list[tuple[pin.SE3, np.ndarray]]:
    """n seeded (target, start) pairs: the target the FK of a random configuration, the start as the protocol
    says."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = robot.random_q(rng)
        if start == "random":
            q0 = robot.random_q(rng)
        else:
            q0 = np.clip(q + rng.normal(0.0, sigma, q.size), robot.lower, robot.upper) if sigma else q.copy()
        out.append((robot.fk(q), q0))
    return out


def solvers(robot: Chain) -> dict[str, Solver]:
    """The contenders: the prepared call, the plain call, the prepared biquaternion solver, the closed form where the
    arm has one (the branch nearest the start) and (if installed) ik_LM."""
    ik = IK(robot, time_budget=BUDGET)
    biquat = IK(robot, solver="biquat", time_budget=BUDGET)
    out: dict[str, Solver] = {
        "IK.solve": lambda t, q0, seed: ik.solve(t, q0=q0, seed=seed).q,
        "kinelab.solve": lambda t, q0, seed: solve(robot, t, q0=q0, seed=seed, time_budget=BUDGET).q,
        "IK.solve biquat": lambda t, q0, seed: biquat.solve(t, q0=q0, seed=seed).q,
    }
    if classify(robot).arm is not None:
        out["solve analytic"] = lambda t, q0, seed: solve(robot, t, solver="analytic", q0=q0).q
    try:
        ets = peers.rtb_ets(robot)
    except (ImportError, peers.PeerDeclinedError):  # not installed, or it does not take this chain
        return out
    out["ik_LM"] = lambda t, q0, seed: np.asarray(ets.ik_LM(t.homogeneous, q0=q0, tol=5e-13, joint_limits=True).q,
                                                   dtype=float)
    return out


def _timed(robot: Chain, fn: Solver, target: pin.SE3, q0: np.ndarray, seed: int) -> tuple[float, bool]:
    t0 = time.perf_counter()
    q = fn(target, q0, seed)
    elapsed = time.perf_counter() - t0
    dp, dr = robot.tool_error(q, target) if np.all(np.isfinite(q)) else (np.inf, np.inf)
    return elapsed, bool(dp <= TOL_POS and dr <= TOL_ROT and robot.within_limits(q))


def rounds(robot: Chain, cases: list[tuple[pin.SE3, np.ndarray]], contenders: dict[str, Solver], repeats: int,
           seed: int) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    """Per contender and round: (times [s], verdicts) over the cases; even rounds interleaved, odd blocked."""
    names = list(contenders)
    out: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {name: [] for name in names}
    for r in range(repeats):
        times = {name: np.zeros(len(cases)) for name in names}
        ok = {name: np.zeros(len(cases), dtype=bool) for name in names}
        for k, name in round_plan(len(cases), names, r):
            target, q0 = cases[k]
            times[name][k], ok[name][k] = _timed(robot, contenders[name], target, q0, seed + r * len(cases) + k)
        for name in names:
            out[name].append((times[name], ok[name]))
    return out


def compare(robot: Chain, n: int = 60, seed: int = 0, repeats: int = 4) -> list[dict[str, Any]]:
    """One row per (protocol, kinelab call): medians, p95, success and the ratios to ik_LM with their spread."""
    contenders = solvers(robot)
    for fn in contenders.values():  # compile, load and warm every contender outside the figures
        target, q0 = problems(robot, 1, seed + 999, "warm", 0.02)[0]
        fn(target, q0, 0)
    rows = []
    for start, sigma in PROTOCOLS:
        cases = problems(robot, n, seed, start, sigma)
        result = rounds(robot, cases, contenders, repeats, seed)
        protocol = start + (f" σ={sigma}" if start == "warm" else "")
        for name in [c for c in contenders if c != "ik_LM"]:
            row = {"robot": robot.name, "protocol": protocol, "call": name, "n": n, "repeats": repeats,
                   **_figures(result[name], result.get("ik_LM"))}
            rows.append(row)
    return rows


Rounds = list[tuple[np.ndarray, np.ndarray]]


def _figures(mine: Rounds, lm: Rounds | None) -> dict[str, float]:
    """A call's median and p95 [µs] and success [%] over its rounds (times [s], successes), and with ik_LM's rounds
    the ratios to them (median of the per-round ratios, their spread, and the p95s' ratio)."""
    med = np.array([np.median(t) for t, _ in mine])
    p95 = np.array([np.percentile(t, 95) for t, _ in mine])
    out = {"median_us": float(np.median(med) * 1e6), "p95_us": float(np.median(p95) * 1e6),
           "success_pct": 100.0 * float(np.mean([ok.mean() for _, ok in mine]))}
    if lm is None:
        return out
    ratio = med / np.array([np.median(t) for t, _ in lm])
    ratio95 = p95 / np.array([np.percentile(t, 95) for t, _ in lm])
    return {**out, "lm_median_us": float(np.median([np.median(t) for t, _ in lm]) * 1e6),
            "lm_success_pct": 100.0 * float(np.mean([ok.mean() for _, ok in lm])),
            "ratio": float(np.median(ratio)), "ratio_low": float(ratio.min()), "ratio_high": float(ratio.max()),
            "ratio_p95": float(np.median(ratio95))}


def markdown(rows: list[dict[str, Any]]) -> str:
    """The table: per arm, protocol and call, kinelab against ik_LM (ratio < 1: kinelab faster)."""
    lines = ["| robot | protocol | call | median µs | p95 µs | success % | ik_LM median µs | ik_LM success % | "
             "ratio (median) [spread] | ratio (p95) |", "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lm = (f"{r['lm_median_us']:.1f} | {r['lm_success_pct']:.1f} | {r['ratio']:.2f} [{r['ratio_low']:.2f}–"
              f"{r['ratio_high']:.2f}] | {r['ratio_p95']:.2f}") if "ratio" in r else "– | – | – | –"
        lines.append(f"| {r['robot']} | {r['protocol']} | {r['call']} | {r['median_us']:.1f} | {r['p95_us']:.1f} | "
                     f"{r['success_pct']:.1f} | {lm} |")
    return "\n".join(lines)


def run(robots: list[str] | None, seed: int = 0, repeats: int = 4, n: int = 60,
        progress: bool = False) -> list[dict[str, Any]]:
    """:func:`compare` on each robot (default: the bench's ten arms)."""
    rows: list[dict[str, Any]] = []
    for name in tqdm(list(robots or DEFAULT_ROBOTS), desc="versus ik_LM", disable=not progress, unit="robot"):
        rows += compare(load(name), n, seed, repeats)
    return rows
