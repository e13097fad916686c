"""The converged whole-body solve: a configuration that meets every task at once, judged per task by Pinocchio.

Two solvers. "step": the differential step iterated at dt = 1 s with full gain (a Gauss–Newton step of every task
at once, within the position limits), the posture asked for second (in the null space of the rest, so that it
never holds a task off its target): held still while the tasks converge, leaned towards once they are met
(:func:`~kinelab.wholebody.iterate.lean`). "frdm": FRDM carried to the tree (:mod:`kinelab.wholebody.frdm`).
On a free-flyer robot either starts with the first move (:mod:`kinelab.wholebody.approach`: the base and the
limbs brought to the tasks), and restarts from random configurations (the base left where the start has it, then
the same move) when it stalls, within the budget.

A task is met when its error is within ``tol_pos`` [m] and ``tol_rot`` [rad] (a posture is a preference: never
judged; a coupling within ``tol_pos``); the answer is a success when every task is met within the limits.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.ik.result import Status
from kinelab.robot.chain import Chain
from kinelab.robot.space import generator
from kinelab.robot.tree import Robot
from kinelab.typing import Configuration
from kinelab.wholebody.approach import approached
from kinelab.wholebody.constraints import Inequality, loops
from kinelab.wholebody.evaluate import kept_data
from kinelab.wholebody.frdm import frdm_solve
from kinelab.wholebody.iterate import SolveSettings, iterate, lean, posture_second
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.subject import as_robot
from kinelab.wholebody.tasks import Task, as_tasks

if TYPE_CHECKING:
    from collections.abc import Sequence

    from kinelab.collision.model import Contact


@dataclass(frozen=True)
class TaskVerdict:
    """One task judged at the answer by Pinocchio: its errors [m, rad] and whether they are within tolerance."""

    label: str
    position_error: float
    rotation_error: float
    met: bool


@dataclass(frozen=True)
class WholeBodyResult:
    """A converged solve's answer.

    Attributes:
        q: (nq,) the configuration (Pinocchio's q); success: every task met within the limits.
        status: ``converged``, ``outside_limits``, ``stalled``, ``max_iterations`` or ``time_budget``.
        tasks: each task's verdict (Pinocchio's FK and centre of mass), in the order given.
        iterations: steps (or FRDM sweeps) in all; restarts: random restarts after the first start.
        wall_time [s]; solver: "step" or "frdm"; judge: whose FK judged.
        closest: with ``limits.collisions``, the nearest pair at q over every monitored pair (names, distance [m]);
            an answer nearer than the margin is no success (status ``collision``).
    """

    q: np.ndarray
    success: bool
    status: Status
    tasks: tuple[TaskVerdict, ...]
    iterations: int
    restarts: int
    wall_time: float
    solver: str
    judge: str = "Pinocchio FK"
    closest: Contact | None = None

    @property
    def message(self) -> str:
        """The tasks not met, in words ("" when every one is)."""
        return "; ".join(f"{t.label}: {t.position_error:.3g} m, {t.rotation_error:.3g} rad" for t in self.tasks
                         if not t.met)


def solve(robot: Robot | Chain, tasks: Task | Sequence[Task], *, q0: Configuration | None = None, solver: str = "step",
          seed: int | None = None,
          tol_pos: float = 1e-6, tol_rot: float = 1e-6, max_iterations: int = 100, max_restarts: int = 200,
          time_budget: float | None = 1.0, limits: Limits | None = None) -> WholeBodyResult:
    """A configuration that meets every task (see the module's docstring).

    Args:
        robot: the whole robot, or a chain (its own joints: Pinocchio's q of its model;
            :mod:`~kinelab.wholebody.subject`).
        tasks: a task or a list of them.
        q0: the start (Pinocchio's q; None: the robot's neutral configuration).
        solver: "step" (the iterated differential step) or "frdm" (FRDM on the tree).
        seed: seed of the random restarts (None: fresh entropy).
        tol_pos: position tolerance [m] of every task.
        tol_rot: rotation tolerance [rad].
        max_iterations: steps (or sweeps) per start.
        max_restarts: random restarts after the first start.
        time_budget: wall-clock budget [s] of the whole solve (None: none).
        limits: the limits every step holds (default: the position limits; velocities mean nothing at dt = 1 s).

    Returns:
        The :class:`WholeBodyResult`, every task judged by Pinocchio.

    Raises:
        ChainError: not a whole robot. OptionError, TargetError, ConfigurationError, FrameNotFoundError,
            JointNotFoundError: bad input, named.
    """
    robot = as_robot(robot, "a whole-body solve")
    found = as_tasks(tasks) + loops(robot)  # a robot's closures held with its tasks
    settings = SolveSettings(solver, tol_pos, tol_rot, max_iterations, max_restarts, time_budget)
    limits = Limits(velocity=None) if limits is None else limits
    if not isinstance(limits, Limits):
        raise OptionError("limits", limits, "a kinelab.Limits(...), or None")
    start = robot.neutral() if q0 is None else robot.check_q(q0, what="q0")
    for t in found:  # a bad frame or joint named before any work
        t.check(robot)
    return _run(robot, found, start, settings, limits, seed)


def _run(robot: Robot, tasks: tuple[Task, ...], start: np.ndarray, settings: SolveSettings, limits: Limits,
         seed: int | None) -> WholeBodyResult:
    """Starts until one meets every task, the restarts or the budget run out; the best answer is returned."""
    t0 = time.perf_counter()
    deadline = math.inf if settings.time_budget is None else t0 + settings.time_budget
    rng = generator(seed)
    best: tuple[tuple[float, float], np.ndarray, Status] | None = None
    iterations, restarts = 0, 0
    q = _approached(robot, tasks, start, limits, deadline)
    while True:
        q, used, status = _converge(robot, tasks, q, settings, limits, deadline)
        iterations += used
        verdicts = judge(robot, tasks, q, settings.tol_pos, settings.tol_rot)
        score = (_penetration(robot, q, limits), _score(verdicts))  # a clear answer before any in collision
        if best is None or score < best[0]:
            best = (score, q, status)
        if score == (0.0, 0.0) or restarts >= settings.max_restarts or time.perf_counter() > deadline:
            break
        restarts += 1
        q = _restart(robot, start, rng, limits)
        for task in tasks:
            if task.settled:  # a restart starts on the robot's loops, as the mechanism would
                task.project(robot, q)
        q = _approached(robot, tasks, q, limits, deadline)
    _, q, status = best
    result = _result(robot, tasks, q, status, settings, iterations, restarts, time.perf_counter() - t0)
    held = limits.held()
    return _clear(robot, result, held) if held else result


def _converge(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, settings: SolveSettings, limits: Limits,
              deadline: float) -> tuple[np.ndarray, int, Status]:
    """One start run to convergence by the chosen solver: (q, iterations, status)."""
    if settings.solver == "frdm":
        return frdm_solve(robot, tasks, q, settings, deadline)
    q, used, status = iterate(robot, posture_second(tasks, pull=False), q, settings, limits, deadline)
    if status is not Status.CONVERGED:
        return q, used, status
    q, more = lean(robot, tasks, q, settings, limits, deadline)
    return q, used + more, status


def _result(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, status: Status, settings: SolveSettings,
            iterations: int, restarts: int, seconds: float) -> WholeBodyResult:
    """The answer judged once more by Pinocchio: converged only where every task is met within the limits."""
    verdicts = judge(robot, tasks, q, settings.tol_pos, settings.tol_rot)
    met = all(v.met for v in verdicts)
    within = robot.within_limits(q)
    final = Status.CONVERGED if met and within else Status.OUTSIDE_LIMITS if met else status
    return WholeBodyResult(q, met and within, final, verdicts, iterations, restarts, seconds, settings.solver)


def _approached(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, limits: Limits, deadline: float
                ) -> np.ndarray:
    """The first move from q (:mod:`~kinelab.wholebody.approach`), kept only where it breaks the inequalities held
    (a plane, a collision pair) no deeper than q does: the limbs are solved alone, blind to them."""
    moved = approached(robot, tasks, q, deadline)
    if moved is q or not limits.held():
        return moved
    return moved if _penetration(robot, moved, limits) <= _penetration(robot, q, limits) else q


def _penetration(robot: Robot, q: np.ndarray, limits: Limits) -> float:
    """How far q breaks the inequalities held (the most of any; 0: it breaks none, or none is asked)."""
    return max((max(0.0, -i.slack(robot, q)) for i in limits.held()), default=0.0)


def _clear(robot: Robot, result: WholeBodyResult, held: tuple[Inequality, ...]) -> WholeBodyResult:
    """The result with its nearest pair (coal's distance on every monitored pair, where collisions are held) and,
    where its q breaks an inequality (a pair nearer than the margin), no success (that inequality's status)."""
    contact = next((c for i in held if (c := i.nearest(robot, result.q)) is not None), None)
    broken = [i for i in held if i.slack(robot, result.q) < 0.0]
    if not broken:
        return replace(result, closest=contact)
    return replace(result, closest=contact, success=False,
                   status=broken[0].broken if result.success else result.status)


def _restart(robot: Robot, start: np.ndarray, rng: np.random.Generator, limits: Limits) -> np.ndarray:
    """A random configuration with the start's free-flyer (the base stays where the tasks put it); with collisions
    held, the first of up to RESTART_DRAWS clear of every pair (else the last drawn: the step brings it out)."""
    for _ in range(RESTART_DRAWS):
        q = robot.random_q(rng)
        if robot.floating:
            q[:7] = start[:7]
        if _penetration(robot, q, limits) == 0.0:
            break
    return q


RESTART_DRAWS = 20


def _score(verdicts: tuple[TaskVerdict, ...]) -> float:
    return sum(v.position_error + v.rotation_error for v in verdicts if not v.met)


def judge(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, tol_pos: float, tol_rot: float,
          ) -> tuple[TaskVerdict, ...]:
    """Each task's errors at q by Pinocchio's own FK (``framesForwardKinematics``) and centre of mass
    (``centerOfMass``), and whether they are within tolerance (a preference — a posture — is never judged: met)."""
    model, data = robot.model, kept_data(robot, "the solve's verdict")
    pin.framesForwardKinematics(model, data, q)
    com = pin.centerOfMass(model, data, q) if any(t.uses_com for t in tasks) else None
    out = []
    for task in tasks:
        dp, dr = task.judged(robot, data, q, com)
        tp, tr = (min(tol_pos, task.tolerance), min(tol_rot, task.tolerance)) if task.tolerance else (tol_pos, tol_rot)
        out.append(TaskVerdict(task.label, dp, dr, task.preference or (dp <= tp and dr <= tr)))
    return tuple(out)
