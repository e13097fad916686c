"""Tasks of whole-body kinematics: frozen values, each asking one thing of the robot's configuration.

Every task gives, at a configuration, its error ``e`` and a matrix ``A`` such that a velocity v [nv] changes the
error at the rate ``A v`` (first order): the step asks ``A v = −gain · e / dt`` of every task, weighted, and the
converged solve drives every ``e`` to zero. Units: errors in m and rad (posture: rad or m per joint), Jacobians per
unit velocity. Frames are Pinocchio's; a target pose is ``oM*`` in the world frame (a RelativeFrameTask's in its
root frame).

- :class:`FrameTask`: a frame's pose, position, one axis (and the position), or orientation.
- :class:`RelativeFrameTask`: a frame's pose in another frame (one hand in the other's).
- :class:`ComTask`: the centre of mass (all three coordinates, or some: "xy" over the feet).
- :class:`PostureTask`: a reference configuration (the joints not asked for elsewhere).
- :class:`CouplingTask`: one joint a linear function of another (mimic joints, gears), held exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.core._verdict import pose_defect
from kinelab.errors import OptionError, TargetError, count_of
from kinelab.typing import Configuration
from kinelab.values import is_real, mixes_non_reals

FRAME_TASKS = ("pose", "position", "axis", "orientation")
AXES = "xyz"


MAX_WEIGHT = 1e12  # a larger weight squares past what the QP's matrix holds with the rest in it


def _weight(name: str, value: Any) -> float:
    if type(value) is float and 0.0 <= value <= MAX_WEIGHT:  # the usual call, checked at once
        return value
    if not is_real(value, 0, MAX_WEIGHT):
        raise OptionError(name, value, f"a number from 0 to {MAX_WEIGHT:g}")
    return float(value)


def _gain(value: Any) -> float:
    """A task's gain: the share of its error a step asks to close, 0 to 1 (more would overshoot the target)."""
    if not is_real(value, 0, 1):
        raise OptionError("gain", value, "a number from 0 to 1 (the share of the error a step closes)")
    return float(value)


def _weights(value: Any) -> float | np.ndarray:
    """A posture's weight: one number, or one per velocity (a read-only array), each finite and ≥ 0."""
    if isinstance(value, list | tuple | np.ndarray):
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError):
            arr = np.array([np.nan])
        if arr.ndim != 1 or not np.all(np.isfinite(arr)) or np.any(arr < 0) or np.any(arr > MAX_WEIGHT):
            raise OptionError("weight", value, f"a number from 0 to {MAX_WEIGHT:g}, or one per velocity (nv such "
                              "numbers)")
        arr.flags.writeable = False
        return arr
    return _weight("weight", value)


def _priority(value: Any) -> int:
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


def _pose(value: Any, what: str) -> FixedPose:
    """A target pose: an SE3 or a 4 × 4 homogeneous matrix, finite, its rotation a rotation; a copy that cannot
    change.

    Raises:
        TargetError: anything else (named).
    """
    if isinstance(value, pin.SE3):
        H = value.homogeneous
    else:
        H = _real_array(value, f"{what} must be a pin.SE3 or a 4 × 4 homogeneous matrix")
        try:
            H = H.reshape(4, 4)
        except ValueError:
            raise TargetError(f"{what} must be a pin.SE3 or a 4 × 4 homogeneous matrix, got {value!r}") from None
    if pose_defect(H) or np.abs(H[:3, 3]).max() > MAX_COORDINATE:
        raise TargetError(f"{what} is not a finite pose with a proper rotation (orthonormal within 1e-6, det +1, "
                          f"last row 0, 0, 0, 1) and a position within {MAX_COORDINATE:g} m")
    return FixedPose(np.ascontiguousarray(H))


MAX_COORDINATE = 1e6  # [m] a target farther than this from the world's origin is a mistake (and overflows rates)


def _real_array(value: Any, what: str) -> np.ndarray:
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


def _vector(value: Any, size: int, what: str) -> np.ndarray:
    """``size`` finite numbers within MAX_COORDINATE, as a new read-only array."""
    arr = _real_array(value, f"{what} must be {size} numbers")
    if arr.shape != (size,) or not np.isfinite(arr).all():
        raise TargetError(f"{what} must be {size} finite numbers, got {count_of(arr.shape)}")
    if np.abs(arr).max() > MAX_COORDINATE:
        raise TargetError(f"{what} must lie within {MAX_COORDINATE:g} m of the world's origin, got {arr.tolist()}")
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True)
class FrameTask:
    """A frame's pose (or part of it) at a target, in the world frame.

    Attributes:
        frame: the frame's name.
        target: oM* (``pin.SE3`` or 4 × 4); for task "position" three numbers [m] may stand for it.
        task: "pose", "position", "axis" (the position and one axis of the frame along the target's same axis,
            free to turn about it) or "orientation".
        axis: the frame axis of task "axis": "x", "y" or "z".
        weight: the weight of the position error [1/m]; orientation_weight: of the rotation error [1/rad] (None:
            the same number).
        gain: the share of the error the step asks to close in ``dt`` (1: all of it).
        priority: 1, or 2 (in the null space of the priority-1 tasks).
    """

    frame: str
    target: Any
    task: str = "pose"
    axis: str = "z"
    weight: float = 1.0
    orientation_weight: float | None = None
    gain: float = 1.0
    priority: int = 1

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError, TargetError: a field out of what it accepts (named).
        """
        if not isinstance(self.frame, str):
            raise OptionError("frame", self.frame, "a frame name")
        if self.task not in FRAME_TASKS:
            raise OptionError("task", self.task, ", ".join(FRAME_TASKS))
        if self.axis not in ("x", "y", "z"):
            raise OptionError("axis", self.axis, "'x', 'y' or 'z'")
        target = self.target
        if self.task == "position" and not isinstance(target, pin.SE3) and np.size(target) == 3:
            target = pin.SE3(np.eye(3), _vector(target, 3, f"target of {self.frame!r}"))
        object.__setattr__(self, "target", _pose(target, f"the target of frame {self.frame!r}"))
        object.__setattr__(self, "weight", _weight("weight", self.weight))
        ow = self.weight if self.orientation_weight is None else self.orientation_weight
        object.__setattr__(self, "orientation_weight", _weight("orientation_weight", ow))
        object.__setattr__(self, "gain", _gain(self.gain))
        object.__setattr__(self, "priority", _priority(self.priority))

    @property
    def rows(self) -> int:
        """How many rows the task adds to the step's least squares."""
        return {"pose": 6, "position": 3, "axis": 6, "orientation": 3}[self.task]

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for (kept on the task)."""
        found = self.__dict__.get("_shape")
        if found is None:
            found = self.__dict__["_shape"] = ("f", self.frame, self.task, self.axis, self.weight,
                                               self.orientation_weight, self.gain, self.priority)
        return found

    def moved(self, target: pin.SE3 | ArrayLike) -> FrameTask:
        """The same task at another target (checked), its other settings taken as they are: a path's samples.

        Raises:
            TargetError: a target that is not a pose (named).
        """
        made = object.__new__(FrameTask)
        made.__dict__.update(self.__dict__)
        if self.task == "position" and not isinstance(target, pin.SE3) and np.size(target) == 3:
            target = pin.SE3(np.eye(3), _vector(target, 3, f"target of {self.frame!r}"))
        made.__dict__["target"] = _pose(target, f"the target of frame {self.frame!r}")
        return made

    @property
    def label(self) -> str:
        """The task in words (results and messages)."""
        return f"{self.task} of {self.frame}" + (f" ({self.axis} axis)" if self.task == "axis" else "")


@dataclass(frozen=True)
class RelativeFrameTask:
    """A frame's pose in another frame (``root``) at a target: one hand held in the other's frame.

    Attributes:
        frame: the moving frame; root: the frame the target is in.
        target: rootM* (``pin.SE3`` or 4 × 4).
        weight, orientation_weight, gain, priority: as :class:`FrameTask`'s.
    """

    frame: str
    root: str
    target: Any
    weight: float = 1.0
    orientation_weight: float | None = None
    gain: float = 1.0
    priority: int = 1

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError, TargetError: a field out of what it accepts (named).
        """
        if not isinstance(self.frame, str) or not isinstance(self.root, str):
            raise OptionError("frame", (self.frame, self.root), "two frame names")
        object.__setattr__(self, "target", _pose(self.target, f"the target of {self.frame!r} in {self.root!r}"))
        object.__setattr__(self, "weight", _weight("weight", self.weight))
        ow = self.weight if self.orientation_weight is None else self.orientation_weight
        object.__setattr__(self, "orientation_weight", _weight("orientation_weight", ow))
        object.__setattr__(self, "gain", _gain(self.gain))
        object.__setattr__(self, "priority", _priority(self.priority))

    rows = 6

    @property
    def label(self) -> str:
        """The task in words."""
        return f"pose of {self.frame} in {self.root}"

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for."""
        return ("r", self.frame, self.root, self.weight, self.orientation_weight, self.gain, self.priority)


@dataclass(frozen=True)
class ComTask:
    """The centre of mass at a target [m], world frame: all three coordinates, or those ``axes`` names.

    Attributes:
        target: three numbers [m] (the coordinates not in ``axes`` are read but not asked for).
        axes: "xyz", or a part such as "xy" (the CoM over a point of the floor).
        weight [1/m], gain, priority: as :class:`FrameTask`'s.
    """

    target: Any
    axes: str = "xyz"
    weight: float = 1.0
    gain: float = 1.0
    priority: int = 1
    index: tuple[int, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError, TargetError: a field out of what it accepts (named).
        """
        object.__setattr__(self, "target", _vector(self.target, 3, "the centre of mass's target"))
        if not isinstance(self.axes, str) or not self.axes or any(a not in AXES for a in self.axes) \
                or len(set(self.axes)) != len(self.axes):
            raise OptionError("axes", self.axes, "'xyz' or a part of it ('xy', 'z', ...)")
        object.__setattr__(self, "index", tuple(AXES.index(a) for a in self.axes))
        object.__setattr__(self, "weight", _weight("weight", self.weight))
        object.__setattr__(self, "gain", _gain(self.gain))
        object.__setattr__(self, "priority", _priority(self.priority))

    @property
    def rows(self) -> int:
        """How many rows the task adds."""
        return len(self.index)

    @property
    def label(self) -> str:
        """The task in words."""
        return f"centre of mass ({self.axes})"

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for."""
        return ("c", self.axes, self.weight, self.gain, self.priority)


@dataclass(frozen=True)
class PostureTask:
    """A reference configuration: every joint pulled toward ``q_ref`` (Pinocchio's q, nq numbers).

    Attributes:
        q_ref: the reference (None: the robot's neutral configuration, within its limits).
        weight: [1/rad or 1/m] every joint's, or one per velocity (nv numbers ≥ 0; a free-flyer's six are read
            only with ``base``); base: include the free-flyer's six velocities (default: not, the base is placed by
            the other tasks).
        gain, priority: as :class:`FrameTask`'s.
    """

    q_ref: Any = None
    weight: Any = 1e-3
    base: bool = False
    gain: float = 1.0
    priority: int = 1

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        if self.q_ref is not None:
            try:
                arr = _real_array(self.q_ref, "")
            except TargetError:
                arr = np.array([np.nan])
            if arr.ndim != 1 or not np.isfinite(arr).all():
                raise OptionError("q_ref", self.q_ref, "nq finite real numbers (Pinocchio's q), or None")
            arr.flags.writeable = False
            object.__setattr__(self, "q_ref", arr)
        object.__setattr__(self, "weight", _weights(self.weight))
        if not isinstance(self.base, bool):
            raise OptionError("base", self.base, "True or False")
        object.__setattr__(self, "gain", _gain(self.gain))
        object.__setattr__(self, "priority", _priority(self.priority))

    label = "posture"

    def shape(self) -> tuple[Any, ...]:
        """Everything but the reference and per-velocity weights: what a compiled step is packed for (``base``
        last)."""
        weight = ("per velocity", self.weight.size) if isinstance(self.weight, np.ndarray) else self.weight
        return ("p", weight, self.gain, self.priority, self.base)

    def moved(self, q_ref: Configuration | None, weight: float | ArrayLike | None = None) -> PostureTask:
        """The same task toward another reference (and with other weights when given), checked: a follower's
        samples.

        Raises:
            OptionError: a reference or weights that are not numbers.
        """
        return replace(self, q_ref=q_ref, weight=self.weight if weight is None else weight)


@dataclass(frozen=True)
class CouplingTask:
    """Joint ``joint`` held at ``ratio · leader + offset`` [rad or m], exactly (an equality of the step): a mimic
    joint or a gear that the file does not declare.

    Attributes:
        joint, leader: 1-DoF joints' names; ratio: the factor; offset: [rad or m].
    """

    joint: str
    leader: str
    ratio: float = 1.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        if not isinstance(self.joint, str) or not isinstance(self.leader, str) or self.joint == self.leader:
            raise OptionError("joint", (self.joint, self.leader), "two different joint names")
        for name in ("ratio", "offset"):
            value = getattr(self, name)
            if not is_real(value):
                raise OptionError(name, value, "a finite number")
            object.__setattr__(self, name, float(value))

    priority = 0  # held exactly, above every weighted task
    rows = 1

    @property
    def label(self) -> str:
        """The task in words."""
        return f"{self.joint} = {self.ratio:g} × {self.leader} + {self.offset:g}"

    def shape(self) -> tuple[Any, ...]:
        """What a compiled step is packed for (the whole coupling)."""
        return ("k", self.joint, self.leader, self.ratio, self.offset, False)


Task = FrameTask | RelativeFrameTask | ComTask | PostureTask | CouplingTask
TASK_TYPES = (FrameTask, RelativeFrameTask, ComTask, PostureTask, CouplingTask)


def as_tasks(tasks: object) -> tuple[Task, ...]:
    """The tasks of a call: one task or a sequence of them.

    Raises:
        OptionError: anything else (named), or no task at all.
    """
    items: Any = (tasks,) if isinstance(tasks, TASK_TYPES) else tasks
    try:
        found = tuple(items)
    except TypeError:
        raise OptionError("tasks", tasks, "a task (FrameTask, RelativeFrameTask, ComTask, PostureTask, CouplingTask) "
                          "or a list of them") from None
    bad = [t for t in found if not isinstance(t, TASK_TYPES)]
    if bad or not found:
        raise OptionError("tasks", bad[0] if bad else tasks, "FrameTask, RelativeFrameTask, ComTask, PostureTask or "
                          "CouplingTask values (at least one)")
    return found
