"""What a whole-body task is given, checked and copied: weights, gains, priorities, target poses and points.

A task is a value: it copies what it is given, and its target cannot change afterwards — a pose is a
:class:`FixedPose` (a ``pin.SE3`` whose arrays are read-only and whose setters refuse), a point a read-only array.
Booleans, complex numbers, text and non-finite numbers are refused by name, and so are targets beyond
:data:`MAX_COORDINATE` of the world's origin and weights beyond :data:`MAX_WEIGHT` (past them a step's numbers
overflow).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.core._verdict import pose_defect
from kinelab.errors import OptionError, TargetError, count_of
from kinelab.values import is_real, mixes_non_reals

MAX_WEIGHT = 1e12  # a larger weight squares past what the QP's matrix holds with the rest in it


def weight(name: str, value: Any) -> float:
    """A weight: a number from 0 to MAX_WEIGHT.

    Raises:
        OptionError: anything else (named).
    """
    if type(value) is float and 0.0 <= value <= MAX_WEIGHT:  # the usual call, checked at once
        return value
    if not is_real(value, 0, MAX_WEIGHT):
        raise OptionError(name, value, f"a number from 0 to {MAX_WEIGHT:g}")
    return float(value)


def gain(value: Any) -> float:
    """A task's gain: the share of its error a step asks to close, 0 to 1 (more would overshoot the target).

    Raises:
        OptionError: anything else.
    """
    if type(value) is float and 0.0 <= value <= 1.0:  # the usual call, checked at once
        return value
    if not is_real(value, 0, 1):
        raise OptionError("gain", value, "a number from 0 to 1 (the share of the error a step closes)")
    return float(value)


def weights(value: Any) -> float | np.ndarray:
    """A weight of a posture or a damping: one number, or one per velocity (a read-only array), each 0 to
    MAX_WEIGHT.

    Raises:
        OptionError: anything else (named).
    """
    if isinstance(value, list | tuple | np.ndarray):
        try:
            arr = real_array(value, "weight")
        except TargetError:
            arr = np.array([np.nan])
        if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr < 0) or np.any(arr > MAX_WEIGHT):
            raise OptionError("weight", value, f"a number from 0 to {MAX_WEIGHT:g}, or one per velocity (nv such "
                              "numbers)")
        arr.flags.writeable = False
        return arr
    return weight("weight", value)


def priority(value: Any) -> int:
    """A task's priority: 1, or 2 (in the null space of the priority-1 tasks).

    Raises:
        OptionError: anything else.
    """
    if value not in (1, 2) or isinstance(value, bool):
        raise OptionError("priority", value, "1 (first) or 2 (in the first's null space)")
    return int(value)


FROZEN = ("a task's target is a value, copied when the task is made: make the task anew (or task.moved(target)) "
          "for another target")


class FixedPose(pin.SE3):
    """A task's target pose: a ``pin.SE3`` that cannot change. Its rotation and translation are read-only views
    and its setters refuse, so that what a step answers for is what its task was given (a caller's SE3 is copied,
    never kept)."""

    __slots__ = ()

    @property
    def translation(self) -> np.ndarray:
        """The position [m], read-only."""
        view = pin.SE3.translation.fget(self)
        view.flags.writeable = False
        return view

    @translation.setter
    def translation(self, value: Any) -> None:
        raise TargetError(FROZEN)

    @property
    def rotation(self) -> np.ndarray:
        """The rotation matrix, read-only."""
        view = pin.SE3.rotation.fget(self)
        view.flags.writeable = False
        return view

    @rotation.setter
    def rotation(self, value: Any) -> None:
        raise TargetError(FROZEN)

    @property
    def homogeneous(self) -> np.ndarray:
        """The 4 × 4 matrix (a copy)."""
        return pin.SE3.homogeneous.fget(self)

    @homogeneous.setter
    def homogeneous(self, value: Any) -> None:
        raise TargetError(FROZEN)

    def setIdentity(self) -> FixedPose:
        """Refused: a target is a value."""
        raise TargetError(FROZEN)

    def setRandom(self) -> FixedPose:
        """Refused: a target is a value."""
        raise TargetError(FROZEN)

    def __reduce__(self) -> tuple[Any, ...]:
        return FixedPose, (pin.SE3.homogeneous.fget(self),)

    def __copy__(self) -> FixedPose:
        return self  # a value: a copy would be the same

    def __deepcopy__(self, memo: dict[int, Any]) -> FixedPose:
        return self


def pose(value: Any, what: str) -> FixedPose:
    """A target pose: an SE3 or a 4 × 4 homogeneous matrix, finite, its rotation a rotation; a copy that cannot
    change.

    Raises:
        TargetError: anything else (named).
    """
    se3 = isinstance(value, pin.SE3)
    if se3:
        H = value.homogeneous
    else:
        H = real_array(value, f"{what} must be a pin.SE3 or a 4 × 4 homogeneous matrix")
        try:
            H = H.reshape(4, 4)
        except ValueError:
            raise TargetError(f"{what} must be a pin.SE3 or a 4 × 4 homogeneous matrix, got {value!r}") from None
    if pose_defect(H) or not math.hypot(*H[:3, 3].tolist()) <= MAX_COORDINATE:
        raise TargetError(f"{what} is not a finite pose with a proper rotation (orthonormal within 1e-6, det +1, "
                          f"last row 0, 0, 0, 1) and a position within {MAX_COORDINATE:g} m")
    return FixedPose(value if se3 else H)  # an SE3 copied as it is (the faster of the two)


MAX_COORDINATE = 1e6  # [m] a target farther than this from the world's origin is a mistake (and overflows rates)


def real_array(value: Any, what: str) -> np.ndarray:
    """``value`` as a new float array; booleans, complex numbers, strings and objects refused (``what`` says what
    was expected)."""
    try:
        arr = np.array(value)
    except (TypeError, ValueError):
        raise TargetError(f"{what}, got {value!r}") from None
    if mixes_non_reals(value):
        raise TargetError(f"{what} (real numbers only: a bool or a complex number among them), got {value!r}")
    if arr.dtype.kind not in "iuf":  # booleans, complex numbers, text and objects are not coordinates
        raise TargetError(f"{what} (real numbers, not {arr.dtype.name}), got {value!r}")
    return arr.astype(float)


def vector(value: Any, size: int, what: str) -> np.ndarray:
    """``size`` finite numbers within MAX_COORDINATE, as a new read-only array."""
    arr = real_array(value, f"{what} must be {size} numbers")
    if arr.shape != (size,) or not np.isfinite(arr).all():
        raise TargetError(f"{what} must be {size} finite numbers, got {count_of(arr.shape)}")
    if np.abs(arr).max() > MAX_COORDINATE:
        raise TargetError(f"{what} must lie within {MAX_COORDINATE:g} m of the world's origin, got {arr.tolist()}")
    arr.flags.writeable = False
    return arr
