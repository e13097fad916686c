"""Targets for IK: a ``pin.SE3`` of the tool in the robot's base frame, helpers that build one, the checks a target
meets, and the reach bound (a cheap, certain test that a target position is out of reach)."""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.core._verdict import NOT_A_ROTATION, NOT_FINITE, NOT_HOMOGENEOUS, first_defect, pose_defect
from kinelab.dq.algebra import DualQuat
from kinelab.errors import TargetError, count_of
from kinelab.robot import Chain
from kinelab.typing import Target, Targets


def from_xyz_rpy(xyz: ArrayLike, rpy: ArrayLike = (0.0, 0.0, 0.0), *, degrees: bool = False) -> pin.SE3:
    """oMtarget from a position [m] and roll-pitch-yaw angles (R = Rz(yaw) Ry(pitch) Rx(roll)).

    Args:
        xyz: the position [m], base frame.
        rpy: roll, pitch, yaw [rad; degrees with ``degrees=True``].
        degrees: the angles are in degrees.

    Raises:
        TargetError: not three finite numbers each, radians beyond ±2π (degrees given as radians, most
            likely: said, with ``degrees=True`` named), or degrees beyond ±3600.
    """
    xyz, rpy = _finite(xyz, 3, "xyz"), _finite(rpy, 3, "rpy")
    if degrees:
        if np.abs(rpy).max() > MAX_DEGREES:
            raise TargetError(f"rpy {rpy.tolist()} [deg]: an angle beyond ±{MAX_DEGREES:g}° (ten turns) is no "
                              "orientation anyone means; give angles within a turn")
        rpy = np.asarray(np.deg2rad(rpy), dtype=float)
    elif np.abs(rpy).max() > DEGREES_LIKELY:
        raise TargetError(f"rpy {rpy.tolist()} looks like degrees (an angle beyond ±2π rad): pass degrees=True, or "
                          "give radians")
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


MAX_DEGREES = 3600.0  # [deg] the largest roll, pitch or yaw taken in degrees
DEGREES_LIKELY = 2 * np.pi + 1e-9  # [rad] an angle beyond this, where radians are expected, was meant in degrees


def from_xyz_quat_wxyz(xyz: ArrayLike, quat_wxyz: ArrayLike) -> pin.SE3:
    """oMtarget from a position [m] and a unit quaternion in (w, x, y, z) order."""
    xyz, quat = _finite(xyz, 3, "xyz"), _finite(quat_wxyz, 4, "quat_wxyz")
    norm = np.linalg.norm(quat)
    if abs(norm - 1.0) > 1e-6:
        raise TargetError(f"quat_wxyz must be a unit quaternion, its norm is {norm:.6g}")
    w, x, y, z = quat / norm
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), xyz)


def as_target(target: Target, task: str = "pose") -> pin.SE3:
    """Check a target: a ``pin.SE3`` with finite entries and a proper rotation, or a unit biquaternion; for
    task "position" also a point (three numbers [m], base frame), taken with the identity rotation.

    Raises:
        TargetError: anything else, or a point given for a task that constrains the rotation.
    """
    if not isinstance(target, pin.SE3 | DualQuat) and _is_point(target):
        if task != "position":
            raise TargetError(f"a point (three numbers) was given as the target of task {task!r}, which needs "
                              "a rotation too; pass task='position' to reach the point with any rotation, or a "
                              "pin.SE3 (kinelab.target_from_xyz_rpy) for a pose")
        return pin.SE3(np.eye(3), _finite(target, 3, "the target point"))
    if isinstance(target, DualQuat):
        return target.require_unit("the target biquaternion").to_se3()
    if not isinstance(target, pin.SE3):
        raise TargetError(
            f"target must be a pin.SE3 (or a unit DualQuat) of the tool in the base frame, "
            f"got {type(target).__name__}; "
            "build one with kinelab.target_from_xyz_rpy or kinelab.target_from_xyz_quat_wxyz"
        )
    defect = pose_defect(target.homogeneous)
    if defect == NOT_FINITE:
        raise TargetError("target has NaN or infinite entries")
    if defect == NOT_A_ROTATION:
        raise TargetError("target rotation is not a rotation matrix (RᵀR ≠ I or det R < 0)")
    return target


def _is_point(target: Any) -> bool:
    """A list, tuple or array of three numbers."""
    if isinstance(target, list | tuple | np.ndarray):
        try:
            return np.shape(target) == (3,)
        except ValueError:
            return False
    return False


def _finite(values: ArrayLike, size: int, what: str) -> np.ndarray:
    try:
        raw = np.asarray(values)
        if raw.dtype.kind not in "fiu":
            raise TypeError
        arr = raw.astype(float)
    except (TypeError, ValueError):
        raise TargetError(f"{what} must be {size} real numbers, got {values!r}") from None
    if arr.shape != (size,):
        raise TargetError(f"{what} must have {size} numbers, got {count_of(arr.shape)}")
    if not np.all(np.isfinite(arr)):
        raise TargetError(f"{what} has NaN or infinite entries: {arr}")
    return arr


class TargetArrays(NamedTuple):
    """Checked targets, base frame: the path or batch once read (what the solvers and followers take)."""

    points: np.ndarray  # (N, 3) [m]
    rotations: np.ndarray  # (N, 3, 3)


def as_target_arrays(targets: Targets) -> TargetArrays:
    """Check a sequence of targets; returns (points (N, 3) [m], rotations (N, 3, 3)), base frame.

    ``targets`` is a sequence of ``pin.SE3`` (or unit biquaternions), or an (N, 4, 4) array of
    homogeneous matrices. A bad target is named by its index. The checks are those of
    :func:`as_target`, made on the whole stack at once.

    Raises:
        TargetError: an empty sequence, a wrong shape or a bad target (its index named).
    """
    H = _stack(targets)
    k, defect = first_defect(H)
    if k >= 0:
        why = {NOT_FINITE: "has NaN or infinite entries", NOT_HOMOGENEOUS: "its last row is not (0, 0, 0, 1)",
               NOT_A_ROTATION: "its rotation is not a rotation matrix (RᵀR ≠ I or det R < 0)"}[defect]
        raise TargetError(f"targets[{k}] {why}")
    return TargetArrays(np.ascontiguousarray(H[:, :3, 3]), np.ascontiguousarray(H[:, :3, :3]))


def _stack(targets: Any) -> np.ndarray:
    """The targets as an (N, 4, 4) float array (N ≥ 1), or a TargetError naming the first that is no pose."""
    if isinstance(targets, np.ndarray) and targets.dtype.kind in "fiu":
        return _array_stack(targets)
    try:
        items = list(targets)
    except TypeError:
        raise TargetError(f"targets must be a sequence of pin.SE3, got {type(targets).__name__}") from None
    if not items:
        raise TargetError("targets is empty: give at least one pin.SE3")
    for k, target in enumerate(items):
        if type(target) is not pin.SE3:  # the usual case passes at once: this loop is most of a large batch's reading
            items[k] = _item(k, target)
    return np.array([t.homogeneous for t in items])


def _array_stack(targets: np.ndarray) -> np.ndarray:
    """A numeric array of targets as (N, 4, 4) floats, or a TargetError naming the shape it has."""
    if targets.ndim != 3 or targets.shape[1:] != (4, 4) or targets.shape[0] == 0:
        raise TargetError(f"targets as an array must have shape (N, 4, 4) with N ≥ 1, got {targets.shape}")
    return np.asarray(targets, dtype=float)


def _item(k: int, target: Any) -> pin.SE3:
    """targets[k] that is not exactly a ``pin.SE3``: a subclass as it is, a unit DualQuat as its pose, else a
    TargetError naming the index."""
    if isinstance(target, DualQuat):
        try:
            return as_target(target)
        except TargetError as err:
            raise TargetError(f"targets[{k}]: {err}") from None
    if not isinstance(target, pin.SE3):
        raise TargetError(f"targets[{k}] must be a pin.SE3 (or a unit DualQuat), got {type(target).__name__}")
    return target


# -- the reach bound: a cheap, certain test that a target position is out of reach ---------------------------
def _reach(robot: Chain) -> tuple[tuple[float, float, float], float]:
    q = robot.neutral()
    oMi = list(robot.joint_placements(q).values())
    anchor = robot.model.jointPlacements[1].translation  # where joint 1 sits, fixed in the base
    points = [anchor] + [m.translation for m in oMi] + [robot.fk(q).translation]
    # each distance between consecutive points is rigid, except along a prismatic joint's slide
    rigid = sum(float(np.linalg.norm(b - a)) for a, b in zip(points, points[1:], strict=False))
    slides = sum(
        max(abs(j.upper - q[i]), abs(j.lower - q[i])) for i, j in enumerate(robot.joints) if j.kind == "prismatic"
    )
    return tuple(np.asarray(anchor, dtype=float).tolist()), rigid + slides


def reach_bound(robot: Chain) -> tuple[tuple[float, float, float], float]:
    """(anchor [m], radius [m]): every reachable tool position lies within the radius of the anchor."""
    return robot.derived("reach_bound", _reach)


def out_of_reach(robot: Chain, position: np.ndarray) -> float:
    """How far [m] a position lies beyond the reach bound (≤ 0 when it may be reachable)."""
    anchor, radius = robot.derived("reach_bound", _reach)
    return math.dist(np.asarray(position, dtype=float).tolist(), anchor) - radius


def beyond_reach(robot: Chain, position: np.ndarray) -> str:
    """Why no configuration can reach ``position`` [m] (base frame) when it lies beyond the reach bound, in words;
    "" when it may be reachable."""
    beyond = out_of_reach(robot, position)
    return f"the target point is at least {beyond:.4g} m beyond the robot's reach" if beyond > 0 else ""
