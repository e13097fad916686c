"""Tasks of whole-body kinematics: values, each asking one thing of the robot's configuration and answering for it.

Every task gives, at a configuration, its error ``e`` and a matrix ``A`` such that a velocity v [nv] changes the
error at the rate ``A v`` (first order): the step asks ``A v = −gain · e / dt`` of every task, weighted, and the
converged solve drives every ``e`` to zero. Units: errors in m and rad (posture: rad or m per joint), Jacobians per
unit velocity. Frames are Pinocchio's; a target pose is ``oM*`` in the world frame (a RelativeFrameTask's in its
root frame).

What a task is, is decided here and nowhere else: each kind is a :class:`Task` and answers, through its own
methods, for what every part of kinelab asks of it — its rows of the readable step (:meth:`Task.add_to`), its block
of the compiled step (:meth:`Task.pack`, :meth:`Task.refresh`), its points for FRDM on the tree
(:meth:`Task.points`) and its errors for the converged solve's verdict (:meth:`Task.judged`). A new task is one
class (docs/extending.md).

- :class:`FrameTask`: a frame's pose, position, one axis (and the position), or orientation.
- :class:`RelativeFrameTask`: a frame's pose in another frame (one hand in the other's).
- :class:`ComTask`: the centre of mass (all three coordinates, or some: "xy" over the feet).
- :class:`PostureTask`: a reference configuration (the joints not asked for elsewhere).
- :class:`DampingTask`: small velocities (a weight on ‖v‖², per velocity if wanted).
- :class:`~kinelab.wholebody.constraints.CouplingTask`: one joint a linear function of another, held exactly.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.errors import OptionError
from kinelab.typing import Configuration
from kinelab.wholebody import targets as tg
from kinelab.wholebody.evaluate import LOCAL, Packing, PointRow, Rowset, StepRows, TargetSlots, skew
from kinelab.wholebody.targets import FixedPose

if TYPE_CHECKING:
    from kinelab.robot.tree import Robot

FRAME_TASKS = ("pose", "position", "axis", "orientation")
AXES = "xyz"
KINDS = {"pose": 0, "position": 1, "orientation": 2, "axis": 3}  # the compiled step's codes of a frame task
T_RELATIVE, T_COM = 4, 5


@dataclass(frozen=True)
class Placement:
    """A frame a task places outright in the world: its name, its target oM* and which part of it the task asks for
    (``kind``: "pose", "position", "axis" or "orientation"; ``axis``: the frame axis of kind "axis")."""

    frame: str
    target: pin.SE3
    kind: str
    axis: str


@dataclass(frozen=True)
class TaskError:
    """One task's error at a configuration: position [m] and rotation [rad] (0 where the task has none; a posture's
    and a coupling's in ``position``, their largest joint gap [rad or m])."""

    label: str
    position: float
    rotation: float


class Task(ABC):
    """What every task answers for (see the module's docstring). A subclass is a frozen dataclass with a
    ``priority`` (1, or 2 in the first's null space; 0: held exactly) and a :attr:`label`."""

    priority: int
    uses_com: ClassVar[bool] = False  # the readable step computes the centre of mass and its Jacobian for it
    preference: ClassVar[bool] = False  # never judged, left out of the converged solve's merit (a posture)
    settled: ClassVar[bool] = False  # projected onto after each step (a nonlinear equality's second-order drift)
    tolerance: ClassVar[float] = 0.0  # a tighter tolerance [m, rad] its verdict holds it to (0: the solve's)

    @property
    @abstractmethod
    def label(self) -> str:
        """The task in words (results and messages)."""

    def check(self, robot: Robot) -> None:
        """Name a frame or joint the robot does not have (before any work).

        Raises:
            FrameNotFoundError, JointNotFoundError, OptionError, ConfigurationError: named.
        """
        return None  # a task that names nothing has nothing to check

    @abstractmethod
    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """Put the task's terms into the readable step's rows at q (``robot.data`` holds Pinocchio's pass there),
        and return its error there."""

    @abstractmethod
    def pack(self, packer: Packing, robot: Robot) -> None:
        """Put the task's block into the compiled problem being packed (its target set by :meth:`refresh`)."""

    def refresh(self, packed: TargetSlots, robot: Robot, slot: int) -> None:
        """Write this task's target into the compiled problem's ``slot`` (per call: what the task holds now)."""
        return None  # a task with no target (a damping) writes nothing

    @abstractmethod
    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled problem is packed for."""

    def points(self, robot: Robot, data: pin.Data, com: np.ndarray | None) -> list[PointRow]:
        """The task's points for FRDM on the tree, at the configuration in ``data`` (none: left to the finish)."""
        return []

    @abstractmethod
    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """(position [m], rotation [rad]) error at q from Pinocchio's placements in ``data`` (and ``com``)."""

    def placement(self) -> Placement | None:
        """The frame this task places outright in the world, for the converged solve's first move
        (:mod:`~kinelab.wholebody.approach`); None: it places none (the default)."""
        return None

    def project(self, robot: Robot, q: np.ndarray) -> bool:
        """Make q meet the task exactly where it can be set outright (a coupling; q changed in place); whether q
        meets it now as far as setting goes (False: the setting failed and q is unchanged)."""
        return True  # a task met only by moving toward it: nothing to set

    def second(self, pull: bool = True) -> Task:
        """The task as the converged solve asks for it (a posture: second, so that it never holds a task off; with
        ``pull`` False, holding the joints where they are instead of pulling them to its reference)."""
        return self

    def moved(self, target: Any) -> Task:
        """The same task at another target (checked), its other settings taken as they are.

        Raises:
            OptionError: a task with no target (a damping, a coupling). TargetError: a target that is not one.
        """
        raise OptionError("target", target, f"a task with a target ({self.label} has none to move)")

    def _target(self, target: Any) -> Any:
        """``target`` checked and copied as this task holds it."""
        return target

    def _with_target(self, target: Any) -> Any:
        """A copy of this task holding ``target`` (checked), made without checking the other fields again."""
        made = object.__new__(type(self))
        made.__dict__.update(self.__dict__)
        made.__dict__["target"] = self._target(target)
        return made


class _Frame(Task):
    """A task on frames: its rows from Pinocchio's Jacobians, its error split into position and rotation."""

    frame: str
    target: FixedPose
    weight: float
    orientation_weight: float | None
    gain: float

    @abstractmethod
    def rows(self, robot: Robot) -> Rowset:
        """(A, e, per-row weight, a pose's translation gap) at ``robot.data``'s configuration."""

    def _check_weights(self) -> None:
        """The weights, the gain and the priority checked (the orientation weight the position's where None).

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        object.__setattr__(self, "weight", tg.weight("weight", self.weight))
        ow = self.weight if self.orientation_weight is None else self.orientation_weight
        object.__setattr__(self, "orientation_weight", tg.weight("orientation_weight", ow))
        object.__setattr__(self, "gain", tg.gain(self.gain))
        object.__setattr__(self, "priority", tg.priority(self.priority))

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """The weighted rows ``A v ≈ −gain · e / dt`` at the task's level."""
        A, e, w, gap = self.rows(robot)
        rows.levels[self.priority - 1].add(A, -self.gain * e / dt, w)
        return self.error_of(e, gap)

    def error_of(self, e: np.ndarray, gap: np.ndarray | None) -> TaskError:
        """The error in m and rad of an error vector: the position the gap's length (or e's linear part), the
        rotation its log's angular part."""
        rot = e[3:]
        return TaskError(self.label, math.hypot(*(e[:3] if gap is None else gap)), math.hypot(*rot))

    def check(self, robot: Robot) -> None:
        """Name an unknown frame.

        Raises:
            FrameNotFoundError: named.
        """
        robot.frame_id(self.frame)

    def refresh(self, packed: TargetSlots, robot: Robot, slot: int) -> None:
        """The target pose, per call."""
        packed.set_pose(slot, self.target.homogeneous)


@dataclass(frozen=True)
class FrameTask(_Frame):
    """A frame's pose (or part of it) at a target, in the world frame.

    Attributes:
        frame: the frame's name.
        target: oM* (``pin.SE3`` or 4 × 4, copied); for task "position" three numbers [m] may stand for it.
        task: "pose", "position", "axis" (the position and one axis of the frame along the target's same axis,
            free to turn about it) or "orientation".
        axis: the frame axis of task "axis": "x", "y" or "z".
        weight: the weight of the position error [1/m]; orientation_weight: of the rotation error [1/rad] (None:
            the same number).
        gain: the share of the error the step asks to close in ``dt``, 0 to 1 (1: all of it).
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
        object.__setattr__(self, "target", self._target(self.target))
        self._check_weights()

    def _target(self, target: Any) -> FixedPose:
        if self.task == "position" and not isinstance(target, pin.SE3) and np.size(target) == 3:
            target = pin.SE3(np.eye(3), tg.vector(target, 3, f"target of {self.frame!r}"))
        return tg.pose(target, f"the target of frame {self.frame!r}")

    @property
    def rows_count(self) -> int:
        """How many rows the task adds to the step's least squares."""
        return {"pose": 6, "position": 3, "axis": 6, "orientation": 3}[self.task]

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for."""
        return ("f", self.frame, self.task, self.axis, self.weight, self.orientation_weight, self.gain, self.priority)

    def moved(self, target: pin.SE3 | ArrayLike) -> FrameTask:
        """The same task at another target (checked), its other settings taken as they are: a path's samples.

        Raises:
            TargetError: a target that is not a pose (named).
        """
        made: FrameTask = self._with_target(target)
        return made

    @property
    def label(self) -> str:
        """The task in words (results and messages)."""
        return f"{self.task} of {self.frame}" + (f" ({self.axis} axis)" if self.task == "axis" else "")

    def rows(self, robot: Robot) -> Rowset:
        """(A, e, per-row weight, None) at ``robot.data``'s configuration: the position's rows in world axes, the
        rotation's ``−Jlog3(E_Rᵀ)`` times the frame's angular Jacobian, an axis's the two unit axes' difference."""
        fid = robot.frame_id(self.frame)
        oMf = robot.data.oMf[fid]
        J = pin.getFrameJacobian(robot.model, robot.data, fid, LOCAL)
        wp, wo = self.weight, float(self.orientation_weight or 0.0)
        R, t = oMf.rotation, oMf.translation - self.target.translation
        if self.task == "position":
            return R @ J[:3], t, np.full(3, wp), None
        if self.task == "axis":
            k = AXES.index(self.axis)
            a = R[:, k]
            A = np.vstack([R @ J[:3], -skew(a) @ R @ J[3:]])
            return A, np.concatenate([t, a - self.target.rotation[:, k]]), np.array([wp] * 3 + [wo] * 3), None
        E_R = R.T @ self.target.rotation
        rot_A, rot_e = -pin.Jlog3(E_R.T) @ J[3:], pin.log3(E_R)
        if self.task == "orientation":
            return rot_A, rot_e, np.full(3, wo), None
        return np.vstack([R @ J[:3], rot_A]), np.concatenate([t, rot_e]), np.array([wp] * 3 + [wo] * 3), None

    def error_of(self, e: np.ndarray, gap: np.ndarray | None) -> TaskError:
        """The error in m and rad (an axis's angle from the two unit axes' difference)."""
        if self.task == "position":
            return TaskError(self.label, math.hypot(*e), 0.0)
        if self.task == "orientation":
            return TaskError(self.label, 0.0, math.hypot(*e))
        if self.task == "axis":
            return TaskError(self.label, math.hypot(*e[:3]), 2.0 * math.asin(min(1.0, math.hypot(*e[3:]) / 2.0)))
        return super().error_of(e, gap)

    def pack(self, packer: Packing, robot: Robot) -> None:
        """A frame block: the frame's joint and placement, the task's code and axis."""
        frame = robot.model.frames[robot.frame_id(self.frame)]
        packer.weighted(self, KINDS[self.task], frame.parentJoint, frame.placement, AXES.index(self.axis))

    def points(self, robot: Robot, data: pin.Data, com: np.ndarray | None) -> list[PointRow]:
        """The origin (unless only the orientation is asked for) and the axes the task constrains."""
        return frame_points(robot, self, data, self.target, -1, self.task, self.axis)

    def placement(self) -> Placement:
        """The frame, its target and the part of it asked for."""
        return Placement(self.frame, self.target, self.task, self.axis)

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """The frame's errors by Pinocchio's placement."""
        return frame_gap(data.oMf[robot.frame_id(self.frame)], self.target, self.task, AXES.index(self.axis))


@dataclass(frozen=True)
class RelativeFrameTask(_Frame):
    """A frame's pose in another frame (``root``) at a target: one hand held in the other's frame.

    Attributes:
        frame: the moving frame; root: the frame the target is in.
        target: rootM* (``pin.SE3`` or 4 × 4, copied).
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
        object.__setattr__(self, "target", self._target(self.target))
        self._check_weights()

    rows_count = 6

    def _target(self, target: Any) -> FixedPose:
        return tg.pose(target, f"the target of {self.frame!r} in {self.root!r}")

    def moved(self, target: pin.SE3 | ArrayLike) -> RelativeFrameTask:
        """The same task at another target (rootM*, checked).

        Raises:
            TargetError: a target that is not a pose (named).
        """
        made: RelativeFrameTask = self._with_target(target)
        return made

    @property
    def label(self) -> str:
        """The task in words."""
        return f"pose of {self.frame} in {self.root}"

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for."""
        return ("r", self.frame, self.root, self.weight, self.orientation_weight, self.gain, self.priority)

    def check(self, robot: Robot) -> None:
        """Name an unknown frame.

        Raises:
            FrameNotFoundError: named.
        """
        robot.frame_id(self.frame), robot.frame_id(self.root)

    def rows(self, robot: Robot) -> Rowset:
        """(A, e, per-row weight, None): the frame's body velocity less the root's, in the root frame."""
        fid, rid = robot.frame_id(self.frame), robot.frame_id(self.root)
        oMf, oMr = robot.data.oMf[fid], robot.data.oMf[rid]
        Jf = pin.getFrameJacobian(robot.model, robot.data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        Jr = pin.getFrameJacobian(robot.model, robot.data, rid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        Rr, Rf = oMr.rotation, oMf.rotation
        gap = oMf.translation - oMr.translation
        E_R = Rf.T @ Rr @ self.target.rotation
        A = np.vstack([Rr.T @ (Jf[:3] - Jr[:3] + skew(gap) @ Jr[3:]), -pin.Jlog3(E_R.T) @ Rf.T @ (Jf[3:] - Jr[3:])])
        e = np.concatenate([Rr.T @ gap - self.target.translation, pin.log3(E_R)])
        wp, wo = self.weight, float(self.orientation_weight or 0.0)
        return A, e, np.array([wp, wp, wp, wo, wo, wo]), None

    def pack(self, packer: Packing, robot: Robot) -> None:
        """A relative block: both frames' joints and placements."""
        frame = robot.model.frames[robot.frame_id(self.frame)]
        other = robot.model.frames[robot.frame_id(self.root)]
        packer.weighted(self, T_RELATIVE, frame.parentJoint, frame.placement, 0, other.parentJoint, other.placement)

    def points(self, robot: Robot, data: pin.Data, com: np.ndarray | None) -> list[PointRow]:
        """The frame's origin and axes, their targets carried by the root frame."""
        by = robot.frame_id(self.root)
        return frame_points(robot, self, data, data.oMf[by] * self.target, by, "pose", "z")

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """The pose's errors in the root frame, by Pinocchio's placements."""
        rMf = data.oMf[robot.frame_id(self.root)].actInv(data.oMf[robot.frame_id(self.frame)])
        return frame_gap(rMf, self.target, "pose", 0)


def frame_points(robot: Robot, task: _Frame, data: pin.Data, target: pin.SE3, by: int, kind: str,
                 axis: str) -> list[PointRow]:
    """A frame task's FRDM points: its origin (unless only its orientation is asked for) and the axes its ``kind``
    constrains, each with its target (``by``: the frame carrying the target, or -1)."""
    fid = robot.frame_id(task.frame)
    oMf = data.oMf[fid]
    fixed = np.zeros(3)
    rows = [] if kind == "orientation" else [(fid, oMf.translation, target.translation, task.weight, False, by, fixed)]
    axes = [AXES.index(axis)] if kind == "axis" else range(3) if kind in ("pose", "orientation") else []
    weight = 0.5 * float(task.orientation_weight or 0.0)  # Σ‖R eₖ − R* eₖ‖² ≈ 2θ²: θ² counted once
    return rows + [(fid, oMf.rotation[:, k], target.rotation[:, k], weight, True, by, fixed) for k in axes]


def frame_gap(M: pin.SE3, target: pin.SE3, kind: str, axis: int) -> tuple[float, float]:
    """(position, rotation) error of pose M against target for a frame task of ``kind``."""
    dp = 0.0 if kind == "orientation" else float(np.linalg.norm(M.translation - target.translation))
    if kind == "position":
        return dp, 0.0
    if kind == "axis":
        u, v = M.rotation[:, axis], target.rotation[:, axis]
        return dp, float(math.atan2(np.linalg.norm(np.cross(u, v)), float(u @ v)))
    return dp, float(np.linalg.norm(pin.log3(M.rotation.T @ target.rotation)))


@dataclass(frozen=True)
class ComTask(Task):
    """The centre of mass at a target [m], world frame: all three coordinates, or those ``axes`` names.

    Attributes:
        target: three numbers [m] (copied; the coordinates not in ``axes`` are read but not asked for).
        axes: "xyz", or a part such as "xy" (the CoM over a point of the floor).
        weight [1/m], gain, priority: as :class:`FrameTask`'s.
    """

    target: Any
    axes: str = "xyz"
    weight: float = 1.0
    gain: float = 1.0
    priority: int = 1
    index: tuple[int, ...] = field(init=False, repr=False, compare=False)
    uses_com: ClassVar[bool] = True

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError, TargetError: a field out of what it accepts (named).
        """
        object.__setattr__(self, "target", self._target(self.target))
        if not isinstance(self.axes, str) or not self.axes or any(a not in AXES for a in self.axes) \
                or len(set(self.axes)) != len(self.axes):
            raise OptionError("axes", self.axes, "'xyz' or a part of it ('xy', 'z', ...)")
        object.__setattr__(self, "index", tuple(AXES.index(a) for a in self.axes))
        object.__setattr__(self, "weight", tg.weight("weight", self.weight))
        object.__setattr__(self, "gain", tg.gain(self.gain))
        object.__setattr__(self, "priority", tg.priority(self.priority))

    @property
    def rows_count(self) -> int:
        """How many rows the task adds."""
        return len(self.index)

    def _target(self, target: Any) -> np.ndarray:
        return tg.vector(target, 3, "the centre of mass's target")

    def moved(self, target: ArrayLike) -> ComTask:
        """The same task at another target [m] (checked).

        Raises:
            TargetError: a target that is not three finite numbers (named).
        """
        made: ComTask = self._with_target(target)
        return made

    @property
    def label(self) -> str:
        """The task in words."""
        return f"centre of mass ({self.axes})"

    def shape(self) -> tuple[Any, ...]:
        """Everything but the target: what a compiled step is packed for."""
        return ("c", self.axes, self.weight, self.gain, self.priority)

    def rows(self, robot: Robot) -> Rowset:
        """(A, e, per-row weight, None) from Pinocchio's centre of mass and its Jacobian."""
        index = list(self.index)
        return robot.data.Jcom[index], (robot.data.com[0] - self.target)[index], np.full(len(index), self.weight), None

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """The weighted rows of the coordinates asked for."""
        A, e, w, _ = self.rows(robot)
        rows.levels[self.priority - 1].add(A, -self.gain * e / dt, w)
        return TaskError(self.label, math.hypot(*e), 0.0)

    def pack(self, packer: Packing, robot: Robot) -> None:
        """A centre-of-mass block (its coordinates as bits)."""
        packer.weighted(self, T_COM, 0, None, sum(1 << i for i in self.index))

    def refresh(self, packed: TargetSlots, robot: Robot, slot: int) -> None:
        """The target point, per call."""
        packed.set_point(slot, self.target)

    def points(self, robot: Robot, data: pin.Data, com: np.ndarray | None) -> list[PointRow]:
        """The centre of mass as a point: its free coordinates' targets are their current values, and follow it."""
        assert com is not None
        index = list(self.index)
        goal = com.copy()
        goal[index] = self.target[index]
        follows = np.ones(3)
        follows[index] = 0.0
        return [(-1, com, goal, self.weight, False, -1, follows)]

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """The distance of the coordinates asked for, by Pinocchio's centre of mass."""
        assert com is not None
        return float(np.linalg.norm((com - self.target)[list(self.index)])), 0.0


@dataclass(frozen=True)
class PostureTask(Task):
    """A reference configuration: every joint pulled toward ``q_ref`` (Pinocchio's q, nq numbers).

    Attributes:
        q_ref: the reference (copied; None: the robot's neutral configuration, within its limits).
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
    preference: ClassVar[bool] = True

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        if self.q_ref is not None:
            try:
                arr = tg.real_array(self.q_ref, "")
            except Exception:  # noqa: BLE001 - any refusal of the numbers is the field's
                arr = np.array([np.nan])
            if arr.ndim != 1 or not np.isfinite(arr).all():
                raise OptionError("q_ref", self.q_ref, "nq finite real numbers (Pinocchio's q), or None")
            arr.flags.writeable = False
            object.__setattr__(self, "q_ref", arr)
        object.__setattr__(self, "weight", tg.weights(self.weight))
        if not isinstance(self.base, bool):
            raise OptionError("base", self.base, "True or False")
        object.__setattr__(self, "gain", tg.gain(self.gain))
        object.__setattr__(self, "priority", tg.priority(self.priority))

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

    def check(self, robot: Robot) -> None:
        """Name a reference or weights that do not fit the robot.

        Raises:
            ConfigurationError, OptionError: named.
        """
        self.reference(robot)
        self.weights(robot)

    def mask(self, robot: Robot) -> np.ndarray:
        """(nv,) the velocities the posture pulls (all but a free-flyer's six unless ``base``)."""
        mask = np.ones(robot.nv, dtype=bool)
        if robot.floating and not self.base:
            mask[:6] = False
        return mask

    def weights(self, robot: Robot) -> np.ndarray:
        """(nv,) the weight per velocity (zero where it does not pull).

        Raises:
            OptionError: per-velocity weights of another length than nv.
        """
        return _per_velocity(robot, self.weight) * self.mask(robot)

    def reference(self, robot: Robot) -> np.ndarray:
        """The reference q (the robot's neutral one for None).

        Raises:
            ConfigurationError: a q_ref that is not a configuration of the robot.
        """
        if self.q_ref is None:
            return robot.neutral()
        return robot.check_q(self.q_ref, what="PostureTask.q_ref")  # its shape, quaternions, coordinates

    def error_at(self, robot: Robot, q: np.ndarray) -> np.ndarray:
        """q ⊖ q_ref (nv) [rad or m]."""
        return np.asarray(pin.difference(robot.model, self.reference(robot), q), dtype=float)

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """The diagonal pull ``weight · ‖v + gain · (q ⊖ q_ref) / dt‖²``; its error the largest gap it pulls."""
        e, weight = self.error_at(robot, q), self.weights(robot)
        level = rows.levels[self.priority - 1]
        level.diag += weight
        level.target += weight * (-self.gain * e / dt)
        return TaskError(self.label, float(np.abs(e[weight > 0]).max(initial=0.0)), 0.0)

    def pack(self, packer: Packing, robot: Robot) -> None:
        """The compiled problem's one posture (its reference and weights written per call)."""
        packer.posture(self, self.weights(robot))

    def refresh(self, packed: TargetSlots, robot: Robot, slot: int) -> None:
        """The reference (and per-velocity weights), per call."""
        packed.set_posture(self.reference(robot), self.weights(robot) if isinstance(self.weight, np.ndarray)
                           else None)

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """The largest gap it pulls (never a verdict: a posture is a preference)."""
        return float(np.abs(self.error_at(robot, q)[self.mask(robot)]).max(initial=0.0)), 0.0

    def second(self, pull: bool = True) -> PostureTask:
        """Asked for second, in what the other tasks leave free (gain 0 without ``pull``: held where it is)."""
        return replace(self, priority=2) if pull else replace(self, priority=2, gain=0.0)


def _per_velocity(robot: Robot, weight: float | np.ndarray) -> np.ndarray:
    """A weight as nv numbers.

    Raises:
        OptionError: per-velocity weights of another length than nv.
    """
    if isinstance(weight, np.ndarray):
        if weight.shape != (robot.nv,):
            raise OptionError("weight", weight, f"a number, or nv = {robot.nv} numbers for {robot.name}")
        return weight.copy()
    return np.full(robot.nv, float(weight))


@dataclass(frozen=True)
class DampingTask(Task):
    """Small velocities: ``weight · ‖v‖²`` in the step's objective (pink's and mink's damping task): the motion
    the other tasks leave free is kept slow. Every velocity, a free-flyer's too (per-velocity weights choose).

    Attributes:
        weight: [1/(rad/s)² or 1/(m/s)²] one number, or one per velocity (nv numbers ≥ 0).
        priority: the level whose objective it joins (1, or 2).
    """

    weight: Any = 1e-3
    priority: int = 1
    preference: ClassVar[bool] = True

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        object.__setattr__(self, "weight", tg.weights(self.weight))
        object.__setattr__(self, "priority", tg.priority(self.priority))

    label = "damping"

    def shape(self) -> tuple[Any, ...]:
        """Its weights and level: all of it (nothing is set per call)."""
        weight = tuple(self.weight.tolist()) if isinstance(self.weight, np.ndarray) else self.weight
        return ("d", weight, self.priority)

    def check(self, robot: Robot) -> None:
        """Name weights of another length than nv.

        Raises:
            OptionError: named.
        """
        _per_velocity(robot, self.weight)

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """The diagonal ``weight · ‖v‖²`` at its level; no error to speak of."""
        rows.levels[self.priority - 1].diag += _per_velocity(robot, self.weight)
        return TaskError(self.label, 0.0, 0.0)

    def pack(self, packer: Packing, robot: Robot) -> None:
        """Its diagonal, at its level."""
        packer.damping(self, _per_velocity(robot, self.weight))

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """Nothing to judge: a damping asks for no place."""
        return 0.0, 0.0


def as_tasks(tasks: object) -> tuple[Task, ...]:
    """The tasks of a call: one task or a sequence of them.

    Raises:
        OptionError: anything else (named), or no task at all.
    """
    items: Any = (tasks,) if isinstance(tasks, Task) else tasks
    try:
        found = tuple(items)
    except TypeError:
        raise OptionError("tasks", tasks, f"a task ({', '.join(NAMES)}) or a list of them") from None
    bad = [t for t in found if not isinstance(t, Task)]
    if bad or not found:
        raise OptionError("tasks", bad[0] if bad else tasks, f"{', '.join(NAMES)} values (at least one)")
    return found


NAMES = ("FrameTask", "RelativeFrameTask", "ComTask", "PostureTask", "DampingTask", "CouplingTask")
