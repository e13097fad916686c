"""``kinelab bench``: the IK benchmark protocol, kinelab's solvers against the peer libraries.

Protocol (per robot): ``n`` seeded random configurations within the limits give the targets (their
Pinocchio FK); every solver starts from the same seeded random configuration per target. A result
counts as solved only when, checked here with Pinocchio's FK, the position error is below 1e-6 m and
the rotation error below 1e-6 rad, q is within the joint limits, and the call returned within the
budget (5 ms by default; restarts inside it are the solver's business). The solvers take turns over
the whole set ``repeats`` times (3 by default) and per problem the fastest run counts, with its own
verdict: the machines are shared and noisy, and a slow spell should not decide a comparison. Speed
targets live here, never in timed tests.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.robot import Robot

TOL_POS = 1e-6  # [m]
TOL_ROT = 1e-6  # [rad]
BUDGET = 0.005  # [s]
REPEATS = 3  # rounds over the problem set; per problem the fastest run counts
DEFAULT_ROBOTS = ("panda", "ur5", "stanford", "era")


@dataclass(frozen=True)
class Case:
    """One benchmark problem: the target is the FK of ``q_target``; every solver starts at ``q_start``."""

    index: int
    q_target: np.ndarray
    q_start: np.ndarray
    oMtarget: pin.SE3


def cases(robot: Robot, n: int, seed: int) -> list[Case]:
    """``n`` seeded problems: targets and starts drawn uniformly within the joint limits."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        q_target, q_start = robot.random_q(rng), robot.random_q(rng)
        out.append(Case(i, q_target, q_start, robot.fk(q_target)))
    return out


def check_solution(robot: Robot, q: np.ndarray | None, oMtarget: pin.SE3, elapsed: float, budget: float = BUDGET,
                   tol_pos: float = TOL_POS, tol_rot: float = TOL_ROT) -> tuple[bool, str]:
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
    dp, dr = robot.tool_error(q, oMtarget)
    if dp > tol_pos or dr > tol_rot:
        return False, f"pose error {dp:.1e} m, {dr:.1e} rad"
    return True, "solved"


# A solver under test: prepare(robot, budget) → solve(case, seed) → (q or None, iterations or -1)
SolveFn = Callable[[Case, int], tuple[np.ndarray | None, int]]
Prepare = Callable[[Robot, float], SolveFn]
