"""The reference solver: Pinocchio damped-least-squares CLIK (log6 error, Jlog6, ``pin.integrate``).

This is the baseline every other kinelab solver is compared with. One attempt from one start; the
restarts, time budget and final check live in :func:`kinelab.solve`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.ik import options as opt
from kinelab.ik.limits import PinLimits
from kinelab.ik.result import Attempt, Status
from kinelab.robot import Robot


@dataclass(frozen=True)
class DLSOptions:
    """Options of the damped-least-squares reference.

    Attributes:
        damping: λ² added to J Jᵀ (Levenberg damping) [in the units of J Jᵀ], ≥ 0.
        step: fraction of the Gauss–Newton step taken per iteration (1 = full step), in (0, 2).
        max_iterations: iteration cap of one attempt.
    """

    damping: float = 1e-6
    step: float = 1.0
    max_iterations: int = 30

    def __post_init__(self) -> None:
        opt.positive("damping", self.damping, zero=True)
        opt.positive("max_iterations", self.max_iterations, integer=True)
        opt.positive("step", self.step)
        if not float(self.step) < 2.0:
            raise OptionError("step", self.step, "a number in (0, 2)")

    @classmethod
    def of(cls, options: DLSOptions | None = None, **kwargs: Any) -> DLSOptions:
        """``options`` as given, or built from keyword arguments (cached for hashable ones)."""
        return opt.resolve(cls, "dls", options, kwargs)


Options = DLSOptions
# the damping grows with the squared error (Levenberg–Marquardt after Sugihara): far from the target the
# steps shorten instead of overshooting into the limits, near it they are Gauss–Newton's
ERROR_DAMPING = 1e-3
# an attempt whose squared error fell by less than STALL_FALL over STALL_ITERATIONS iterations is stalled:
# a restart then costs less than the iterations it has left
STALL_ITERATIONS, STALL_FALL = 5, 0.05


def attempt(
    robot: Robot,
    oMtarget: pin.SE3,
    q0: np.ndarray,
    tol_pos: float,
    tol_rot: float,
    deadline: float,
    options: DLSOptions | None = None,
    **kwargs: Any,
) -> Attempt:
    """Damped Gauss–Newton on the tool's log6 error in the tool frame, from ``q0``; the damping is
    ``damping`` plus 1e-3 of the squared error, and an attempt whose error stops falling ends as stalled.

    Args:
        robot: the robot; oMtarget: the wanted tool pose in the base frame; q0: the start [rad or m].
        tol_pos: position tolerance [m]; tol_rot: rotation tolerance [rad].
        deadline: ``time.perf_counter()`` value after which the attempt stops.
        options: a :class:`DLSOptions`, or its fields as keyword arguments.

    Returns:
        The attempt, before kinelab's Pinocchio check.
    """
    opts = DLSOptions.of(options, **kwargs)
    damping, step, max_iterations = opts.damping, opts.step, opts.max_iterations
    model, data, fid = robot.model, robot.data, robot.tool_frame_id
    limits = PinLimits(robot)
    q = robot.to_pin_q(q0)
    eye = np.eye(6)
    errors: list[float] = []
    for it in range(max_iterations):
        pin.computeJointJacobians(model, data, q)  # FK and every joint Jacobian in one pass
        oMtool = pin.updateFramePlacement(model, data, fid)
        tMd = oMtool.actInv(oMtarget)
        err = pin.log6(tMd).vector
        dp = oMtarget.actInv(oMtool).translation  # position error in the target frame (same norm)
        if math.sqrt(dp @ dp) <= tol_pos and math.sqrt(err[3:] @ err[3:]) <= tol_rot:
            return Attempt(robot.from_pin_q(q), Status.CONVERGED, it)
        if time.perf_counter() > deadline:
            return Attempt(robot.from_pin_q(q), Status.TIME_BUDGET, it)
        size = float(err @ err)
        errors.append(size)
        if len(errors) > STALL_ITERATIONS and size > (1.0 - STALL_FALL) * errors[-1 - STALL_ITERATIONS]:
            return Attempt(robot.from_pin_q(q), Status.STALLED, it)  # held at a limit or a local minimum
        J = pin.getFrameJacobian(model, data, fid, pin.LOCAL)
        J = pin.Jlog6(tMd.inverse()) @ J
        v = J.T @ np.linalg.solve(J @ J.T + (damping + ERROR_DAMPING * size) * eye, err)
        q = limits.project(pin.integrate(model, q, step * v))
    return Attempt(robot.from_pin_q(q), Status.MAX_ITERATIONS, max_iterations)
