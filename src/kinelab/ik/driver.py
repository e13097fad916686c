"""The driver: one solve of one target for a validated :class:`~kinelab.ik.request.Request`.

It runs the chosen solver from a start and then from seeded random starts until one succeeds or the time
budget or restart count runs out, and re-checks the answer with Pinocchio's FK: ``success`` means the
returned q is within the joint limits and its tool pose is within ``tol_pos`` [m] and ``tol_rot`` [rad] of
the target on the components the task constrains. Every public entry point (:mod:`kinelab.ik.api`) ends here.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
import pinocchio as pin

from kinelab.core.spec import EngineSpec
from kinelab.ik.limits import turned_verdict, wrap_q
from kinelab.ik.registry import SolverOptions
from kinelab.ik.request import Request, verdict_reserve
from kinelab.ik.result import Attempt, BypassRecord, IKResult, SingularEvent, Status
from kinelab.ik.targets import as_target, out_of_reach, reach_bound
from kinelab.ik.tasks import POSE, Task, short_arm_note
from kinelab.robot import Chain
from kinelab.robot.chain import _compiled_judge
from kinelab.typing import Configuration, Target

if TYPE_CHECKING:
    from kinelab.ik.chain import ChainModel
    from kinelab.ik.registry import SolverModule

S = TypeVar("S", bound=EngineSpec)  # an engine's spec type


class _LazyRng:
    """A seeded generator made on first use (making one costs more than most solves)."""

    def __init__(self, seed: int | None):
        self.seed = seed
        self._rng: np.random.Generator | None = None

    def uniform(self, low: np.ndarray, high: np.ndarray, size: int | None = None) -> np.ndarray:
        if self._rng is None:
            self._rng = np.random.default_rng(self.seed)
        drawn: np.ndarray = self._rng.uniform(low, high, size)
        return drawn


def _start(robot: Chain, q0: Any, rng: _LazyRng, on_limits: str) -> np.ndarray:
    if q0 is None:
        return rng.uniform(robot.lower, robot.upper)
    q = robot.check_q(q0, what="q0")
    if robot.within_limits(q):
        return q
    if on_limits == "refuse":
        robot.check_q(q, limits=True, what="q0")
    projected: np.ndarray = np.clip(wrap_q(robot, q), robot.lower, robot.upper)
    warnings.warn(f"q0 is outside the joint limits of {robot.name}; projected into them", stacklevel=4)
    return projected


def solve_one(robot: Chain, target: Target, q0: Configuration | None, req: Request) -> IKResult:
    """Solve IK for one target.

    Args:
        robot: the robot.
        target: oMtarget (``pin.SE3`` in the base frame; a point for task "position").
        q0: the first start [rad or m], or None (a seeded random configuration).
        req: the validated request.

    Returns:
        The result, checked by Pinocchio on the components the task constrains.

    Raises:
        TargetError, ConfigurationError, JointLimitError: bad target or start, named.
    """
    module, opts = req.module, req.options
    prepare_solver(module, robot, opts)
    t_start = time.perf_counter()
    target = as_target(target, req.task.name)
    rng = _LazyRng(req.seed)
    budget = 1e9 if req.time_budget is None else req.time_budget - verdict_reserve(req.time_budget)
    problem = Call(robot, target, req.solver, req.tol_pos, req.tol_rot, t_start, t_start + budget, req.seed,
                       req.task, req.task_label)
    max_restarts = req.max_restarts
    # only a task that constrains the point can be out of reach (an orientation target's point is ignored)
    beyond = out_of_reach(robot, target.translation) if req.task.position else 0.0
    if beyond > 0:
        max_restarts = 0  # proved out of reach: one attempt gives the best pose, restarts cannot help
    elif getattr(opts, "compiled", False) and hasattr(module, "multistart"):
        start = None if q0 is None else _start(robot, q0, rng, req.start_outside_limits)  # None: the kernel draws
        return _fast(module, problem, start, max_restarts, opts)
    return _loop(module, problem, _start(robot, q0, rng, req.start_outside_limits), max_restarts, opts, rng, beyond)


def prepare_solver(module: SolverModule, robot: Chain, options: SolverOptions) -> None:
    """The solver module's model building for this robot (its ``prepare``, where it has one): not a solve's time."""
    prepare = getattr(module, "prepare", None)
    if prepare is not None:
        prepare(robot, options)


@dataclass(slots=True)
class Call:
    """What one solve is asked, handed between the driver's helpers (and to an engine's general result)."""

    robot: Chain
    target: pin.SE3
    solver: str
    tol_pos: float
    tol_rot: float
    t_start: float
    deadline: float
    seed: int | None
    task: Task = POSE
    task_label: str = "pose"
    finals: list[tuple[Status, float]] = field(default_factory=list)

    def judge(self, q: np.ndarray) -> tuple[np.ndarray, bool, float, float]:
        """The answer and the judge's verdict on it (Pinocchio's FK, or the compiled FK certified equal to it on
        this robot): (q, success, position error [m], rotation error [rad]) on the task's components (the rotation
        error of task "axis" is the angle between the tool axes). A revolute joint outside its limits with a whole
        turn of it inside is turned there first: the answer returned and judged is that one (the same pose)."""
        if not (q.dtype == np.float64 and q.ndim == 1 and q.flags.c_contiguous):
            q = np.ascontiguousarray(q, dtype=float)
        q, dp, dr, within = turned_verdict(self.robot, self.target.homogeneous, q, self.task.axis)
        return q, within and self.met(dp, dr), dp, dr

    def met(self, dp: float, dr: float) -> bool:
        """The task's components within the tolerances (position error dp [m], rotation error dr [rad])."""
        return self.task.met(dp, dr, self.tol_pos, self.tol_rot)


@dataclass(slots=True)
class _Tally:
    """The attempts of one solve so far: the best (by position error / reach + rotation error), and the sums."""

    score: float = np.inf
    best: Attempt | None = None
    ok: bool = False
    dp: float = np.nan
    dr: float = np.nan
    iterations: int = 0
    restarts: int = 0
    events: list[SingularEvent] = field(default_factory=list)
    bypasses: list[BypassRecord] = field(default_factory=list)

    def add(self, att: Attempt, ok: bool, dp: float, dr: float, scale: float) -> None:
        self.iterations += att.iterations
        self.events += att.events
        self.bypasses += att.bypasses
        score = dp / scale + dr
        if self.best is None or ok or score < self.score:
            self.score, self.best, self.ok, self.dp, self.dr = score, att, ok, dp, dr


def _attempts(module: Any, pb: Call, start: np.ndarray, max_restarts: int, opts: Any, rng: _LazyRng) -> _Tally:
    """Attempts from the start, then from seeded random starts, each judged, until one succeeds, the budget runs
    out or the restarts are spent."""
    robot, tally = pb.robot, _Tally()
    scale = robot.characteristic_length()
    for k in range(max_restarts + 1):
        att = module.attempt(robot, pb.target, start, pb.tol_pos, pb.tol_rot, pb.deadline, opts)
        att.q, ok, dp, dr = pb.judge(att.q)
        tally.add(att, ok, dp, dr, scale)
        pb.finals.append((att.status, dp))
        if ok or time.perf_counter() > pb.deadline or k == max_restarts:
            break
        tally.restarts += 1
        start = rng.uniform(robot.lower, robot.upper)
    return tally


def _loop(module: Any, pb: Call, start: np.ndarray, max_restarts: int, opts: Any, rng: _LazyRng,
          beyond: float) -> IKResult:
    """Attempts from the start, then from seeded random starts, each judged by Pinocchio."""
    tally = _attempts(module, pb, start, max_restarts, opts, rng)
    att, best_ok, dp, dr = tally.best, tally.ok, tally.dp, tally.dr
    assert att is not None
    status, message = _status(best_ok, att, pb.finals, beyond, pb.tol_pos, time.perf_counter() > pb.deadline)
    if not best_ok:
        status, message = _outside_limits(pb, att.q, dp, dr, status, message)
    # the answer's own attempt, apart from the restarts' (a user asks whether a bypass made this answer)
    diag = replace(att.diagnostics, answer_events=tuple(att.events), answer_bypasses=tuple(att.bypasses))
    return IKResult(
        q=att.q, success=best_ok, status=status, position_error=dp, rotation_error=dr,
        iterations=tally.iterations, restarts=tally.restarts, wall_time=time.perf_counter() - pb.t_start,
        solver=pb.solver, mode=att.mode or pb.solver, singular_events=tally.events, bypasses=tally.bypasses,
        message=_explained(pb, status, message), diagnostics=diag, task=pb.task_label,
        judge=pb.robot.fk_certificate.judge,
    )


def _fast(module: Any, pb: Call, start: np.ndarray | None, max_restarts: int, opts: Any) -> IKResult:
    """Restarts inside the solver's compiled kernel; the answer is then checked by Pinocchio."""
    att, restarts = module.multistart(pb.robot, pb.target, start, pb.tol_pos, pb.tol_rot, pb.deadline, pb.seed,
                                      max_restarts, opts)
    att.q, ok, dp, dr = pb.judge(att.q)
    return compiled_result(pb, att, restarts, ok, dp, dr)


def compiled_result(pb: Call, att: Attempt, restarts: int, success: bool, dp: float, dr: float) -> IKResult:
    """The result of a compiled multistart's attempt, given the judge's verdict on it (success, errors)."""
    status, message = att.status, ""
    if success:
        status = Status.CONVERGED
    elif status == Status.CONVERGED:
        status, message = Status.STALLED, "the solver converged but its answer failed Pinocchio's check"
    else:
        errors = [f"{dp:.3g} m"] * pb.task.position + [f"{dr:.3g} rad"] * pb.task.rotation
        message = (f"none of {restarts + 1} starts met the {pb.task.constrained} to the tolerances; the best "
                   f"answer is {' and '.join(errors)} from the target")
    if not success:
        status, message = _outside_limits(pb, att.q, dp, dr, status, message)
    return IKResult(
        q=att.q, success=success, status=status, position_error=dp, rotation_error=dr, iterations=att.iterations,
        restarts=restarts, wall_time=time.perf_counter() - pb.t_start, solver=pb.solver, mode=att.mode,
        singular_events=att.events, message=_explained(pb, status, message), diagnostics=att.diagnostics,
        task=pb.task_label, judge=pb.robot.fk_certificate.judge,
    )


def engine_spec(robot: Chain, req: Request, cm: ChainModel,
                attempt_of: Callable[[int, np.ndarray, np.ndarray, float], Attempt], mode: str,
                diagnostics: Callable[[np.ndarray], Any], spec_type: type[S], **kernel: Any) -> S:
    """What a solver's one-call engine (:class:`kinelab.core._engine.Engine`) reads from its prepared solver: the
    checks' bounds, the reach bound, the budget, the verdict's tolerances and components, the converged result's
    shared fields, and ``unmet``, which builds any other outcome's result exactly as the general route does.

    Args:
        robot: the robot.
        req: the prepared solver's request.
        cm: the robot's chain model.
        attempt_of: (the kernel's code, q, statistics, deadline [s]) → the :class:`Attempt` the general route builds.
        mode: the converged result's ``mode``.
        diagnostics: statistics → the result's diagnostics (called when they are first read).
        spec_type: the engine's spec (:class:`kinelab.core.spec.FRDMSpec`, :class:`~kinelab.core.spec.BiquatSpec`).
        kernel: the engine's own settings (its kernel's arrays and constants: the spec type's own fields, and
            ``pstar``, ``Rstar``, ``wrap_continuous``).
    """
    task, tol_pos, tol_rot = req.task, float(req.tol_pos), float(req.tol_rot)

    def unmet(target: Target, code: int, q: np.ndarray, stats: np.ndarray, dp: float, dr: float, ok: bool,
              t_start: float, deadline: float, seed: int) -> IKResult:
        call = Call(robot, target, req.solver, tol_pos, tol_rot, t_start, deadline, seed, task, req.task_label)
        return compiled_result(call, attempt_of(code, q, stats, deadline), max(0, int(stats[ATTEMPTS]) - 1), ok, dp, dr)

    anchor, radius = reach_bound(robot)
    lower, upper = robot.check_bounds
    budget = np.inf if req.time_budget is None else float(req.time_budget) - verdict_reserve(float(req.time_budget))
    fields = dict(success=True, status=Status.CONVERGED, solver=req.solver, mode=mode, message="",
                  task=req.task_label, judge=robot.fk_certificate.judge)
    radius = float(radius) if task.position else np.inf  # a point the task ignores is never out of reach
    return spec_type(
        kind=cm.kind, draw_lower=cm.lower, draw_upper=cm.upper, check_lower=lower, check_upper=upper,
        turn_lower=np.asarray(robot.lower, dtype=float), turn_upper=np.asarray(robot.upper, dtype=float),
        anchor=np.array(anchor, dtype=float), radius=radius, attempts=req.max_restarts + 1, budget=budget,
        tol_pos=tol_pos, tol_rot=tol_rot, check_pos=task.position, check_rot=task.rotation, axis=task.axis,
        se3=pin.SE3, result=IKResult, fields=fields, diagnostics=diagnostics, unmet=unmet, **kernel)


ATTEMPTS = 0  # the statistics slot in which every compiled multistart counts its attempts


def engine_judge(robot: Chain, options: SolverOptions) -> Any:
    """The judge an engine can use for these options: the robot's certified compiled FK (``kinelab.core._chain.
    Judge``) when the options run compiled, else None (no engine: the general route serves)."""
    return robot.derived("compiled judge", _compiled_judge) if getattr(options, "compiled", False) else None


def _outside_limits(pb: Call, q: np.ndarray, dp: float, dr: float, status: Status,
                    message: str) -> tuple[Status, str]:
    """A failed answer with a joint outside its limits: status OUTSIDE_LIMITS when the task's components are
    met (only the limits fail), the joint named either way."""
    where = _outside_where(pb.robot, q)
    if where is None:
        return status, message
    if pb.met(dp, dr) and status is not Status.UNREACHABLE:  # proved out of reach within the limits: that says more
        return Status.OUTSIDE_LIMITS, f"the {pb.task.constrained} are met, but only with {where}"
    return status, f"{message}; the best answer has {where}" if message else f"the best answer has {where}"


def _outside_where(robot: Chain, q: np.ndarray) -> str | None:
    """The first joint of q outside its limits, named with its value and limits (and how many more), or None."""
    lower, upper = robot.check_bounds
    outside = [i for i in range(robot.n) if not lower[i] <= q[i] <= upper[i]]
    if not outside:
        return None
    i = outside[0]
    unit = "m" if robot.joint_kinds[i] == "prismatic" else "rad"
    more = f" (and {len(outside) - 1} more)" if len(outside) > 1 else ""
    return f"joint {robot.joint_names[i]!r} at {q[i]:.6g} {unit}, outside its limits " \
           f"[{robot.lower[i]:.6g}, {robot.upper[i]:.6g}]{more}"


def _explained(pb: Call, status: Status, message: str) -> str:
    """The message, with the reason a short arm misses a whole pose and the tasks that fit it."""
    note = short_arm_note(pb.robot.name, pb.robot.n, pb.task.name)
    if status in (Status.CONVERGED, Status.OUTSIDE_LIMITS) or note is None:
        return message
    return f"{message}; {note}" if message else note


def _agreed_distance(finals: list[tuple[Status, float]], tol_pos: float) -> float | None:
    """The distance [m] at which at least three starts, all of them, stopped at a stationary point short of the
    target and agreeing to 0.1 % (the sign of a target out of the workspace), or None."""
    stationary = [dp for st, dp in finals if st in (Status.STALLED, Status.SINGULAR)]
    if len(stationary) < 3 or len(stationary) != len(finals) or min(stationary) <= tol_pos:
        return None
    low = min(stationary)
    return low if max(stationary) - low <= 1e-3 * low + 1e-9 else None


def _status(success: bool, att: Attempt, finals: list[tuple[Status, float]], beyond: float, tol_pos: float,
            out_of_time: bool) -> tuple[Status, str]:
    if success:
        return Status.CONVERGED, ""
    if beyond > 0:
        return Status.UNREACHABLE, f"the target position is at least {beyond:.4g} m beyond the robot's reach"
    agreed = _agreed_distance(finals, tol_pos)
    if agreed is not None:
        return Status.UNREACHABLE, (
            f"every one of {len(finals)} starts stopped at a stationary point {agreed:.4g} m from the "
            "target: it is very likely out of the workspace"
        )
    if att.status == Status.CONVERGED:  # the solver's own test passed but Pinocchio's or the limits did not
        return Status.STALLED, "the solver converged but its answer failed Pinocchio's check or the joint limits"
    if out_of_time and att.status != Status.TIME_BUDGET:
        return Status.TIME_BUDGET, f"best attempt ended {att.status.value}; then the time budget ran out"
    return att.status, ""
