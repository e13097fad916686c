"""Constraints of whole-body kinematics: what the step holds exactly rather than weighs.

Equalities are tasks of the same protocol (:class:`kinelab.wholebody.tasks.Task`) at priority 0: each adds rows
``a · v = c`` that the QP holds, its error driven to zero (drift corrected every step). Inequalities are the
step's bounds (:class:`kinelab.wholebody.limits.Limits`).

- :class:`CouplingTask`: one joint a linear function of another (mimic joints, gears), held exactly.
- :class:`ClosureTask`: a robot's loop held closed (:mod:`kinelab.robot.closures`), one per declared closure.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import pinocchio as pin

from kinelab.errors import JointNotFoundError, OptionError
from kinelab.robot.assembly import closure_error, closure_jacobian, newton, passive_indices
from kinelab.robot.closures import ASSEMBLY_TOL, Closure, check_closures
from kinelab.values import is_real
from kinelab.wholebody.evaluate import Packing, StepRows
from kinelab.wholebody.tasks import Task, TaskError

if TYPE_CHECKING:
    from kinelab.robot.tree import Robot


@dataclass(frozen=True)
class CouplingTask(Task):
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
    rows_count = 1

    @property
    def label(self) -> str:
        """The task in words."""
        return f"{self.joint} = {self.ratio:g} × {self.leader} + {self.offset:g}"

    def shape(self) -> tuple[Any, ...]:
        """What a compiled step is packed for (the whole coupling)."""
        return ("k", self.joint, self.leader, self.ratio, self.offset, False)

    def indices(self, robot: Robot) -> tuple[tuple[int, int], tuple[int, int]]:
        """((q, v) index of the joint, (q, v) index of the leader).

        Raises:
            JointNotFoundError: an unknown joint. OptionError: a joint with more than one coordinate.
        """
        idx = []
        for name in (self.joint, self.leader):
            if not robot.model.existJointName(name):
                raise JointNotFoundError(name, robot.joint_names)
            joint = robot.model.joints[robot.model.getJointId(name)]
            if joint.nq != 1 or joint.nv != 1:
                raise OptionError("CouplingTask", name, "a joint with one coordinate (revolute or prismatic)")
            idx.append((joint.idx_q, joint.idx_v))
        return idx[0], idx[1]

    def check(self, robot: Robot) -> None:
        """Name an unknown joint, or one with more than one coordinate.

        Raises:
            JointNotFoundError, OptionError: named.
        """
        self.indices(robot)

    def row(self, robot: Robot, q: np.ndarray, dt: float) -> tuple[np.ndarray, float]:
        """(a, c): the equality a·v = c that keeps ``joint = ratio · leader + offset`` after the step (and brings it
        back when it is off)."""
        (qj, vj), (ql, vl) = self.indices(robot)
        a = np.zeros(robot.nv)
        a[vj], a[vl] = 1.0, -self.ratio
        return a, -(q[qj] - self.ratio * q[ql] - self.offset) / dt

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """Its equality; its error |joint − ratio · leader − offset|."""
        a, c = self.row(robot, q, dt)
        rows.equalities.append((a, c))
        return TaskError(self.label, abs(c * dt), 0.0)

    def pack(self, packer: Packing, robot: Robot) -> None:
        """Its indices, ratio and offset."""
        (qj, vj), (ql, vl) = self.indices(robot)
        packer.coupling(self, qj, vj, ql, vl)

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """|joint − ratio · leader − offset|."""
        return abs(self.row(robot, q, 1.0)[1]), 0.0

    def project(self, robot: Robot, q: np.ndarray) -> bool:
        """The joint set from its leader."""
        (qj, _), (ql, _) = self.indices(robot)
        q[qj] = self.ratio * q[ql] + self.offset
        return True


@dataclass(frozen=True)
class ClosureTask(Task):
    """A robot's loop held closed (an equality of the step: its error driven to zero each step, drift corrected);
    added by the step and the solve for every closure the robot declares (:mod:`kinelab.robot.closures`).

    Attributes:
        closure: the loop.
    """

    closure: Closure

    def __post_init__(self) -> None:
        """Check the closure.

        Raises:
            OptionError: not a kinelab.Closure.
        """
        if not isinstance(self.closure, Closure):
            raise OptionError("closure", self.closure, "a kinelab.Closure")

    priority = 0  # held exactly, above every weighted task
    settled: ClassVar[bool] = True  # the rows hold the loop to first order; the rest is projected out each step
    tolerance: ClassVar[float] = ASSEMBLY_TOL  # a solve meets its tasks with every loop closed to this

    @property
    def rows_count(self) -> int:
        """One row per held component."""
        return len(self.closure.rows)

    @property
    def label(self) -> str:
        """The loop in words."""
        return self.closure.label

    def shape(self) -> tuple[Any, ...]:
        """What a compiled step is packed for (the whole closure)."""
        return ("c", self.closure)

    def check(self, robot: Robot) -> None:
        """Name a frame the robot does not have.

        Raises:
            FrameNotFoundError: named.
        """
        check_closures(robot.model, [self.closure], ())

    def _frames(self, robot: Robot) -> tuple[int, int]:
        return robot.frame_id(self.closure.frame_a), robot.frame_id(self.closure.frame_b)

    def add_to(self, rows: StepRows, robot: Robot, q: np.ndarray, dt: float) -> TaskError:
        """Its equalities ``J v = −e / dt``; its error (position [m], rotation [rad]) at q."""
        frames = self._frames(robot)
        e = closure_error(robot.model, robot.data, self.closure, frames)
        J = closure_jacobian(robot.model, robot.data, self.closure, frames)
        for a, c in zip(J, -e / dt, strict=True):
            rows.equalities.append((a, float(c)))
        return TaskError(self.label, *self._split(e))

    def _split(self, e: np.ndarray) -> tuple[float, float]:
        """(largest position component [m], largest rotation component [rad]) of an error."""
        linear = self.closure.rows < 3
        return (float(np.max(np.abs(e[linear]), initial=0.0)), float(np.max(np.abs(e[~linear]), initial=0.0)))

    def pack(self, packer: Packing, robot: Robot) -> None:
        """No compiled block yet: the readable step answers a robot with loops."""
        packer.decline("a loop closure (the compiled step has no block for one yet)")

    def judged(self, robot: Robot, data: pin.Data, q: np.ndarray, com: np.ndarray | None) -> tuple[float, float]:
        """The loop's error at q from Pinocchio's placements in ``data``."""
        return self._split(closure_error(robot.model, data, self.closure, self._frames(robot)))

    def project(self, robot: Robot, q: np.ndarray) -> bool:
        """The passive joints moved to close the loops (Gauss–Newton, the actuated joints held; q changed in place
        where it closes them, to ASSEMBLY_TOL); whether they are closed. Every loop of the robot at once: the task
        of its first loop does it and answers for all, the others' leave it to that one."""
        if robot.closures and self.closure in robot.closures[1:]:
            return True
        passive = robot.derived("loops' passive joints", lambda r: passive_indices(r, r.actuated))
        closed, residual = newton(robot, q, passive, ASSEMBLY_TOL)
        if residual <= ASSEMBLY_TOL:
            q[:] = closed
        return residual <= ASSEMBLY_TOL


def loops(robot: Robot) -> tuple[Task, ...]:
    """What the robot itself holds, as the equalities every step and solve adds to its tasks: its folded mimic
    joints (couplings) and its loops (none: ``()``)."""
    couplings = tuple(CouplingTask(m.name, m.leader, m.multiplier, m.offset) for m in robot.mimics)
    return couplings + tuple(ClosureTask(c) for c in robot.closures)
