"""The validated request every IK entry point builds: one set of names, defaults and checks.

:func:`kinelab.solve`, :func:`kinelab.solve_batch`, :func:`kinelab.solve_all`, :func:`kinelab.track` and the
prepared :class:`kinelab.IK` take the same keywords (``solver``, ``seed``, ``tol_pos``, ``tol_rot``,
``time_budget``, ``max_restarts``, ``start_outside_limits``, ``task``, ``axis``, ``options`` or the
solver's option fields as keywords). Each turns them into one :class:`Request`, checked here once, and hands
it to the driver; no entry point checks an argument of its own.
"""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from kinelab.errors import ChainError, OptionError
from kinelab.ik.registry import SolverOptions, solver_module
from kinelab.ik.tasks import POSE, Task
from kinelab.robot import Chain
from kinelab.values import is_real

START_POLICIES = ("project", "refuse")
TOL_FLOOR = 1e-12
"""The smallest tolerance accepted [m or rad]: Pinocchio's FK in double precision rounds a tool pose by
~1e-16 per metre of chain, and two correct ways of measuring the same error (``pin.log3`` and the
atan2 angle) differ by that much; a finer tolerance could not be checked, so a success against it
would be a guess."""


@contextmanager
def unmeetable_tolerances() -> Iterator[None]:
    """Within the block, accept tolerances below :data:`TOL_FLOOR` (down to any number > 0): for measurements
    that need calls no answer can end, such as how well a solve keeps its ``time_budget``. Not thread-safe
    (it changes the module's floor for the block)."""
    global TOL_FLOOR
    kept, TOL_FLOOR = TOL_FLOOR, 0.0
    try:
        yield
    finally:
        TOL_FLOOR = kept


@dataclass(frozen=True, slots=True)
class Request:
    """What a solve is asked, validated.

    Attributes:
        solver: the solver's name; module: its module (:mod:`kinelab.ik.registry`).
        options: the solver's options object, already adapted to ``task``.
        task: the components to meet.
        tol_pos: position tolerance [m]; tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget of the call [s] (None: none).
        max_restarts: random restarts after the first attempt (per target).
        seed: base seed of the random starts (None: fresh entropy).
        start_outside_limits: "project" (move a start into the limits, with a warning) or "refuse".
    """

    solver: str
    module: Any
    options: Any
    task: Task
    tol_pos: float
    tol_rot: float
    time_budget: float | None
    max_restarts: int
    seed: int | None
    start_outside_limits: str

    @property
    def task_label(self) -> str:
        """The task as results name it: "pose", "position", "orientation" or "axis z" (with its axis)."""
        return self.task.name if self.task.axis < 0 else f"axis {'xyz'[self.task.axis]}"


def check_robot(robot: object) -> None:
    """Refuse anything but a :class:`kinelab.Chain` where an entry point takes the robot.

    Raises:
        ChainError: naming what was given.
    """
    if not isinstance(robot, Chain):
        raise ChainError(f"the robot must be a kinelab.Chain (kinelab.load(...) or Chain.from_model(...)), got "
                         f"{type(robot).__name__}")


def make_request(solver: str = "frdm", seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6,
                 time_budget: float | None = 1.0, max_restarts: int = 1000, start_outside_limits: str = "project",
                 options: SolverOptions = None, task: str = "pose", axis: str = "z",
                 solver_options: dict[str, Any] | None = None) -> Request:
    """Check every argument once and build the :class:`Request`.

    Raises:
        SolverNotFoundError: an unknown solver.
        OptionError: a bad value (named, with what is valid), an option the solver does not have, both
            ``options`` and option keywords, or a task the solver cannot meet.
    """
    module = solver_module(solver)
    opts = module.Options.of(options, **(solver_options or {}))
    tk = Task.of(task, axis)
    if tk is not POSE:
        opts = for_task(solver, opts, tk)
    check_arguments(tol_pos, tol_rot, time_budget, max_restarts, seed, start_outside_limits)
    return Request(solver, module, opts, tk, float(tol_pos), float(tol_rot),
                   None if time_budget is None else float(time_budget), int(max_restarts),
                   None if seed is None else int(seed), start_outside_limits)


def for_task(solver: str, opts: SolverOptions, task: Task) -> SolverOptions:
    """The solver's options for a task other than "pose" (its ``for_task``).

    Raises:
        OptionError: the solver meets whole poses only.
    """
    made = getattr(opts, "for_task", None)
    if made is None:
        raise OptionError("task", task.name, f"'pose' for solver {solver!r}, which drives the whole pose; "
                          "solvers 'frdm' and 'dls' take 'position', 'axis' and 'orientation' too")
    return made(task)  # type: ignore[no-any-return]


def check_arguments(tol_pos: float, tol_rot: float, time_budget: float | None, max_restarts: int, seed: object,
                    start_outside_limits: str) -> None:
    """Refuse what no entry point can honour, naming the argument, the value and what is valid.

    Raises:
        OptionError: the first bad argument.
    """
    if _plain_positive(tol_pos, tol_rot, 1.0 if time_budget is None else time_budget) \
            and min(tol_pos, tol_rot) >= TOL_FLOOR and _plain_counts(max_restarts, seed) \
            and start_outside_limits in START_POLICIES:
        return  # the common case, checked fast
    _check_positive("tol_pos", tol_pos, TOL_FLOOR)
    _check_positive("tol_rot", tol_rot, TOL_FLOOR)
    if time_budget is not None:
        _check_positive("time_budget", time_budget, 0.0)
    _check_counts(max_restarts, seed, start_outside_limits)


def _check_counts(max_restarts: Any, seed: Any, start_outside_limits: Any) -> None:
    """:func:`check_arguments` on the restart count, the seed and the start policy."""
    if not count_ok(max_restarts) or max_restarts > MAX_RESTARTS:
        raise OptionError("max_restarts", max_restarts, f"an integer from 0 to {MAX_RESTARTS:,} (the kernels count "
                          "attempts in 32-bit integers; a time_budget bounds a long search)")
    if seed is not None and not count_ok(seed):
        raise OptionError("seed", seed, "an integer ≥ 0, or None for fresh entropy")
    if not isinstance(start_outside_limits, str) or start_outside_limits not in START_POLICIES:
        raise OptionError("start_outside_limits", start_outside_limits, "'project' or 'refuse'")


def _check_positive(name: str, value: Any, floor: float) -> None:
    """Refuse a value that is not a finite real > 0 and ≥ floor (a tolerance's floor: :data:`TOL_FLOOR`)."""
    if not is_real(value, 0, above=True):
        raise OptionError(name, value, "a finite number > 0" + (" or None" if name == "time_budget" else ""))
    if float(value) < floor:
        raise OptionError(name, value, f"a finite number ≥ {floor:g} (a finer error is below the rounding of "
                          "Pinocchio's double-precision FK and could not be checked)")


def _plain_positive(a: Any, b: Any, c: Any) -> bool:
    """All three Python floats in (0, inf)."""
    return (type(a) is float and type(b) is float and type(c) is float
            and 0.0 < a < math.inf and 0.0 < b < math.inf and 0.0 < c < math.inf)


def _plain_counts(max_restarts: Any, seed: Any) -> bool:
    return type(max_restarts) is int and 0 <= max_restarts <= MAX_RESTARTS and \
        (seed is None or (type(seed) is int and seed >= 0))


def check_seed(seed: object, name: str = "seed") -> None:
    """Refuse a seed that is not an integer ≥ 0 (numpy's generators take no other).

    Raises:
        OptionError: naming the value and what is valid.
    """
    if not count_ok(seed):
        raise OptionError(name, seed, "an integer ≥ 0" + (", or None for fresh entropy" if name == "seed" else ""))


MAX_RESTARTS = 10**9  # restarts a solve may ask for: more than any budget runs, and within the kernels' C ints


def count_ok(value: object) -> bool:
    """An integer ≥ 0 (a bool is not a count)."""
    return not isinstance(value, bool) and isinstance(value, numbers.Integral) and int(value) >= 0


def verdict_reserve(budget: float) -> float:
    """Seconds of a solve's ``time_budget`` [s] kept back for what follows the solver: the verdict, the status and
    the result, which after milliseconds of kernel work run with cold caches (≈ 0.1–0.2 ms on the development
    machine, against ≈ 15 µs warm). 4 % of the budget, at most 0.2 ms: the bench's allowance is 5 % + 0.1 ms."""
    return min(2e-4, 0.04 * budget)


class Deadline:
    """A budget's end for a loop of uneven steps: :meth:`near` says whether the next step, as slow as the slowest
    one so far, would end past it, so that a loop stops before a step that overruns rather than after it.

    Args:
        start: ``time.perf_counter()`` when the budget began [s].
        budget: the budget [s] (None: none; the deadline never comes).
    """

    __slots__ = ("end", "slowest", "last")

    def __init__(self, start: float, budget: float | None):
        self.end = math.inf if budget is None else start + budget - verdict_reserve(budget)
        self.slowest, self.last = 0.0, start

    def near(self) -> bool:
        """Call before each step: True when the step after the one just finished would pass the end."""
        now = time.perf_counter()
        self.slowest, self.last = max(self.slowest, now - self.last), now
        return now + self.slowest > self.end
