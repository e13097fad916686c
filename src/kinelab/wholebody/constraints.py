"""Constraints of whole-body kinematics: what the step holds exactly rather than weighs.

Equalities are tasks of the same protocol (:class:`kinelab.wholebody.tasks.Task`) at priority 0: each adds rows
``a · v = c`` that the QP holds, its error driven to zero (drift corrected every step). Inequalities are
:class:`Inequality` objects: each gives rows ``A v ≥ b`` at the step's start, may add rows for what its first order
missed once the QP has answered, says whether a step's end breaks it (the step is shortened until none does) and
how far a configuration is inside it (the converged solve's verdict); one whose rows are single velocities
(``bounded``) gives them as bounds on v instead, which the QP holds as its bounds. The joints' position, velocity
and acceleration limits are one (:class:`kinelab.wholebody.limits.JointLimits`, the only one the compiled step
packs), collisions another (:class:`kinelab.wholebody.clearance.Clearance`); :class:`kinelab.wholebody.Limits`
gathers what a step holds, a user's own through ``Limits(inequalities=...)``.

- :class:`CouplingTask`: one joint a linear function of another (mimic joints, gears), held exactly.
- :class:`ClosureTask`: a robot's loop held closed (:mod:`kinelab.robot.closures`), one per declared closure.
- :class:`Inequality`, :class:`Held`: the inequality protocol and its rows.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import pinocchio as pin

from kinelab.errors import JointNotFoundError, OptionError
from kinelab.ik.result import Status
from kinelab.robot.assembly import closure_error, closure_jacobian, newton, passive_indices
from kinelab.robot.closures import ASSEMBLY_TOL, Closure, check_closures
from kinelab.values import is_real
from kinelab.wholebody.evaluate import Packing, StepRows
from kinelab.wholebody.tasks import Task, TaskError

if TYPE_CHECKING:
    from kinelab.collision.model import Contact
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


@dataclass(frozen=True)
class Held:
    """One inequality's rows at a step's start: ``A v ≥ b`` (A: (m, nv), b: (m,), in the inequality's unit per
    second), its slack there (:meth:`Inequality.slack`; a start that broke it may end no deeper than it started),
    the nearest pair when it has one (collisions), and what the inequality keeps for its later calls."""

    A: np.ndarray
    b: np.ndarray
    slack: float = 0.0
    closest: Contact | None = None
    memo: Any = None


class Inequality(ABC):
    """What every inequality of the step answers for (see the module's docstring). A subclass is a frozen dataclass
    (a value: equal ones are the same problem) with a :attr:`label`."""

    broken: ClassVar[Status] = Status.OUTSIDE_LIMITS  # a converged solve's status where its answer breaks it
    bounded: ClassVar[bool] = False  # its rows are bounds on single velocities, given by bounds(): the QP's bounds
    compiled: ClassVar[bool] = False  # the compiled step holds it (the joints' limits only)

    @property
    @abstractmethod
    def label(self) -> str:
        """The inequality in words (results and messages)."""

    def check(self, robot: Robot) -> None:
        """Name what the robot lacks (before any work).

        Raises:
            KinelabError: a subclass naming it.
        """
        return None  # an inequality that names nothing has nothing to check

    @abstractmethod
    def rows(self, robot: Robot, q: np.ndarray, dt: float) -> Held:
        """Its rows at q (``robot.data``: Pinocchio's placements and joint Jacobians there) for a step of dt [s]:
        rows that let it close at most a share of its slack in one step, and ask a start that breaks it back."""

    def bounds(self, robot: Robot, q: np.ndarray, dt: float, v_prev: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A ``bounded`` inequality's (lower, upper) on v [nv] (±inf where it bounds nothing) and which velocities
        it is bringing back (bool [nv]); ``v_prev``: the velocity before the step, or None.

        Raises:
            OptionError: an inequality that is not ``bounded`` (its rows say all).
        """
        raise OptionError("bounds", self.label, "an inequality whose rows are single velocities (bounded = True)")

    def overshoot(self, robot: Robot, held: Held, v: np.ndarray, q_next: np.ndarray, dt: float
                  ) -> tuple[np.ndarray, np.ndarray] | None:
        """More rows (A, b) where the step's answer v (to ``q_next``) breaks it though its rows held (their first
        order missed); None: none."""
        return None  # linear in v: its rows say all

    def breaks(self, robot: Robot, held: Held, q_next: np.ndarray) -> bool:
        """Whether a step's end breaks it (then the step is made shorter): inside it less than it allows, or, from
        a start that broke it (``held.slack`` < 0), deeper than it started."""
        return self.slack(robot, q_next) < min(0.0, held.slack) - 1e-12

    @abstractmethod
    def slack(self, robot: Robot, q: np.ndarray) -> float:
        """How far q is inside it (≥ 0: it holds; < 0: broken by that much), in its own unit."""

    def nearest(self, robot: Robot, q: np.ndarray) -> Contact | None:
        """Its nearest pair at q, for a result to name (None: it has no pairs)."""
        return None


def feasible(A: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The right-hand sides b of rows A v ≥ b, each at most half of the largest rate its row can reach within the
    bounds on v: a start that breaks an inequality is brought back as fast as the bounds allow, never made
    infeasible by one row."""
    with np.errstate(invalid="ignore"):  # 0 · inf where a row does not move an unbounded velocity
        reach = np.where(A > 0, A * upper, A * lower)
    reach = np.where(A == 0, 0.0, reach).sum(axis=1)
    return np.where(b > 0, np.minimum(b, 0.5 * np.maximum(reach, 0.0)), b)
