"""A whole-body problem prepared once: ``kinelab.WholeBody(robot, tasks, limits=..., options=...)``.

It checks its tasks against the robot, reads the limits and packs the compiled problem once (its caches are its
own attributes); then each :meth:`WholeBody.step` is one compiled call (the readable step where the compiled one
does not serve: another QP solver, a tree or a task it has no code for — the same answers), and
:meth:`WholeBody.set_target` moves one task's target without packing again. :func:`kinelab.step` and
:func:`kinelab.solve` work through a kept ``WholeBody`` per robot and task structure, as :func:`kinelab.solve`
works through a kept ``IK`` for a chain.
"""

from __future__ import annotations

import operator
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from kinelab.errors import OptionError
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot
from kinelab.wholebody import compiled as cp
from kinelab.wholebody.constraints import loops
from kinelab.wholebody.limits import Limits, acceleration_bounds, checked_v_prev, is_positive_time, velocity_bounds
from kinelab.wholebody.step import DEFAULT_LIMITS, DEFAULT_OPTIONS, StepOptions, StepResult, _step
from kinelab.wholebody.subject import as_robot
from kinelab.wholebody.tasks import Task, as_tasks
from kinelab.wholebody.worlds import BatchStep, Worlds

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from numpy.typing import ArrayLike

    from kinelab.typing import Configuration
    from kinelab.wholebody.solve import WholeBodyResult

NO_LIMIT = cp.NO_LIMIT


class WholeBody:
    """A robot's tasks, limits and step options, checked and packed once (see the module's docstring).

    Args:
        robot: the whole robot (:func:`kinelab.load`), or a chain (its own joints; :mod:`~kinelab.wholebody.subject`).
        tasks: a task or a list of them (:mod:`kinelab.wholebody.tasks`, and any :class:`~kinelab.wholebody.Task`).
        limits: what every step holds (:class:`~kinelab.wholebody.Limits`).
        options: the QP's damping and solver (:class:`~kinelab.wholebody.StepOptions`).

    Raises:
        ChainError: not a whole robot. OptionError, TargetError: a bad task, limit or option, named.
        FrameNotFoundError, JointNotFoundError, ConfigurationError: a task naming what the robot lacks.
    """

    def __init__(self, robot: Robot | Chain, tasks: Task | Sequence[Task], *, limits: Limits = DEFAULT_LIMITS,
                 options: StepOptions = DEFAULT_OPTIONS):
        robot = as_robot(robot)
        if not isinstance(limits, Limits):
            raise OptionError("limits", limits, "a kinelab.Limits(...)")
        if not isinstance(options, StepOptions):
            raise OptionError("options", options, "a kinelab.StepOptions(...)")
        self.robot, self.limits, self.options = robot, limits, options
        self._tasks = list(as_tasks(tasks))
        self.loops = loops(robot)  # the robot's closures, held as equalities of every step
        for task in self._tasks:
            task.check(robot)
        for inequality in limits.inequalities:
            inequality.check(robot)
        self._vmax = np.ascontiguousarray(velocity_bounds(limits, robot.space), dtype=float)
        amax = acceleration_bounds(limits, robot.space)
        self._amax = NO_LIMIT if amax is None else np.ascontiguousarray(amax, dtype=float)
        self._packed = _packed(robot, tuple(self._tasks) + self.loops, options)
        self._worlds: Worlds | None = None  # step_batch's threads, made at its first call
        self._refresh_all()

    def use(self, limits: Limits) -> None:
        """Hold ``limits`` from the next step on (the velocity and acceleration bounds read again)."""
        if limits is self.limits:
            return
        self.limits = limits
        self._vmax = np.ascontiguousarray(velocity_bounds(limits, self.robot.space), dtype=float)
        amax = acceleration_bounds(limits, self.robot.space)
        self._amax = NO_LIMIT if amax is None else np.ascontiguousarray(amax, dtype=float)

    def takes(self, limits: Limits, options: StepOptions) -> bool:
        """Whether these limits and options are this problem's (the same objects, or equal ones)."""
        if options is not self.options and options != self.options:
            return False
        if limits is not self.limits:
            if not _equal_limits(limits, self.limits):
                return False
            self.limits = limits
        return True

    @property
    def tasks(self) -> tuple[Task, ...]:
        """The tasks as they are now (a moved target is a new task value in its place)."""
        return tuple(self._tasks)

    @property
    def compiled(self) -> bool:
        """Whether each step is one compiled call (else the readable step answers, alike: :attr:`route` says
        why)."""
        return self._packed is not None and self.limits.compiled

    @property
    def route(self) -> str:
        """Which step answers, and why, in words."""
        if self.limits.collisions is not None:
            return "readable: collisions are held (the compiled step has no block for the collision rows yet)"
        if not self.limits.compiled:
            return "readable: inequalities beyond the joints' limits are held (the compiled step has no block for them)"
        if self._packed is not None:
            return "compiled: the tree certified against Pinocchio, DAQP's C interface linked, every task packed"
        if self.options.solver != "daqp":
            return f"readable: the QP solver is {self.options.solver!r} (the compiled step runs DAQP)"
        if not cp.daqp_linked():
            return "readable: DAQP's C interface is not linked (an installed daqp other than 0.11.x, or none)"
        if self.robot.derived("compiled tree", cp.pack_tree) is None:
            return "readable: the robot's tree has a joint the compiled step has no code for, or failed its certificate"
        if self.loops:
            return "readable: the robot closes loops (the compiled step has no block for a closure yet)"
        return "readable: a task the compiled step has no block for (or two postures, or a posture on the base)"

    def step(self, q: Configuration, dt: float, v_prev: ArrayLike | None = None) -> StepResult:
        """One differential step from q (:func:`kinelab.step`'s answer for these tasks, limits and options).

        Args:
            q: the configuration (Pinocchio's q, nq numbers); it may lie outside the limits (brought back), and
                off the robot's own loops and folded mimic joints (brought onto them first: the step starts there).
            dt: the step [s], at least 1e-9.
            v_prev: the velocity before the step (nv), for acceleration limits.

        Returns:
            The :class:`~kinelab.wholebody.StepResult`.

        Raises:
            ConfigurationError: a bad q. OptionError: a bad dt or v_prev (named).
        """
        dt = is_positive_time(dt)
        prev = None if v_prev is None else checked_v_prev(v_prev, self.robot.nv)
        if self.loops:
            q = self._onto_loops(q)
        fast = self._compiled_step(q, dt, prev)
        if fast is not None:
            return fast
        return _step(self.robot, self.robot.check_q(q), tuple(self._tasks) + self.loops, dt, self.limits,
                     self.options, prev)

    def step_batch(self, Q: ArrayLike, dt: float,
                   targets: Mapping[Any, ArrayLike] | Sequence[tuple[Any, ArrayLike]] | None = None,
                   v_prev: ArrayLike | None = None) -> BatchStep:
        """N worlds one step each, in one call (:mod:`kinelab.wholebody.worlds`): the compiled step on every core,
        the GIL released.

        Args:
            Q: (N, nq) the worlds' configurations (Pinocchio's q, one row per world).
            dt: the step [s], at least 1e-9.
            targets: per task (the task or its index in :attr:`tasks`) its target in each world: an (N, 4, 4)
                array of poses (oM*, world frame; a relative task's in its root frame) or an (N, 3) array of points
                [m], as a mapping or as (task, array) pairs (a task holding an array, a ComTask, is no dict key);
                the tasks not named keep their own target in every world.
            v_prev: (N, nv) each world's velocity before the step, for acceleration limits.

        Returns:
            A :class:`~kinelab.wholebody.worlds.BatchStep` (q, v, solved, flags, iterations per world).

        Raises:
            OptionError, TargetError: a bad array, dt or task (named).
        """
        dt = is_positive_time(dt)
        if self._worlds is None:
            self._worlds = Worlds(self)
        return self._worlds.step(Q, dt, targets, v_prev)

    def _onto_loops(self, q: Any) -> np.ndarray:
        """A copy of q brought onto what the robot itself holds (its loops closed, its folded mimic joints set from
        their leaders), as the mechanism is: a start off them is a model's, not a motion the step must make."""
        arr = np.array(self.robot.check_q(q), dtype=float)
        for task in self.loops:
            task.project(self.robot, arr)
        return arr

    def _compiled_step(self, q: Any, dt: float, prev: np.ndarray | None) -> StepResult | None:
        """The step in one compiled call, or None where it does not serve (a q to check and name first, an
        acceleration limit without the velocity before)."""
        packed, arr, limits = self._packed, _plain(q, self.robot.nq), self.limits
        if packed is None or arr is None or (self._amax.size and prev is None) or not limits.compiled:
            return None
        return cp.run(packed, self.robot, arr, dt, (self._vmax, limits.position, self._amax), prev,
                      self.options.damping)

    def set_target(self, task: Task | int, target: Any) -> Task:
        """Move one task's target (the task given, or its index in :attr:`tasks`): the task is replaced by
        ``task.moved(target)`` and only its target is written into the compiled problem.

        Returns:
            The new task value (now in :attr:`tasks`).

        Raises:
            OptionError: a task not in this problem, or one with no target. TargetError: a bad target (named).
        """
        i = self._index(task)
        moved = self._tasks[i].moved(target)
        self._tasks[i] = moved
        if self._packed is not None:
            moved.refresh(self._packed, self.robot, self._packed.slots[i])
        return moved

    def _index(self, task: Task | int) -> int:
        if isinstance(task, int) and not isinstance(task, bool) and 0 <= task < len(self._tasks):
            return task
        for i, held in enumerate(self._tasks):
            if held is task:
                return i
        raise OptionError("task", task, f"one of this problem's tasks, or its index (0 to {len(self._tasks) - 1})")

    def retarget(self, tasks: Sequence[Task]) -> None:
        """Take ``tasks`` in place of the problem's, task for task of the same structure (what
        :func:`kinelab.step` does with a kept problem): their targets written into the compiled problem.

        Raises:
            OptionError: a list of another structure.
        """
        found = as_tasks(tasks)
        if cp.structure(found) != cp.structure(tuple(self._tasks)):
            raise OptionError("tasks", tasks, "tasks of the same kinds, frames and settings as the problem's (a new "
                              "kinelab.WholeBody for others)")
        self._take(found)

    def _take(self, found: tuple[Task, ...]) -> None:
        """Tasks of this structure in place of the problem's: only those that are other objects write their
        targets (a task is a value: the same object holds the same target)."""
        packed = self._packed
        for i, (held, task) in enumerate(zip(self._tasks, found, strict=True)):
            if task is not held:
                self._tasks[i] = task
                if packed is not None:
                    task.refresh(packed, self.robot, packed.slots[i])

    def _refresh_all(self) -> None:
        if self._packed is not None:
            cp.set_targets(self.robot, self._packed, tuple(self._tasks) + self.loops)

    def solve(self, q0: Configuration | None = None, **settings: Any) -> WholeBodyResult:
        """The converged solve of these tasks (:func:`kinelab.wholebody.solve.solve`; the limits' positions held,
        its velocities and accelerations meaning nothing at its dt of 1 s).

        Args:
            q0: the start (Pinocchio's q; None: the robot's neutral configuration).
            settings: the solve's keywords (solver, seed, tol_pos, tol_rot, max_iterations, max_restarts,
                time_budget).

        Returns:
            The :class:`~kinelab.wholebody.solve.WholeBodyResult`, every task judged by Pinocchio.
        """
        from kinelab.wholebody.solve import solve

        limits = replace(self.limits, velocity=None, acceleration=None)
        return solve(self.robot, tuple(self._tasks), q0=q0, limits=limits, **settings)

    def __repr__(self) -> str:
        return (f"WholeBody({self.robot.name}, {len(self._tasks)} tasks, "
                f"{'compiled' if self.compiled else 'readable'} step)")


def _plain(q: Any, nq: int) -> np.ndarray | None:
    """q when it is nq contiguous float64 numbers, as the compiled step takes it (else None: the readable step
    checks and names it)."""
    if type(q) is np.ndarray and q.dtype == np.float64 and q.flags.c_contiguous and q.shape == (nq,):
        return q
    return None


def _packed(robot: Robot, tasks: tuple[Task, ...], options: StepOptions) -> cp.Packed | None:
    """The compiled problem of the tasks (:func:`~kinelab.wholebody.compiled.packed_for`)."""
    return cp.packed_for(robot, tasks, options.solver)


def step(robot: Robot | Chain, q: Configuration, tasks: Task | Sequence[Task], dt: float, *,
         limits: Limits = DEFAULT_LIMITS, options: StepOptions = DEFAULT_OPTIONS,
         v_prev: ArrayLike | None = None) -> StepResult:
    """One differential step of whole-body kinematics (:mod:`kinelab.wholebody.step`), through a kept
    :class:`WholeBody` for this robot and task structure (:func:`kept`).

    Args:
        robot: the whole robot (:func:`kinelab.load`), or a chain (its own joints; :mod:`~kinelab.wholebody.subject`).
        q: the configuration (Pinocchio's q, nq numbers); it may lie outside the limits (brought back).
        tasks: a task or a list of them (:mod:`kinelab.wholebody.tasks`).
        dt: the step [s], at least 1e-9.
        limits: what the step holds (:class:`~kinelab.wholebody.Limits`).
        options: the QP's damping and solver (:class:`~kinelab.wholebody.StepOptions`).
        v_prev: the velocity before the step (nv), for acceleration limits.

    Returns:
        The :class:`~kinelab.wholebody.StepResult`.

    Raises:
        ChainError: not a whole robot. ConfigurationError: a bad q. OptionError, TargetError: a bad task, limit or
            option, named. FrameNotFoundError, JointNotFoundError: an unknown frame or joint.
    """
    return kept(as_robot(robot, "step"), tasks, limits, options).step(q, dt, v_prev)


KEPT = 32  # problems kept per robot for kinelab.step (a caller sweeping weights: the memory stays bounded)


def kept(robot: Robot, tasks: Any, limits: Limits, options: StepOptions) -> WholeBody:
    """The problem :func:`kinelab.step` answers through: the one whose very task objects, limits and options
    these are (tasks are values: the same objects hold the same targets); else one of the same structure, given
    these tasks; else a new one."""
    if isinstance(tasks, Task):
        tasks = (tasks,)
    table: dict[Any, WholeBody] = robot.derived("whole-body problems", _new_table)
    last = table.get(LAST)
    if last is not None and _same_objects(last._tasks, tasks) and last.takes(limits, options):
        return last
    if last is not None and _alike(last._tasks, tasks) and last.takes(limits, options):
        last._take(tuple(tasks))  # a new target each step, the way a loop runs: only the targets are written
        return last
    if not isinstance(limits, Limits):
        raise OptionError("limits", limits, "a kinelab.Limits(...)")
    if not isinstance(options, StepOptions):
        raise OptionError("options", options, "a kinelab.StepOptions(...)")
    found = as_tasks(tasks)
    key = cp.structure(found)
    problem = table.get(key)
    if problem is not None and problem.options == options:
        problem._take(found)  # the same structure: the key says so
        problem.use(limits)
    else:
        if len(table) >= KEPT:
            table.clear()
        problem = table[key] = WholeBody(robot, found, limits=limits, options=options)
    table[LAST] = problem
    return problem


LAST = ("the last problem stepped",)


def _equal_limits(a: object, b: Limits) -> bool:
    """Whether ``a`` is a Limits equal to ``b`` field by field (arrays by their values)."""
    if not isinstance(a, Limits):
        return False
    return all(np.array_equal(np.asarray(x, dtype=object), np.asarray(y, dtype=object))
               if isinstance(x, np.ndarray | list | tuple) or isinstance(y, np.ndarray | list | tuple) else x == y
               for x, y in ((a.position, b.position), (a.velocity, b.velocity), (a.acceleration, b.acceleration),
                            (a.collisions, b.collisions))) and _same_objects(list(a.inequalities), b.inequalities)


def _alike(held: list[Task], tasks: Any) -> bool:
    """Whether ``tasks`` is a list or tuple of tasks of the same kinds and shapes as ``held``, one for one (the
    same objects, or values that differ in their targets only)."""
    if not isinstance(tasks, list | tuple) or len(tasks) != len(held):
        return False
    return all(t is h or (type(t) is type(h) and t.shape() == h.shape()) for h, t in zip(held, tasks, strict=True))


def _same_objects(held: list[Task], tasks: Any) -> bool:
    """Whether ``tasks`` is a sequence of exactly the objects ``held`` (not equal ones: the same)."""
    try:
        return len(held) == len(tasks) and all(map(operator.is_, held, tasks))
    except TypeError:
        return False


def _new_table(_: Robot) -> dict[Any, Any]:
    return {}
