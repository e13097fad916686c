"""Constraints of whole-body kinematics: what the step holds exactly rather than weighs.

Equalities are tasks of the same protocol (:class:`kinelab.wholebody.tasks.Task`) at priority 0: each adds rows
``a · v = c`` that the QP holds, its error driven to zero (drift corrected every step). Inequalities are the
step's bounds (:class:`kinelab.wholebody.limits.Limits`).

- :class:`CouplingTask`: one joint a linear function of another (mimic joints, gears), held exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab.errors import JointNotFoundError, OptionError
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

    def project(self, robot: Robot, q: np.ndarray) -> None:
        """The joint set from its leader."""
        (qj, _), (ql, _) = self.indices(robot)
        q[qj] = self.ratio * q[ql] + self.offset
