"""What the readable step's tasks share: Pinocchio's pass at a configuration (``computeJointJacobians``), the rows
of each priority level the tasks add themselves to (:meth:`kinelab.wholebody.tasks.Task.add_to`), and the shapes
of their answers.

A task gives ``(A, e)``: its error e (m, rad) and A with ``de/dt = A v`` to first order (v: nv velocities). A frame's
pose error is its position's and its rotation's, apart: the frame origin's offset from the target's in world axes
[m], and Pinocchio's logarithm of the rotation between them, in the frame's axes (``log3``), with the Jacobian of the
logarithm (``Jlog3``) in A; an axis error is the difference of the two unit axes. A relative pose's error is the same
in the root frame's axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from kinelab.robot.tree import Robot

LOCAL = pin.ReferenceFrame.LOCAL
Rowset = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]  # A, e, the rows' weights, a pose's gap
# one FRDM point of a task: (frame, point, target, weight, is a direction, carrier frame, follows)
PointRow = tuple[int, np.ndarray, np.ndarray, float, bool, int, np.ndarray]


class Packing(Protocol):
    """What a task hands its block of the compiled problem to (:class:`kinelab.wholebody.compiled.Packer`)."""

    def weighted(self, task: Any, kind: int, joint: int, placement: pin.SE3 | None, axis: int, root: int = 0,
                 root_placement: pin.SE3 | None = None) -> None:
        """A weighted task's block."""

    def posture(self, task: Any, weights: np.ndarray) -> None:
        """The posture."""

    def damping(self, task: Any, weights: np.ndarray) -> None:
        """A damping's diagonal."""

    def coupling(self, task: Any, qj: int, vj: int, ql: int, vl: int) -> None:
        """A coupling's indices."""

    def decline(self, reason: str) -> None:
        """A block the compiled step has no code for: the readable step answers the list (``reason`` says why)."""


class TargetSlots(Protocol):
    """Where a task writes its target per call (:class:`kinelab.wholebody.compiled.Packed`)."""

    def set_pose(self, slot: int, H: np.ndarray) -> None:
        """A target pose."""

    def set_point(self, slot: int, p: np.ndarray) -> None:
        """A target point."""

    def set_posture(self, q_ref: np.ndarray, weights: np.ndarray | None) -> None:
        """The posture's reference."""


@dataclass
class Rows:
    """The weighted rows of one priority level: ``A v ≈ b`` with b = −gain·e/dt, each row's weight ``w``, and the
    diagonal part (``diag``: a weight per velocity — a posture's, a damping's — and ``target``: its pull)."""

    A: list[np.ndarray]
    b: list[np.ndarray]
    w: list[np.ndarray]
    diag: np.ndarray
    target: np.ndarray

    def add(self, A: np.ndarray, b: np.ndarray, w: np.ndarray) -> None:
        """Rows ``A v ≈ b``, weighted row by row by ``w``."""
        self.A.append(A)
        self.b.append(b)
        self.w.append(w)


@dataclass
class StepRows:
    """What the tasks of one readable step put in: two priority levels and the equalities ``a · v = c``."""

    nv: int
    levels: list[Rows] = field(init=False)
    equalities: list[tuple[np.ndarray, float]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.levels = [Rows([], [], [], np.zeros(self.nv), np.zeros(self.nv)) for _ in range(2)]

    def used(self) -> list[Rows]:
        """The levels a task asked something of (the first alone when none did)."""
        used = [lv for lv in self.levels if lv.A or lv.diag.any()]
        return used or self.levels[:1]


def skew(a: np.ndarray) -> np.ndarray:
    """The 3 × 3 matrix of a × (·)."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def kept_data(robot: Robot, purpose: str) -> pin.Data:
    """A Pinocchio Data of the robot's model kept on the robot for one ``purpose`` (its user computes what it reads
    first): making one costs milliseconds on a humanoid, too much to pay on every solve."""
    found: pin.Data = robot.derived(f"data for {purpose}", lambda r: r.model.createData())
    return found


def forward(robot: Robot, q: np.ndarray, com: bool) -> None:
    """Pinocchio's pass at q: joint placements and Jacobians, frame placements, and with ``com`` the centre of mass
    and its Jacobian (in ``robot.data``)."""
    pin.computeJointJacobians(robot.model, robot.data, q)
    pin.updateFramePlacements(robot.model, robot.data)
    if com:
        pin.jacobianCenterOfMass(robot.model, robot.data, False)


def task_rows(robot: Robot, task: Any) -> Rowset:
    """(A, e, per-row weight, a pose's translation gap) of a frame, relative frame or centre-of-mass task at
    ``robot.data``'s configuration (the task's own :meth:`rows`)."""
    rows: Rowset = task.rows(robot)
    return rows


def posture_error(robot: Robot, task: Any, q: np.ndarray) -> np.ndarray:
    """A posture's q ⊖ q_ref (nv) [rad or m] (its own :meth:`error_at`)."""
    error: np.ndarray = task.error_at(robot, q)
    return error


def posture_mask(robot: Robot, task: Any) -> np.ndarray:
    """(nv,) the velocities a posture pulls (its own :meth:`mask`)."""
    mask: np.ndarray = task.mask(robot)
    return mask
