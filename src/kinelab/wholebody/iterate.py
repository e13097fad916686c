"""The iterated differential step: Gauss–Newton on every task at once at dt = 1 s, within the position limits and
a cap on each joint's change per iteration (what keeps the linearization honest far from the answer). The
converged solve (:mod:`kinelab.wholebody.solve`) and FRDM's finish (:mod:`kinelab.wholebody.frdm`) run it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from kinelab.ik import options as opt
from kinelab.ik.result import Status
from kinelab.robot.tree import Robot
from kinelab.wholebody import compiled as cp
from kinelab.wholebody.limits import Limits, acceleration_bounds, velocity_bounds
from kinelab.wholebody.step import StepOptions, StepResult, _step
from kinelab.wholebody.tasks import Task, TaskError

SOLVERS = ("step", "frdm")
STALL = 1e-3  # a step that takes off less than this share of the error, ten times running, is a stall


@dataclass(frozen=True)
class SolveSettings:
    """The solve's checked settings (see :func:`solve`)."""

    solver: str = "step"
    tol_pos: float = 1e-6
    tol_rot: float = 1e-6
    max_iterations: int = 100
    max_restarts: int = 200
    time_budget: float | None = 1.0
    damping: float = 1e-6
    max_step: float = 1.0  # [rad or m] the largest joint change of one iteration: keeps Gauss–Newton's linearization

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        opt.choice("solver", self.solver, SOLVERS)
        for name in ("tol_pos", "tol_rot"):
            opt.positive(name, getattr(self, name))
        opt.positive("max_iterations", self.max_iterations, integer=True)
        opt.positive("max_restarts", self.max_restarts, integer=True, zero=True)
        opt.positive("time_budget", self.time_budget, allow_none=True)
        opt.positive("damping", self.damping, zero=True)


def posture_second(tasks: tuple[Task, ...], pull: bool = True) -> tuple[Task, ...]:
    """The tasks as a converged solve asks for them (:meth:`~kinelab.wholebody.tasks.Task.second`: every posture
    second, priority 2), so that it meets the others exactly; without ``pull``, every posture holds the joints where
    they are (the converged solve's first phase)."""
    return tuple(t.second(pull) for t in tasks)


def iterate(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, settings: SolveSettings, limits: Limits,
            deadline: float) -> tuple[np.ndarray, int, Status]:
    """The step at dt = 1 s, full gain, until the tasks are met, it stalls, or the iterations or time run out. A step
    that does not lower the merit (Σ of every error squared, each in units of its tolerance) is cut in half along
    the same direction from where it started: full Gauss–Newton steps circle a solution near a singularity."""
    options, limits = _setup(settings, limits)
    step = stepper(robot, tasks, limits, options)
    accepted: tuple[np.ndarray, np.ndarray, float] | None = None  # (q, its full step's q, merit)
    share, still, best = 1.0, 0, math.inf
    for k in range(settings.max_iterations):
        if time.perf_counter() > deadline:
            return q, k, Status.TIME_BUDGET
        result = step(q)
        size, merit = _size(result.errors, tasks, settings)
        if size <= 1.0:
            return q, k, Status.CONVERGED
        if not result.solved:
            return q, k + 1, Status.STALLED
        if accepted is not None and merit > accepted[2] * (1.0 - 1e-4):
            share /= 2.0  # worse than where it stood: a shorter step the same way
            if share < 1e-3:
                return accepted[0], k + 1, Status.STALLED
            q = _toward(robot, accepted[0], accepted[1], share)
            continue
        still = still + 1 if merit > best * (1.0 - STALL) else 0
        best = min(best, merit)
        if still >= 10:
            return q, k + 1, Status.STALLED
        accepted, share = (q, result.q, merit), 1.0
        q = result.q
    return q, settings.max_iterations, Status.MAX_ITERATIONS


def lean(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, settings: SolveSettings, limits: Limits,
         deadline: float) -> tuple[np.ndarray, int]:
    """From a q that meets the tasks, towards the postures they leave room for: LEAN_STEPS times, one step with the
    postures pulling (the tasks held to first order), then the tasks met again with the postures holding still.

    Returns:
        (the last q that met every task — q itself when the first lean does not come back —, steps taken).
    """
    if not any(t.preference for t in tasks):
        return q, 0
    held = posture_second(tasks, pull=False)
    options, limits = _setup(settings, limits)
    pull = stepper(robot, posture_second(tasks), limits, options)
    used = 0
    for _ in range(LEAN_STEPS):
        moved = pull(q)
        if not moved.solved:
            break
        again, steps, status = iterate(robot, held, moved.q, settings, limits, deadline)
        used += steps + 1
        if status is not Status.CONVERGED:
            break
        q = again
    return q, used


LEAN_STEPS = 2


def _setup(settings: SolveSettings, limits: Limits) -> tuple[StepOptions, Limits]:
    """The step's options and limits at dt = 1 s: the settings' damping, and the settings' cap on each joint's change
    an iteration where the limits set no velocity (velocities mean nothing at dt = 1 s)."""
    return StepOptions(damping=settings.damping), (replace(limits, velocity=settings.max_step)
                                                   if limits.velocity is None else limits)


def stepper(robot: Robot, tasks: tuple[Task, ...], limits: Limits, options: StepOptions
            ) -> Callable[[np.ndarray], StepResult]:
    """The step at dt = 1 s for these tasks, as a function of q: the compiled one (the readable one's answers, in one
    call; its problem packed once per task structure and kept on the robot, the targets written at each call) where
    it serves, else the readable one (:mod:`kinelab.wholebody.step`)."""
    packed = _kept_packed(robot, tasks, options) if limits.compiled and not (robot.closures or robot.mimics) \
        else None  # a robot's couplings as tasks: the readable step (docs/bench/standing-approach-2026-12-07.md)
    if packed is None or acceleration_bounds(limits, robot.space) is not None:
        return lambda q: _step(robot, q, tasks, 1.0, limits, options, None)
    bounds = (np.ascontiguousarray(velocity_bounds(limits, robot.space), dtype=float), limits.position, cp.NO_LIMIT)

    def step(q: np.ndarray) -> StepResult:
        cp.set_targets(robot, packed, tasks)  # another solve of the same structure may have written its own
        found = cp.run(packed, robot, np.ascontiguousarray(q, dtype=float), 1.0, bounds, None, options.damping)
        return _step(robot, q, tasks, 1.0, limits, options, None) if found is None else found

    return step


def _kept_packed(robot: Robot, tasks: tuple[Task, ...], options: StepOptions) -> cp.Packed | None:
    """The compiled problem of this task structure (None: the compiled step does not serve it), packed once."""
    table: dict[tuple[object, ...], cp.Packed | None] = robot.derived("converged solve's compiled problems",
                                                                       lambda _: {})
    key = (cp.structure(tasks), options.solver)
    if key not in table:
        if len(table) >= KEPT:
            table.clear()
        table[key] = cp.packed_for(robot, tasks, options.solver)
    return table[key]


KEPT = 32  # task structures kept per robot (a caller sweeping weights: the memory stays bounded)


def _toward(robot: Robot, q: np.ndarray, q_full: np.ndarray, share: float) -> np.ndarray:
    """The configuration ``share`` of the way from ``q`` to ``q_full`` on the model's manifold."""
    model = robot.model
    return pin.integrate(model, q, share * pin.difference(model, q, q_full))


def _size(errors: tuple[TaskError, ...], tasks: tuple[Task, ...], settings: SolveSettings) -> tuple[float, float]:
    """(the largest error, the sum of the errors squared), each in units of its tolerance, a posture left out."""
    scaled = [(e.position / settings.tol_pos, e.rotation / settings.tol_rot)
              for e, t in zip(errors, tasks, strict=True) if not t.preference]
    return max((max(p, r) for p, r in scaled), default=0.0), sum(p * p + r * r for p, r in scaled)
