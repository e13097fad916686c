"""Inverse kinematics: one entry point, :func:`solve`, for every kinelab solver.

``solve`` validates the input, runs the chosen solver from a start and then from seeded random starts
until one succeeds or the time budget or restart count runs out, and re-checks the answer with
Pinocchio's FK: ``success`` means the returned q is within the joint limits and its tool pose is within
``tol_pos`` [m] and ``tol_rot`` [rad] of the target.
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import time
import warnings
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.ik import dls
from kinelab.ik.limits import wrap_q
from kinelab.ik.result import Attempt, IKResult, Status
from kinelab.ik.targets import TargetError, as_target, from_xyz_quat_wxyz, from_xyz_rpy
from kinelab.ik.workspace import out_of_reach
from kinelab.robot import Robot

AttemptFn = Callable[..., Attempt]
SOLVERS: dict[str, AttemptFn] = {"dls": dls.attempt}


def register(name: str, fn: AttemptFn) -> None:
    """Make ``fn`` available as ``solve(..., solver=name)``."""
    SOLVERS[name] = fn


def _solver(name: str) -> AttemptFn:
    _load_builtin_solvers()
    if name not in SOLVERS:
        raise KinelabError(f"unknown solver {name!r}; solvers are: {', '.join(sorted(SOLVERS))}")
    return SOLVERS[name]


_BUILTINS_LOADED = False


def _load_builtin_solvers() -> None:
    global _BUILTINS_LOADED
    if _BUILTINS_LOADED:
        return
    _BUILTINS_LOADED = True
    for name, module in (("frdm", "kinelab.ik.frdm.solver"), ("biquat", "kinelab.ik.biquat")):
        if name not in SOLVERS and importlib.util.find_spec(module) is not None:
            register(name, importlib.import_module(module).attempt)


@functools.cache
def _options_of(fn: AttemptFn) -> tuple[str, ...]:
    params = inspect.signature(fn).parameters
    return tuple(p for p, spec in params.items() if spec.kind == inspect.Parameter.KEYWORD_ONLY)


@functools.cache
def _module_of(fn: AttemptFn):
    return importlib.import_module(fn.__module__)


def _prepare(name: str, robot: Robot) -> None:
    prep = getattr(_module_of(SOLVERS[name]), "prepare", None)
    if prep is not None:
        prep(robot)


@functools.cache
def _fast_path_test(fn: AttemptFn):
    return getattr(_module_of(fn), "fast_path_allowed", None)


def _check_options(name: str, fn: AttemptFn, options: dict) -> None:
    valid = _options_of(fn)
    unknown = [k for k in options if k not in valid]
    if unknown:
        raise KinelabError(f"unknown option {unknown[0]!r} for solver {name!r}; its options are: {', '.join(valid)}")


class _LazyRng:
    """A seeded generator made on first use (making one costs more than most solves)."""

    def __init__(self, seed):
        self.seed, self._rng = seed, None

    def uniform(self, low, high, size=None):
        if self._rng is None:
            self._rng = np.random.default_rng(self.seed)
        return self._rng.uniform(low, high, size)


def _start(robot: Robot, q0, rng: _LazyRng, on_limits: str) -> np.ndarray:
    if q0 is None:
        return rng.uniform(robot.lower, robot.upper)
    q0 = robot.check_q(q0, what="q0")
    if robot.within_limits(q0):
        return q0
    if on_limits == "refuse":
        robot.check_q(q0, limits=True, what="q0")
    projected = np.clip(wrap_q(robot, q0), robot.lower, robot.upper)
    warnings.warn(f"q0 is outside the joint limits of {robot.name}; projected into them", stacklevel=3)
    return projected


def solve(
    robot: Robot,
    target: pin.SE3,
    solver: str = "frdm",
    q0=None,
    seed: int | None = None,
    tol_pos: float = 1e-6,
    tol_rot: float = 1e-6,
    time_budget: float = 1.0,
    max_restarts: int = 1000,
    start_outside_limits: str = "project",
    **solver_options,
) -> IKResult:
    """Solve IK for the tool pose ``target`` (``pin.SE3`` in the robot's base frame).

    Args:
        robot: the robot (:func:`kinelab.load`).
        target: oMtarget, the wanted tool pose in the base frame.
        solver: "frdm", "biquat" or "dls" (the Pinocchio reference).
        q0: first start (one number per joint); default a seeded random configuration.
        seed: seed of the random starts (restarts always draw from it, so runs repeat exactly).
        tol_pos: position tolerance [m]; tol_rot: rotation tolerance [rad] (angle of R*ᵀR).
        time_budget: wall-clock budget [s] for all attempts together.
        max_restarts: random restarts after the first attempt.
        start_outside_limits: "project" (default: move q0 into the limits, with a warning) or "refuse".
        solver_options: passed to the solver (see its ``attempt`` function).
    """
    fn = _solver(solver)
    _prepare(solver, robot)  # compilation and model building are not the solve's time
    t_start = time.perf_counter()
    if solver_options:
        _check_options(solver, fn, solver_options)
    target = as_target(target)
    if not (tol_pos > 0 and tol_rot > 0 and time_budget > 0 and max_restarts >= 0):
        raise KinelabError("tol_pos, tol_rot and time_budget must be positive and max_restarts ≥ 0")
    if start_outside_limits not in ("project", "refuse"):
        raise KinelabError("start_outside_limits must be 'project' or 'refuse'")
    rng = _LazyRng(seed)
    start = _start(robot, q0, rng, start_outside_limits)
    deadline = t_start + time_budget
    beyond = out_of_reach(robot, target.translation)
    if beyond > 0:
        max_restarts = 0  # proved out of reach: one attempt gives the best pose, restarts cannot help

    compiled = _compiled_multistart(solver, solver_options) if beyond <= 0 else None
    if compiled is not None:
        return _fast(compiled, solver, robot, target, start, tol_pos, tol_rot, deadline, seed, max_restarts,
                     solver_options, t_start)
    scale = robot.characteristic_length()
    best: tuple[float, Attempt, float, float] | None = None
    best_ok = False
    finals: list[tuple[Status, float]] = []
    iterations = restarts = 0
    events, bypasses = [], []
    for k in range(max_restarts + 1):
        att = fn(robot, target, start, tol_pos, tol_rot, deadline, **solver_options)
        iterations += att.iterations
        events += att.events
        bypasses += att.bypasses
        dp, dr = robot.tool_error(att.q, target)
        ok = dp <= tol_pos and dr <= tol_rot and robot.within_limits(att.q)
        score = dp / scale + dr
        if best is None or ok or score < best[0]:
            best, best_ok = (score, att, dp, dr), ok
        finals.append((att.status, dp))
        if ok or time.perf_counter() > deadline or k == max_restarts:
            break
        restarts += 1
        start = rng.uniform(robot.lower, robot.upper)

    _, att, dp, dr = best
    success = best_ok  # Pinocchio's check of the answer kept
    status, message = _status(success, att, finals, beyond, tol_pos, time.perf_counter() > deadline)
    return IKResult(
        q=att.q, success=success, status=status, position_error=dp, rotation_error=dr,
        iterations=iterations, restarts=restarts, wall_time=time.perf_counter() - t_start, solver=solver,
        mode=att.info.get("mode", solver), singular_events=events, bypasses=bypasses, message=message,
        info=att.info,
    )


def _compiled_multistart(solver: str, options: dict):
    """The solver's compiled multistart when the options ask for nothing it leaves out, else None."""
    allowed = _fast_path_test(SOLVERS[solver])
    return _module_of(SOLVERS[solver]).multistart if allowed is not None and allowed(options) else None


def _fast(multistart, solver, robot, target, start, tol_pos, tol_rot, deadline, seed, max_restarts, options,
          t_start) -> IKResult:
    """Restarts inside the solver's compiled kernel; the answer is then checked by Pinocchio."""
    att, restarts = multistart(robot, target, start, tol_pos, tol_rot, deadline, seed, max_restarts, **options)
    dp, dr = robot.tool_error(att.q, target)
    success = dp <= tol_pos and dr <= tol_rot and robot.within_limits(att.q)
    status, message = att.status, ""
    if success:
        status = Status.CONVERGED
    elif status == Status.CONVERGED:
        status, message = Status.STALLED, "the solver converged but its answer failed Pinocchio's check"
    return IKResult(
        q=att.q, success=success, status=status, position_error=dp, rotation_error=dr, iterations=att.iterations,
        restarts=restarts, wall_time=time.perf_counter() - t_start, solver=solver, mode=att.info["mode"],
        singular_events=att.events, message=message, info=att.info,
    )


def _status(success, att, finals, beyond, tol_pos, out_of_time) -> tuple[Status, str]:
    if success:
        return Status.CONVERGED, ""
    if beyond > 0:
        return Status.UNREACHABLE, f"the target position is at least {beyond:.4g} m beyond the robot's reach"
    stationary = [dp for st, dp in finals if st in (Status.STALLED, Status.SINGULAR)]
    agree = len(stationary) >= 3 and len(stationary) == len(finals) and min(stationary) > tol_pos
    if agree and max(stationary) - min(stationary) <= 1e-3 * min(stationary) + 1e-9:
        return Status.UNREACHABLE, (
            f"every one of {len(finals)} starts stopped at a stationary point {min(stationary):.4g} m from the "
            "target: it is very likely out of the workspace"
        )
    if att.status == Status.CONVERGED:  # the solver's own test passed but Pinocchio's or the limits did not
        return Status.STALLED, "the solver converged but its answer failed Pinocchio's check or the joint limits"
    if out_of_time and att.status != Status.TIME_BUDGET:
        return Status.TIME_BUDGET, f"best attempt ended {att.status.value}; then the time budget ran out"
    return att.status, ""


target_from_xyz_rpy = from_xyz_rpy
target_from_xyz_quat_wxyz = from_xyz_quat_wxyz

__all__ = ["IKResult", "Status", "TargetError", "register", "solve", "target_from_xyz_quat_wxyz",
           "target_from_xyz_rpy"]
