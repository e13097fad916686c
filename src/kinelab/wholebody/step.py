"""One differential whole-body step: the velocity v [nv] that best does every task in dt, within the limits.

The step solves one QP (two with tasks of priority 2): minimize Σ w‖A v + gain·e/dt‖² over the tasks (each
weighted row by row), plus the posture's pull and a small damping λ‖v‖², subject to the limits as bounds on v
(:mod:`kinelab.wholebody.limits`) and the couplings as equalities. Tasks of priority 2 are solved second, with the
priority-1 tasks' rates A₁v held at the first answer's (they act in its null space). The new configuration is
q ⊕ v·dt through ``pin.integrate``.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
import pinocchio as pin

from kinelab.errors import ChainError, OptionError
from kinelab.robot.tree import Robot
from kinelab.typing import Configuration
from kinelab.values import is_real
from kinelab.wholebody import compiled as cp
from kinelab.wholebody import evaluate as ev
from kinelab.wholebody import qp
from kinelab.wholebody.limits import (
    Limits,
    acceleration_bounds,
    bounds,
    checked_v_prev,
    is_positive_time,
    velocity_bounds,
)
from kinelab.wholebody.tasks import Task, TaskError, as_tasks

if TYPE_CHECKING:
    from collections.abc import Sequence

    from numpy.typing import ArrayLike


T = TypeVar("T")


@dataclass(frozen=True)
class StepOptions:
    """How the step solves.

    Attributes:
        damping: λ, the weight of ‖v‖² (keeps the QP well posed at a singular configuration) [1/(rad/s)²].
        solver: "daqp" (default) or "proxsuite".
    """

    damping: float = 1e-6
    solver: str = "daqp"

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts.
        """
        if not is_real(self.damping, 0):
            raise OptionError("damping", self.damping, "a finite number ≥ 0")
        if self.solver not in qp.SOLVERS:
            raise OptionError("solver", self.solver, " or ".join(qp.SOLVERS))


class StepResult:
    """A step's answer.

    Attributes:
        v: (nv,) the velocities [rad/s or m/s]; q: (nq,) the configuration after dt (Pinocchio's q).
        status: the QP's status ("solved", "infeasible", ...); solved: it is solved (else v is zero and q unmoved).
        errors: each task's error at the start of the step, in the order given (:class:`TaskError`).
        returning: the joints outside their limits at the start, brought back at the velocity limit.
        iterations: the QP's iterations (both levels).
    """

    __slots__ = ("v", "q", "status", "solved", "iterations", "_errors", "_labels", "_returning", "_names")

    def __init__(self, v: np.ndarray, q: np.ndarray, status: str, solved: bool,
                 errors: tuple[TaskError, ...] | np.ndarray, returning: tuple[str, ...] | np.ndarray = (),
                 iterations: int = 0, labels: tuple[str, ...] = (),
                 names: tuple[str, ...] = ()):
        """A step's answer (``errors``: TaskErrors, or an (ntasks, 2) array with ``labels``; ``returning``: joint
        names, or a bool mask over the velocities with ``names``)."""
        self.v, self.q, self.status, self.solved, self.iterations = v, q, status, solved, iterations
        self._errors, self._labels, self._returning, self._names = errors, labels, returning, names

    @property
    def errors(self) -> tuple[TaskError, ...]:
        """Each task's error at the start of the step, in the order given."""
        if isinstance(self._errors, np.ndarray):
            self._errors = tuple(TaskError(label, float(p), float(r))
                                 for label, (p, r) in zip(self._labels, self._errors.tolist(), strict=True))
        return tuple(self._errors)

    @property
    def returning(self) -> tuple[str, ...]:
        """The joints outside their limits at the start, brought back at the velocity limit."""
        if isinstance(self._returning, np.ndarray):
            self._returning = tuple(self._names[i] for i in np.flatnonzero(self._returning))
        return tuple(self._returning)

    def __repr__(self) -> str:
        return f"StepResult(status={self.status!r}, v={self.v!r}, q={self.q!r})"


DEFAULT_LIMITS = Limits()
DEFAULT_OPTIONS = StepOptions()


def step(robot: Robot, q: Configuration, tasks: Task | Sequence[Task], dt: float, *, limits: Limits = DEFAULT_LIMITS,
         options: StepOptions = DEFAULT_OPTIONS, v_prev: ArrayLike | None = None) -> StepResult:
    """One differential step of whole-body kinematics (see the module's docstring).

    Args:
        robot: the whole robot (:func:`kinelab.load`).
        q: the configuration (Pinocchio's q, nq numbers); it may lie outside the limits (brought back).
        tasks: a task or a list of them (:mod:`kinelab.wholebody.tasks`).
        dt: the step [s].
        limits: what the step holds (:class:`Limits`).
        options: the QP's damping and solver (:class:`StepOptions`).
        v_prev: the velocity before the step (nv), for acceleration limits.

    Returns:
        The :class:`StepResult`.

    Raises:
        ChainError: not a whole robot. ConfigurationError: a bad q. OptionError, TargetError: a bad task, limit or
            option, named. FrameNotFoundError, JointNotFoundError: an unknown frame or joint.
    """
    if not isinstance(robot, Robot):
        raise ChainError(f"step takes a whole robot (kinelab.load('talos'), or load(path, whole=True)), got "
                         f"{type(robot).__name__}")
    if not isinstance(limits, Limits):
        raise OptionError("limits", limits, "a kinelab.Limits(...)")
    if not isinstance(options, StepOptions):
        raise OptionError("options", options, "a kinelab.StepOptions(...)")
    dt = is_positive_time(dt)
    prev = None if v_prev is None else checked_v_prev(v_prev, robot.nv)
    fast = _compiled(robot, q, tasks, dt, limits, options, prev)
    if fast is not None:
        return fast
    q, found = robot.check_q(q), as_tasks(tasks)
    return _step(robot, q, found, dt, limits, options, prev)


MAX_PACKED = 32  # task structures kept per robot (a caller sweeping weights: the memory stays bounded)
NO_LIMIT = np.empty(0)


def _compiled(robot: Robot, q: Any, tasks: Any, dt: float, limits: Limits, options: StepOptions,
              v_prev: np.ndarray | None) -> StepResult | None:
    """The step in one compiled call (:mod:`kinelab.wholebody.compiled`), or None where that path does not serve (a
    q or task list to check and name, another QP solver, a tree it does not take): the readable step then answers,
    alike."""
    packed = _packed(robot, tasks, options)
    if packed is None:
        return None
    arr = q if type(q) is np.ndarray and q.dtype == np.float64 and q.flags.c_contiguous else None
    if arr is None or arr.shape != (robot.nq,):
        return None
    vmax, amax = _velocity_limits(robot, limits)
    prev = NO_LIMIT if v_prev is None else v_prev
    if amax.size and v_prev is None:
        return None
    q_out, v_out, errors = np.empty(robot.nq), np.empty(robot.nv), np.zeros((len(packed.labels), 2))
    returning = np.empty(robot.nv, dtype=np.uint8)
    flag, iterations = packed.step.step(arr, dt, vmax, limits.position, amax, prev, options.damping, q_out, v_out,
                                        errors, returning)
    if flag == -100:  # not a configuration: the readable path names what is wrong
        return None
    return StepResult(v_out, q_out, "solved" if flag in (1, 2) else STATUS.get(flag, str(flag)),
                      flag in (1, 2), errors, returning.view(bool), iterations, packed.labels, robot.space.names_v)


STATUS = {**qp.DAQP_STATUS, -101: qp.NOT_FINITE}  # the compiled step's flags in words


def _velocity_limits(robot: Robot, limits: Limits) -> tuple[np.ndarray, np.ndarray]:
    """(vmax, amax) of ``limits`` for the robot (amax empty: none), kept per limits object."""
    table: dict[int, tuple[Limits, np.ndarray, np.ndarray]] = robot.derived("compiled limits", _new_table)
    found = table.get(id(limits))
    if found is None or found[0] is not limits:
        vmax = np.ascontiguousarray(velocity_bounds(limits, robot.space), dtype=float)
        a = acceleration_bounds(limits, robot.space)
        amax = NO_LIMIT if a is None else np.ascontiguousarray(a, dtype=float)
        found = _kept(table, id(limits), (limits, vmax, amax))
    return found[1], found[2]


def _new_table(_: Robot) -> dict[Any, Any]:
    return {}


def _packed(robot: Robot, tasks: Any, options: StepOptions) -> cp.Packed | None:
    """The compiled problem of this task list with its targets set, or None (see :func:`_compiled`). The very task
    objects of a recent call take that call's problem as it is: tasks are values (their targets copied and
    read-only, :mod:`kinelab.wholebody.tasks`), so the same objects hold the same targets."""
    if options.solver != "daqp" or not cp.daqp_linked():
        return None
    if isinstance(tasks, Task):
        tasks = (tasks,)
    recent: list[tuple[tuple[Task, ...], cp.Packed]] = robot.derived("compiled recent", _new_list)
    for held, packed in recent:
        if packed.current is held and _same_objects(held, tasks):
            return packed
    found = as_tasks(tasks)
    made = _of_structure(robot, found)
    if made is None:
        return None
    cp.set_targets(robot, made, found)
    made.current = found
    recent.insert(0, (found, made))
    del recent[RECENT:]
    return made


RECENT = 4  # task lists whose problems are looked up by the objects themselves (a loop alternating a few lists)


def _same_objects(held: tuple[Task, ...], tasks: Any) -> bool:
    """Whether ``tasks`` is a sequence of exactly the objects ``held`` (not equal ones: the same)."""
    try:
        return len(held) == len(tasks) and all(map(operator.is_, held, tasks))
    except TypeError:
        return False


def _new_list(_: Robot) -> list[Any]:
    return []


def _of_structure(robot: Robot, tasks: tuple[Task, ...]) -> cp.Packed | None:
    """The compiled problem of the task list's structure, packed once per robot and structure (its names checked
    first), or None where the compiled step does not take the tree or the list (kept as such)."""
    tree = robot.derived("compiled tree", cp.pack_tree)
    if tree is None:
        return None
    key = cp.structure(tasks)
    table: dict[Any, cp.Packed | None] = robot.derived("compiled steps", _new_table)
    if key not in table:
        for t in tasks:
            t.check(robot)
        _kept(table, key, cp.pack(robot, tree, tasks))
    return table[key]


def _kept(table: dict[Any, T], key: Any, value: T) -> T:
    """``table[key] = value`` in a table of at most MAX_PACKED entries (emptied when full)."""
    if len(table) >= MAX_PACKED:
        table.clear()
    table[key] = value
    return value


def _step(robot: Robot, q: np.ndarray, tasks: tuple[Task, ...], dt: float, limits: Limits, options: StepOptions,
          v_prev: np.ndarray | None) -> StepResult:
    """:func:`step` once its arguments are checked."""
    ev.forward(robot, q, com=any(t.uses_com for t in tasks))
    rows = ev.StepRows(robot.nv)
    errors = [task.add_to(rows, robot, q, dt) for task in tasks]
    levels, eq = rows.used(), rows.equalities
    vmax = velocity_bounds(limits, robot.space)
    lower, upper, returning = bounds(robot.space, q, dt, vmax, limits.position,
                                     acceleration_bounds(limits, robot.space), v_prev)
    A_eq, b_eq = (np.array([a for a, _ in eq]), np.array([c for _, c in eq])) if eq else (None, None)
    solution = _solve_level(levels[0], options, lower, upper, A_eq, b_eq, dt)
    iterations = solution.iterations
    if solution.solved and len(levels) > 1:
        second = _second_level(robot, levels, solution.v, options, lower, upper, A_eq, b_eq, dt)
        iterations += second.iterations
        solution = second if second.solved else solution
    v = solution.v if solution.solved else np.zeros(robot.nv)
    q_next = np.asarray(pin.integrate(robot.model, q, v * dt), dtype=float) if solution.solved else q.copy()
    status, solved = solution.status, solution.solved
    if solved and not (np.isfinite(v).all() and np.isfinite(q_next).all()):
        status, solved, v, q_next = qp.NOT_FINITE, False, np.zeros(robot.nv), q.copy()
    names = tuple(robot.space.names_v[i] for i in np.flatnonzero(returning))
    return StepResult(v, q_next, status, solved, tuple(errors), names, iterations)


def _second_level(robot: Robot, levels: list[ev.Rows], v_first: np.ndarray, options: StepOptions,
                  lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None, b_eq: np.ndarray | None, dt: float
                  ) -> qp.Solution:
    """The priority-2 tasks' QP, with what the first level reached held as equalities (its rows at ``v_first``)
    beside the couplings' (``A_eq``, ``b_eq``; None: none)."""
    held = np.vstack(levels[0].A) if levels[0].A else np.zeros((0, robot.nv))
    if A_eq is None or b_eq is None:
        return _solve_level(levels[1], options, lower, upper, held, held @ v_first, dt)
    return _solve_level(levels[1], options, lower, upper, np.vstack([A_eq, held]),
                        np.concatenate([b_eq, held @ v_first]), dt)


def _solve_level(rows: ev.Rows, options: StepOptions, lower: np.ndarray, upper: np.ndarray,
                 A_eq: np.ndarray | None, b_eq: np.ndarray | None, dt: float) -> qp.Solution:
    """One level's QP: H = Σ Aᵀ W A + diag + λI, f = −Σ Aᵀ W b − target (solved for v·dt, :func:`qp.solve`)."""
    nv = lower.shape[0]
    H = np.diag(rows.diag + options.damping)
    f = -rows.target.copy()
    if rows.A:
        A, b, w = np.vstack(rows.A), np.concatenate(rows.b), np.concatenate(rows.w)
        WA = A * w[:, None]
        H += A.T @ WA
        f -= WA.T @ b
    elif not rows.diag.any():
        H += np.eye(nv) * max(options.damping, 1e-12)
    return qp.solve(H, f, lower, upper, A_eq, b_eq, options.solver, dt)
