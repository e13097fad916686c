"""One differential whole-body step: the velocity v [nv] that best does every task in dt, within the limits.

The step solves one QP (two with tasks of priority 2): minimize Σ w‖A v + gain·e/dt‖² over the tasks (each
weighted row by row), plus the posture's pull and a small damping λ‖v‖², subject to the limits as bounds on v
(:mod:`kinelab.wholebody.limits`) and the couplings as equalities. Tasks of priority 2 are solved second, with the
priority-1 tasks' rates A₁v held at the first answer's (they act in its null space). The new configuration is
q ⊕ v·dt through ``pin.integrate``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.robot.tree import Robot
from kinelab.values import is_real
from kinelab.wholebody import evaluate as ev
from kinelab.wholebody import qp
from kinelab.wholebody.constraints import Held, Inequality, feasible
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.tasks import Task, TaskError

if TYPE_CHECKING:
    from kinelab.collision.model import Contact


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
        closest: with collisions held, the nearest pair within margin + detection at the start (names and distance
            [m]), else None.
    """

    __slots__ = ("v", "q", "status", "solved", "iterations", "closest", "_errors", "_labels", "_returning",
                 "_names")

    def __init__(self, v: np.ndarray, q: np.ndarray, status: str, solved: bool,
                 errors: tuple[TaskError, ...] | np.ndarray, returning: tuple[str, ...] | np.ndarray = (),
                 iterations: int = 0, labels: tuple[str, ...] = (),
                 names: tuple[str, ...] = ()):
        """A step's answer (``errors``: TaskErrors, or an (ntasks, 2) array with ``labels``; ``returning``: joint
        names, or a bool mask over the velocities with ``names``)."""
        self.v, self.q, self.status, self.solved, self.iterations = v, q, status, solved, iterations
        self.closest: Contact | None = None
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


SEPARATE = 1e4  # the weight of a broken row's return (a pair in collision), where it cannot be held with the others
REFINE = 3  # re-solves of a step whose answer breaks an inequality its rows held (Inequality.overshoot)


def _step(robot: Robot, q: np.ndarray, tasks: tuple[Task, ...], dt: float, limits: Limits, options: StepOptions,
          v_prev: np.ndarray | None) -> StepResult:
    """:func:`step` once its arguments are checked."""
    ev.forward(robot, q, com=any(t.uses_com for t in tasks))
    rows = ev.StepRows(robot.nv)
    errors = [task.add_to(rows, robot, q, dt) for task in tasks]
    levels, eq = rows.used(), rows.equalities
    lower, upper, returning = _box(robot, q, dt, limits.boxes(), v_prev)
    A_eq, b_eq = (np.array([a for a, _ in eq]), np.array([c for _, c in eq])) if eq else (None, None)
    problem = _Levels(levels, options, lower, upper, (A_eq, b_eq), dt)
    held = limits.held()
    if held:
        solution, closest = _apart(robot, q, dt, held, problem)
    else:
        solution, closest = problem.solve(robot, None), None
    names = tuple(robot.space.names_v[i] for i in np.flatnonzero(returning))
    result = _result(robot, q, dt, solution, tuple(errors), names, solution.iterations)
    result.closest = closest
    return _settled(robot, q, dt, tasks, result) if result.solved and any(t.settled for t in tasks) else result


def _box(robot: Robot, q: np.ndarray, dt: float, boxes: tuple[Inequality, ...], v_prev: np.ndarray | None
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The bounds on v every bounded inequality asks for, intersected (the joints' limits first), and the velocities
    any of them is bringing back."""
    lower, upper, returning = boxes[0].bounds(robot, q, dt, v_prev)
    for inequality in boxes[1:]:
        lo, hi, back = inequality.bounds(robot, q, dt, v_prev)
        lower, upper, returning = np.maximum(lower, lo), np.minimum(upper, hi), returning | back
    return lower, upper, returning


@dataclass(frozen=True)
class _Levels:
    """A step's QP levels with their bounds and equalities, solved with given collision rows."""

    levels: list[ev.Rows]
    options: StepOptions
    lower: np.ndarray
    upper: np.ndarray
    eq: tuple[np.ndarray | None, np.ndarray | None]
    dt: float

    def pulled(self, A: np.ndarray, b: np.ndarray) -> _Levels:
        """These levels with rows ``A v ≈ b`` asked first, at the weight SEPARATE (pairs in collision brought out)."""
        first = self.levels[0]
        pulled = ev.Rows([*first.A, A], [*first.b, b], [*first.w, np.full(b.shape, SEPARATE)], first.diag,
                         first.target)
        return replace(self, levels=[pulled, *self.levels[1:]])

    def solve(self, robot: Robot, apart: qp.Inequalities | None) -> qp.Solution:
        """Both levels (the second where there are tasks of priority 2); iterations summed."""
        A_eq, b_eq = self.eq
        solution = _solve_level(self.levels[0], self.options, self.lower, self.upper, A_eq, b_eq, self.dt, apart)
        if not solution.solved or len(self.levels) < 2:
            return solution
        second = _second_level(robot, self.levels, solution.v, self.options, self.lower, self.upper, self.eq,
                               self.dt, apart)
        best = second if second.solved else solution
        return qp.Solution(best.v, best.status, True, solution.iterations + second.iterations)


def _apart(robot: Robot, q: np.ndarray, dt: float, held: tuple[Inequality, ...], problem: _Levels
           ) -> tuple[qp.Solution, Contact | None]:
    """The step with every inequality's rows (collisions': :mod:`~kinelab.wholebody.clearance`), solved again with
    the rows their answer's overshoot asks for (up to REFINE times); an answer that still breaks one is shortened."""
    starts = [inequality.rows(robot, q, dt) for inequality in held]
    closest = min((s.closest for s in starts if s.closest is not None), key=lambda c: c.distance, default=None)
    A = np.vstack([np.zeros((0, robot.nv)), *(s.A for s in starts)])
    b = feasible(A, np.concatenate([np.zeros(0), *(s.b for s in starts)]), problem.lower, problem.upper)
    solution = problem.solve(robot, qp.Inequalities(A, b) if b.size else None)
    if not solution.solved and (b > 0).any():  # rows broken at the start that cannot all be held at once
        inside = b > 0
        problem = problem.pulled(A[inside], b[inside])
        A, b = A[~inside], b[~inside]
        solution = problem.solve(robot, qp.Inequalities(A, b) if b.size else None)
    if not solution.solved:
        return solution, closest
    for _ in range(REFINE):
        q_next = _moved(robot, q, solution.v, dt)
        more = [m for i, s in zip(held, starts, strict=True) if (m := i.overshoot(robot, s, solution.v, q_next, dt))]
        if not more:
            return solution, closest
        A = np.vstack([A, *(m[0] for m in more)])
        b = np.concatenate([b, *(feasible(m[0], m[1], problem.lower, problem.upper) for m in more)])
        again = problem.solve(robot, qp.Inequalities(A, b))
        if not again.solved:
            break
        solution = again
    return _shortened(robot, q, dt, held, starts, solution), closest


def _moved(robot: Robot, q: np.ndarray, v: np.ndarray, dt: float) -> np.ndarray:
    return np.asarray(pin.integrate(robot.model, q, v * dt), dtype=float)


def _shortened(robot: Robot, q: np.ndarray, dt: float, held: tuple[Inequality, ...], starts: list[Held],
               solution: qp.Solution) -> qp.Solution:
    """The answer, halved until it breaks no inequality (none moved at all after 10 halvings): where the rows
    cannot say how an inequality changes within the step (a pair's nearest points), the step is made shorter."""
    v = solution.v
    for _ in range(10):
        q_next = _moved(robot, q, v, dt)
        if not any(i.breaks(robot, s, q_next) for i, s in zip(held, starts, strict=True)):
            return qp.Solution(v, solution.status, True, solution.iterations)
        v = 0.5 * v
    return qp.Solution(np.zeros_like(v), solution.status, True, solution.iterations)


HALVINGS = 8  # a step the loops' projection cannot close is halved at most this many times


def _settled(robot: Robot, q: np.ndarray, dt: float, tasks: tuple[Task, ...], result: StepResult) -> StepResult:
    """The step's q projected onto the equalities the QP holds to first order only (a loop's), v = (q_next ⊖ q)/dt
    again: the drift a step leaves (O(|v dt|²)) removed where it is made, not carried to the next step. A step too
    long for the projection to close the loops from (a passive joint at its stop on the way) is halved until it
    can (at most HALVINGS times; else the whole step, as the QP gave it)."""
    q_next, closed = _projected(robot, result.q, tasks)
    step = result.v * dt
    for _ in range(0 if closed else HALVINGS):
        step = 0.5 * step
        shorter, closed = _projected(robot, np.asarray(pin.integrate(robot.model, q, step), dtype=float), tasks)
        if closed:
            q_next = shorter
            break
    v = np.asarray(pin.difference(robot.model, q, q_next), dtype=float) / dt
    settled = StepResult(v, q_next, result.status, result.solved, result.errors, result.returning, result.iterations)
    settled.closest = result.closest
    return settled


def _projected(robot: Robot, q_next: np.ndarray, tasks: tuple[Task, ...]) -> tuple[np.ndarray, bool]:
    """q_next with every settled task's projection applied (a copy), and whether every one of them closed."""
    q_next = q_next.copy()
    closed = True
    for task in tasks:
        if task.settled:
            closed = task.project(robot, q_next) is not False and closed  # a task of the older protocol says None
    return q_next, closed


def _result(robot: Robot, q: np.ndarray, dt: float, solution: qp.Solution, errors: tuple[TaskError, ...],
            returning: tuple[str, ...], iterations: int) -> StepResult:
    """The step's answer: q ⊕ v·dt where the QP solved and its answer is finite, else v zero and q unmoved (status
    ``not finite`` for an answer that overflowed)."""
    status, solved = solution.status, solution.solved
    v = solution.v if solved else np.zeros(robot.nv)
    q_next = np.asarray(pin.integrate(robot.model, q, v * dt), dtype=float) if solved else q.copy()
    if solved and not (np.isfinite(v).all() and np.isfinite(q_next).all()):
        status, solved, v, q_next = qp.NOT_FINITE, False, np.zeros(robot.nv), q.copy()
    return StepResult(v, q_next, status, solved, errors, returning, iterations)


def _second_level(robot: Robot, levels: list[ev.Rows], v_first: np.ndarray, options: StepOptions,
                  lower: np.ndarray, upper: np.ndarray, eq: tuple[np.ndarray | None, np.ndarray | None], dt: float,
                  apart: qp.Inequalities | None) -> qp.Solution:
    """The priority-2 tasks' QP, with what the first level reached held as equalities (its rows at ``v_first``)
    beside the couplings' (``eq``: A_eq, b_eq; None: none) and the collision rows ``apart``."""
    A_eq, b_eq = eq
    held = np.vstack(levels[0].A) if levels[0].A else np.zeros((0, robot.nv))
    if A_eq is None or b_eq is None:
        return _solve_level(levels[1], options, lower, upper, held, held @ v_first, dt, apart)
    return _solve_level(levels[1], options, lower, upper, np.vstack([A_eq, held]),
                        np.concatenate([b_eq, held @ v_first]), dt, apart)


def _solve_level(rows: ev.Rows, options: StepOptions, lower: np.ndarray, upper: np.ndarray,
                 A_eq: np.ndarray | None, b_eq: np.ndarray | None, dt: float,
                 apart: qp.Inequalities | None = None) -> qp.Solution:
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
    return qp.solve(H, f, lower, upper, A_eq, b_eq, options.solver, dt, apart)
