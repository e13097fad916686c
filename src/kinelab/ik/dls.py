"""The reference solver: Pinocchio damped-least-squares CLIK (log6 error, Jlog6, ``pin.integrate``).

This is the baseline every other kinelab solver is compared with. One attempt from one start; the
restarts, time budget and final check live in :func:`kinelab.solve`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.ik import options as opt
from kinelab.ik.limits import PinLimits
from kinelab.ik.result import Attempt, Status
from kinelab.ik.tasks import Task
from kinelab.robot import Chain


@dataclass(frozen=True)
class DLSOptions:
    """Options of the damped-least-squares reference.

    Attributes:
        damping: λ² added to J Jᵀ (Levenberg damping) [in the units of J Jᵀ], ≥ 0.
        step: fraction of the Gauss–Newton step taken per iteration (1 = full step), in (0, 2).
        max_iterations: iteration cap of one attempt.
        task: the task's rows of the error and Jacobian (:mod:`kinelab.ik.tasks`): "pose" (all six),
            "position" (the three linear rows), "orientation" (the three angular rows) or "axis" (the
            linear rows and the two angular rows across the tool axis ``tool_axis``).
        tool_axis: the axis of task "axis": "x", "y" or "z".
    """

    damping: float = 1e-6
    step: float = 1.0
    max_iterations: int = 30
    task: str = "pose"
    tool_axis: str = "z"

    def __post_init__(self) -> None:
        opt.positive("damping", self.damping, zero=True)
        opt.positive("max_iterations", self.max_iterations, integer=True)
        opt.positive("step", self.step)
        opt.choice("task", self.task, ("pose", "position", "axis", "orientation"), what="task")
        opt.choice("tool_axis", self.tool_axis, ("x", "y", "z"), what="tool axis")
        if not float(self.step) < 2.0:
            raise OptionError("step", self.step, "a number in (0, 2)")

    def for_task(self, task: Task) -> DLSOptions:
        """These options for a :class:`~kinelab.ik.tasks.Task` (cached)."""
        return self if task.name == "pose" else _for_task(self, task)

    @classmethod
    def of(cls, options: DLSOptions | None = None, **kwargs: object) -> DLSOptions:
        """``options`` as given, or built from keyword arguments (cached for hashable ones)."""
        return opt.resolve(cls, "dls", options, kwargs)


Options = DLSOptions


@functools.lru_cache(maxsize=64)
def _for_task(opts: DLSOptions, task: Task) -> DLSOptions:
    return dataclasses.replace(opts, task=task.name, tool_axis="xyz"[task.axis] if task.axis >= 0 else opts.tool_axis)

# the damping grows with the squared error (Levenberg–Marquardt after Sugihara): far from the target the
# steps shorten instead of overshooting into the limits, near it they are Gauss–Newton's
ERROR_DAMPING = 1e-3
# an attempt whose squared error fell by less than STALL_FALL over STALL_ITERATIONS iterations is stalled:
# a restart then costs less than the iterations it has left
STALL_ITERATIONS, STALL_FALL = 5, 0.05


def attempt(
    robot: Chain,
    oMtarget: pin.SE3,
    q0: np.ndarray,
    tol_pos: float,
    tol_rot: float,
    deadline: float,
    options: DLSOptions | None = None,
    **kwargs: object,
) -> Attempt:
    """Damped Gauss–Newton on the tool's log6 error in the tool frame, from ``q0``; the damping is
    ``damping`` plus 1e-3 of the squared error, and an attempt whose error stops falling ends as stalled.

    Args:
        robot: the robot.
        oMtarget: the wanted tool pose in the base frame.
        q0: the start [rad or m].
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        deadline: ``time.perf_counter()`` value after which the attempt stops.
        options: a :class:`DLSOptions`.
        kwargs: or its fields as keyword arguments.

    Returns:
        The attempt, before kinelab's Pinocchio check.
    """
    opts = DLSOptions.of(options, **kwargs)
    model, data, fid = robot.model, robot.data, robot.tool_frame_id
    limits = PinLimits(robot)
    task = Task.of(opts.task, opts.tool_axis)
    q = robot.to_pin_q(q0)
    errors: list[float] = []
    for it in range(opts.max_iterations):
        pin.computeJointJacobians(model, data, q)  # FK and every joint Jacobian in one pass
        oMtool = pin.updateFramePlacement(model, data, fid)
        # (6, nv) even for one joint: Pinocchio returns a 6 × 1 Jacobian as a flat (6,) array
        J_local = pin.getFrameJacobian(model, data, fid, pin.LOCAL).reshape(6, model.nv)
        err, J = _rows(task, oMtool, oMtarget, J_local)
        dp, dr = task.errors(oMtarget, oMtool)
        if task.met(dp, dr, tol_pos, tol_rot):
            return Attempt(robot.from_pin_q(q), Status.CONVERGED, it)
        if time.perf_counter() > deadline:
            return Attempt(robot.from_pin_q(q), Status.TIME_BUDGET, it)
        with np.errstate(over="ignore"):
            size = float(err @ err)
        errors.append(size)
        if len(errors) > STALL_ITERATIONS and size > (1.0 - STALL_FALL) * errors[-1 - STALL_ITERATIONS]:
            return Attempt(robot.from_pin_q(q), Status.STALLED, it)  # held at a limit or a local minimum
        with np.errstate(over="ignore", invalid="ignore"):
            v = J.T @ np.linalg.solve(J @ J.T + (opts.damping + ERROR_DAMPING * size) * np.eye(len(err)), err)
        if not (math.isfinite(size) and np.all(np.isfinite(v))):  # a target too far for floating point
            return Attempt(robot.from_pin_q(q), Status.STALLED, it)  # the last finite q, not a NaN one
        q = limits.project(pin.integrate(model, q, opts.step * v))
    return Attempt(robot.from_pin_q(q), Status.MAX_ITERATIONS, opts.max_iterations)


def _rows(task: Task, oMtool: pin.SE3, oMtarget: pin.SE3, J_local: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The task's error (tool frame) and the matching rows of Jlog6 · J_local.

    Pose: the log6 error. Position: the target point in the tool frame against the linear rows. Orientation:
    log3 of the relative rotation against the angular rows. Axis: the linear rows, and the two angular rows
    across the tool axis k, with the error the rotation taking the tool's axis onto the target's (u × u*,
    scaled to the angle, in the tool frame): the roll about k is left free.
    """
    tMd = oMtool.actInv(oMtarget)
    if task.name == "pose":
        return pin.log6(tMd).vector, pin.Jlog6(tMd.inverse()) @ J_local
    if task.name == "position":
        return tMd.translation, J_local[:3]
    if task.name == "orientation":
        return pin.log3(tMd.rotation), pin.Jlog3(tMd.rotation.T) @ J_local[3:]
    k = task.axis
    target_axis = tMd.rotation[:, k]  # the target's axis k in the tool frame; the tool's own is e_k
    cross = np.cross(np.eye(3)[k], target_axis)
    sine = float(np.linalg.norm(cross))
    angle = np.arctan2(sine, float(target_axis[k]))
    rotvec = cross * (angle / sine) if sine > 1e-12 else np.zeros(3)
    across = [i for i in range(3) if i != k]
    err = np.concatenate([tMd.translation, rotvec[across]])
    return err, np.vstack([J_local[:3], J_local[3:][across]])
