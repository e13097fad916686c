"""``kinelab bench``: the IK benchmark protocol, kinelab's solvers against the peer libraries.

Protocol (per robot): ``n`` seeded random configurations within the limits give the targets (their
Pinocchio FK); every solver starts from the same configuration per target: a seeded random one
(``start="random"``), or the target's own configuration plus seeded Gaussian noise of ``sigma`` rad
(or m) per joint, clipped into the limits (``start="warm"``, the loop of a controller). A result
counts as solved only when, checked here with Pinocchio's FK, the position error is below 1e-6 m and
the rotation error below 1e-6 rad, q is within the joint limits, and the call returned within the
budget (5 ms by default; restarts inside it are the solver's business). The solvers take turns over
the whole set ``repeats`` times (3 by default) and per problem the fastest run counts, with its own
verdict: the machines are shared and noisy, and a slow spell should not decide a comparison. Speed
targets live here, never in timed tests.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.ik.tasks import Task
from kinelab.robot import Chain

TOL_POS = 1e-6  # [m]
TOL_ROT = 1e-6  # [rad]
BUDGET = 0.005  # [s]
REPEATS = 3  # rounds over the problem set; per problem the fastest run counts
DEFAULT_ROBOTS = ("panda", "ur5", "stanford", "era", "xarm7", "z1", "kinova", "ur10", "so101", "youbot")
STARTS = ("random", "warm")
SCHEDULES = ("blocked", "interleaved")


@dataclass(frozen=True)
class Case:
    """One benchmark problem: the target is the FK of ``q_target``; every solver starts at ``q_start``."""

    index: int
    q_target: np.ndarray
    q_start: np.ndarray
    oMtarget: pin.SE3
    task: str = "pose"  # the components judged (kinelab.ik.tasks); the tool axis of "axis" is z


def round_plan(count: int, names: list[str], r: int) -> list[tuple[int, str]]:
    """The order of round r over ``count`` problems and the solvers ``names``: (problem, solver) pairs. Even
    rounds interleaved (every solver on each problem in turn), odd rounds blocked (each solver over the whole
    set); the solvers' order rotates with the round, so that each goes first as often as the others."""
    order = names[r % len(names):] + names[:r % len(names)]
    return ([(k, name) for k in range(count) for name in order] if r % 2 == 0 else
            [(k, name) for name in order for k in range(count)])


def cases(robot: Chain, n: int, seed: int, start: str = "random", sigma: float = 0.2,
          task: str = "pose") -> list[Case]:
    """``n`` seeded problems: targets drawn uniformly within the joint limits; starts drawn uniformly
    (``start="random"``) or the target's configuration plus N(0, sigma²) per joint, clipped into the
    limits (``"warm"``; sigma in rad or m). Task "position" gives each target a random rotation (mostly
    out of reach: only the point counts), task "axis" a random roll about the tool z axis (the free one)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        q_target, q_start = robot.random_q(rng), robot.random_q(rng)
        if start == "warm":
            q_start = np.clip(q_target + rng.normal(0.0, sigma, robot.n), robot.lower, robot.upper)
        oMtarget = robot.fk(q_target)
        if task == "position":
            oMtarget = pin.SE3(pin.exp3(rng.normal(size=3)), oMtarget.translation)
        elif task == "axis":
            oMtarget = pin.SE3(oMtarget.rotation @ pin.exp3(np.array([0.0, 0.0, rng.uniform(-np.pi, np.pi)])),
                               oMtarget.translation)
        out.append(Case(i, q_target, q_start, oMtarget, task))
    return out


def check_solution(robot: Chain, q: np.ndarray | None, oMtarget: pin.SE3, elapsed: float, budget: float = BUDGET,
                   tol_pos: float = TOL_POS, tol_rot: float = TOL_ROT, task: str = "pose") -> tuple[bool, str]:
    """The protocol's verdict on one answer: (solved, reason). Pinocchio's FK is the judge."""
    if q is None:
        return False, "no answer"
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.n,) or not np.all(np.isfinite(q)):
        return False, "malformed answer"
    if elapsed > budget:
        return False, "over budget"
    if not robot.within_limits(q):
        return False, "outside the joint limits"
    judge = Task.of(task)
    dp, dr = judge.errors(oMtarget, robot.fk(q))
    if not judge.met(dp, dr, tol_pos, tol_rot):
        return False, f"pose error {dp:.1e} m, {dr:.1e} rad"
    return True, "solved"


# A solver under test: prepare(robot, budget) → solve(case, seed) → (q or None, iterations or -1)
SolveFn = Callable[[Case, int], tuple[np.ndarray | None, int]]
Prepare = Callable[[Chain, float], SolveFn]


def smooth_path(robot: Chain, seed: int, samples: int = 2000, amplitude: float = 0.6) -> np.ndarray:
    """A smooth joint-space path (samples × n): each joint a sinusoid of seeded phase and rate (0.5–1.5 periods)
    over ± ``amplitude`` of its range about mid-range (continuous joints: of [−π, π]). The tracking
    protocol's targets are its FK; its own largest joint step is the yardstick of a branch jump."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    phase, rate = rng.uniform(0, 2 * np.pi, robot.n), rng.uniform(0.5, 1.5, robot.n)
    t = np.linspace(0, 2 * np.pi, samples)
    return (lo + hi) / 2 + amplitude * (hi - lo) / 2 * np.sin(np.outer(t, rate) + phase)


def blend_path(robot: Chain, seed: int, samples: int = 200, amplitude: float = 0.6) -> np.ndarray:
    """A smooth joint-space path (samples × n) from one seeded configuration to another, both drawn within
    ± ``amplitude`` of each joint's range about mid-range (continuous joints: of [−π, π]), blended by a cosine
    (zero joint speed at both ends)."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    mid, half = (lo + hi) / 2, amplitude * (hi - lo) / 2
    qa, qb = mid + half * rng.uniform(-1, 1, robot.n), mid + half * rng.uniform(-1, 1, robot.n)
    s = (1 - np.cos(np.linspace(0, np.pi, samples))) / 2
    return qa + np.outer(s, qb - qa)


def path_set(robot: Chain, seed: int, count: int, samples: int = 200) -> list[np.ndarray]:
    """``count`` seeded joint-space paths, cosine blends and sinusoids in turn (path k from seed + k): the set
    the tracking protocol and its test follow."""
    return [(blend_path if k % 2 == 0 else smooth_path)(robot, seed + k, samples) for k in range(count)]


def _pulled_pair(robot: Chain, rng: np.random.Generator, share: float) -> tuple[np.ndarray, np.ndarray]:
    """Two configurations drawn uniform in the limits, each pulled to ``share`` of the way from mid-range."""
    mid = (robot.lower + robot.upper) / 2
    qa, qb = (mid + share * (rng.uniform(robot.lower, robot.upper) - mid) for _ in range(2))
    return qa, qb


def cosine_path(robot: Chain, rng: np.random.Generator, samples: int = 2000, share: float = 0.6) -> np.ndarray:
    """Two random configurations pulled to ``share`` of every joint's range about its middle, joined by a cosine
    blend (samples × n) [rad or m]: inside the limits, feasible by construction (the trust issues' path)."""
    qa, qb = _pulled_pair(robot, rng, share)
    s = (1 - np.cos(np.pi * np.linspace(0, 1, samples))) / 2
    return qa + s[:, None] * (qb - qa)


def joint_line(robot: Chain, rng: np.random.Generator, samples: int = 400, step: float = 0.025) -> np.ndarray:
    """A straight joint-space line of ``samples`` samples between two configurations drawn as :func:`cosine_path`
    draws them, no joint moving more than ``step`` [rad or m] between two."""
    qa, qb = _pulled_pair(robot, rng, 0.6)
    d = qb - qa
    d *= min(1.0, step * (samples - 1) / np.abs(d).max())
    return qa + np.linspace(0, 1, samples)[:, None] * d


Call = Callable[[pin.SE3, int], Any]  # a solver timed on (target, seed)


def rounds(poses: list[pin.SE3], calls: dict[str, Call], repeats: int) -> dict[str, list[float]]:
    """Per solver, the median time per call [s] of each round (:func:`~kinelab.report.bench.protocol.round_plan`:
    interleaved and blocked rounds alternating)."""
    medians: dict[str, list[float]] = {name: [] for name in calls}
    names = list(calls)
    for r in range(repeats):
        times: dict[str, list[float]] = {name: [] for name in calls}
        for k, name in round_plan(len(poses), names, r):
            t0 = time.perf_counter()
            calls[name](poses[k], r * len(poses) + k)
            times[name].append(time.perf_counter() - t0)
        for name in names:
            medians[name].append(float(np.median(times[name])))
    return medians


def warmed_rounds(poses: list[pin.SE3], calls: dict[str, Call], repeats: int) -> dict[str, list[float]]:
    """Each call once on the first pose (compilation, not timed), then :func:`rounds`."""
    for call in calls.values():
        call(poses[0], 0)
    return rounds(poses, calls, repeats)


def figures(medians: dict[str, list[float]]) -> dict[str, Any]:
    """{"us": the median over rounds [µs], "spread_us": (lowest, highest round) [µs]} per call."""
    return {"us": {k: 1e6 * float(np.median(v)) for k, v in medians.items()},
            "spread_us": {k: (1e6 * min(v), 1e6 * max(v)) for k, v in medians.items()}}
