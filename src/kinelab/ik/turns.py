"""An answer's revolute angles moved by whole turns to the copies nearest a start: the same pose, the answer a
user expects to see next to where the arm stands (``kinelab ik``'s start, the teach page's current q)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from kinelab.ik.limits import nearest_inside
from kinelab.ik.result import IKResult
from kinelab.robot import Chain


def nearest_turns(robot: Chain, result: IKResult, q0: np.ndarray | None, target: pin.SE3, task: str = "pose",
                  axis: str = "z", tol_pos: float = 1e-6, tol_rot: float = 1e-6) -> IKResult:
    """The result with each revolute angle moved by whole turns to the copy nearest ``q0`` within the limits.

    Args:
        robot: the robot.
        result: a solve's result.
        q0: the start [rad or m] (None: the result as it is).
        target: oMtarget (``pin.SE3``, base frame), to judge the moved answer again.
        task: the solve's task ("pose", "position", "axis", "orientation").
        axis: the tool axis of task "axis".
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].

    Returns:
        The moved answer with its errors, judged again as the solve was; the result unchanged when no angle moves,
        the answer failed, or the moved one would not pass (rounding of q + 2πk could, in principle, tip it over).
    """
    revolute = np.array([k != "prismatic" for k in robot.joint_kinds])
    if q0 is None or not result.success or not revolute.any():
        return result
    moved, kept = nearest_inside(result.q[None, :], robot.lower, robot.upper, q0, 0.0)
    q = np.where(revolute, moved[0], result.q) if kept[0] else result.q
    if np.array_equal(q, result.q):
        return result
    return _judged_again(robot, result, q, target, task, axis, (tol_pos, tol_rot))


def _judged_again(robot: Chain, result: IKResult, q: np.ndarray, target: pin.SE3, task: str, axis: str,
                  tolerances: tuple[float, float]) -> IKResult:
    """The result at q when the judge confirms q meets the task's components of ``target`` within the tolerances
    ([m], [rad]) and the limits, else the result unchanged."""
    dp, dr, within = robot.verdict(target.homogeneous, np.ascontiguousarray(q, dtype=float),
                                   "xyz".index(axis) if task == "axis" else -1)
    met = within and (dp <= tolerances[0] or task == "orientation") and (dr <= tolerances[1] or task == "position")
    return replace(result, q=q, position_error=dp, rotation_error=dr) if met else result
