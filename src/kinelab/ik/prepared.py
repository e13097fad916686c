"""The prepared solver: build once, call in the loop (what TRAC-IK's solver, pink's Configuration and rtb's
``ets.ik_LM`` users already do).

``IK(robot, solver=..., task=..., tol_pos=..., ...)`` checks every setting once and compiles the solver's
kernels before it returns; ``ik.solve(target, q0=...)`` then checks only what changes per call (the target and
the start), so a call pays no argument validation or option building. Its answers are those of
:func:`kinelab.solve` with the same settings and seed (tested), and every one is judged.

The prepared solver owns its solver's engine (:class:`kinelab.core._engine.Engine`; compiled FRDM's comes with
:class:`LeanFRDM`, the biquaternion preset's from its module's ``engine``). The usual call — a ``pin.SE3`` target, a
float64 start of the right length (or none), an integer seed or none — on a robot whose compiled FK is certified
is one compiled call: it checks both (finite, a proper rotation, the start within the limits, the target within
the reach bound), runs the multistart and judges the answer; the result is built directly, its diagnostics only
when read. On a robot judged by Pinocchio's FK, FRDM's usual call runs as three compiled calls with Pinocchio's
verdict between them. Anything else (a point target, a list start, a start outside the limits, a target beyond
reach) takes the general driver, which names the problem, warns or answers UNREACHABLE
exactly as :func:`kinelab.solve` does: the engine changes the cost, never the answer.
"""

from __future__ import annotations

import os
import time
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.collision.model import as_collisions, collision_model
from kinelab.core._engine import Engine, FRDMEngine
from kinelab.core._verdict import usual_inputs
from kinelab.geometry import stack_homogeneous
from kinelab.ik.analytic.branches import (
    NearestBranch,
    analytic_one,
    arm_of,
    nearest_batch,
    prepared_form,
    refuse_options,
)
from kinelab.ik.batch import BatchIKResult, run_batch
from kinelab.ik.branches import UNSEEN, find_all, route_of
from kinelab.ik.clear import clear_batch, mark_colliding, solve_clear
from kinelab.ik.driver import Call, compiled_result, prepare_solver, solve_one
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm import solver as frdm
from kinelab.ik.limits import turned_verdict
from kinelab.ik.registry import capabilities
from kinelab.ik.request import Request, check_robot, check_seed, make_request, verdict_reserve
from kinelab.ik.result import Branches, IKResult, Status
from kinelab.ik.targets import as_target, as_target_arrays, reach_bound
from kinelab.robot import Robot
from kinelab.robot.model import _compiled_judge

SEED_LIMIT = 1 << 64
OK = 0  # usual_inputs: the call is the usual one


class LeanFRDM:
    """The engine of a prepared compiled-FRDM solver, and its lean call where the engine cannot serve (see the
    module's docstring).

    Args:
        robot: the robot.
        req: the prepared solver's request (solver "frdm" with options the compiled multistart serves).
    """

    def __init__(self, robot: Robot, req: Request):
        self.robot, self.req = robot, req
        self.ctx = frdm._context(robot, req.options, float(req.tol_pos), float(req.tol_rot))
        self.lower, self.upper = robot.check_bounds
        anchor, radius = reach_bound(robot)
        self.anchor = np.array(anchor, dtype=float)
        self.radius = float(radius) if req.task.position else np.inf  # an ignored point is never out of reach
        self.none = np.empty(0)
        self.budget = np.inf if req.time_budget is None else \
            float(req.time_budget) - verdict_reserve(float(req.time_budget))
        self.attempts = req.max_restarts + 1
        self.axis, self.n = req.task.axis, robot.n
        self.check_pos, self.check_rot = req.task.position, req.task.rotation
        self.tol_pos, self.tol_rot, self.task_label = req.tol_pos, req.tol_rot, req.task_label
        self.judge = robot.fk_certificate.judge  # certified here, before any call's clock starts
        self.engine = self._engine()

    def _engine(self) -> FRDMEngine | None:
        """The one-call engine, where the robot's compiled FK is its judge (else None)."""
        judge = self.robot.derived("compiled judge", _compiled_judge)
        if judge is None:
            return None
        ctx, cm = self.ctx, self.ctx.cm
        spec = SimpleNamespace(
            kind=cm.kind, draw_lower=cm.lower, draw_upper=cm.upper, check_lower=self.lower, check_upper=self.upper,
            turn_lower=np.asarray(self.robot.lower, dtype=float), turn_upper=np.asarray(self.robot.upper, dtype=float),
            wrap_continuous=True, anchor=self.anchor, radius=self.radius, pstar=ctx.pstar, Rstar=ctx.Rstar,
            order=ctx.order, cap=ctx.cap,
            attempts=self.attempts, first_chunk=ctx.chunk, later_chunk=ctx.later_chunk, budget=self.budget,
            tol_pos=float(self.tol_pos), tol_rot=float(self.tol_rot), check_pos=bool(self.check_pos),
            check_rot=bool(self.check_rot), axis=self.axis, se3=pin.SE3, result=IKResult, fields=dict(
                success=True, status=Status.CONVERGED, solver="frdm", mode=ctx.mode, message="",
                task=self.task_label, judge=self.judge),
            diagnostics=self._diagnostics, stall_events=ctx.stall_events, unmet=self._unmet)
        return FRDMEngine(ctx.packed, judge, spec)

    def _diagnostics(self, stats: np.ndarray) -> Any:
        return self.ctx.diagnostics(stats.tolist())

    def _unmet(self, target: Any, code: int, q: np.ndarray, stats: np.ndarray, dp: float, dr: float, ok: bool,
               t_start: float, deadline: float, seed: int) -> IKResult:
        """The engine's result of any outcome but a confirmed convergence (the general path's bookkeeping)."""
        call = Call(self.robot, target, self.req.solver, self.tol_pos, self.tol_rot, t_start, deadline, seed,
                    self.req.task, self.task_label)
        return compiled_result(call, self.ctx.attempt(code, q, stats, deadline),
                               max(0, int(stats[kernel.T_ATTEMPTS]) - 1), ok, dp, dr)

    def solve(self, target: Any, q0: Any, seed: Any) -> IKResult | None:
        """The result for the usual call in three compiled calls with the robot's verdict between them, or None for
        the general driver (see the module's docstring); where :attr:`engine` exists, the prepared solver calls it
        instead."""
        t_start = time.perf_counter()
        start, seed = self._usual(target, q0, seed)
        if start is None:
            return None
        H = target.homogeneous
        ctx = self.ctx
        if usual_inputs(H, start, self.n, self.lower, self.upper, self.anchor, self.radius, ctx.pstar, ctx.Rstar) != OK:
            return None
        deadline = t_start + self.budget
        code, q, stats = ctx.run_aimed(None if q0 is None else start, seed, self.attempts, deadline)
        if ctx.continuous:
            q = self.robot.wrap_continuous(q)
        q, dp, dr, ok = self._judged(H, q)
        if ok and code == kernel.CONVERGED:  # the usual outcome, built without the general path's bookkeeping
            return self._converged(q, stats, dp, dr, t_start)
        call = Call(self.robot, target, self.req.solver, self.tol_pos, self.tol_rot, t_start, deadline, seed,
                    self.req.task, self.task_label)
        return compiled_result(call, ctx.attempt(code, q, stats, deadline), max(0, int(stats[kernel.T_ATTEMPTS]) - 1),
                               ok, dp, dr)

    def _judged(self, H: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, float, float, bool]:
        """(the answer, turned into the limits where a whole turn does it; position error [m], rotation error
        [rad], the task's components met within the limits)."""
        q, dp, dr, within = turned_verdict(self.robot, H, q, self.axis)
        return q, dp, dr, within and (not self.check_pos or dp <= self.tol_pos) and \
            (not self.check_rot or dr <= self.tol_rot)

    def _usual(self, target: Any, q0: Any, seed: Any) -> tuple[np.ndarray | None, int]:
        """(the kernel's start array, the seed) of a usual call — a ``pin.SE3`` target, a C-contiguous float64
        start or none, an integer seed or none (fresh entropy, as the general path draws) — else (None, 0)."""
        if type(target) is not pin.SE3:
            return None, 0
        if q0 is None:
            start = self.none
        elif type(q0) is np.ndarray and q0.dtype == np.float64 and q0.shape == (self.n,) and q0.flags.c_contiguous:
            start = q0
        else:
            return None, 0
        if seed is None:
            return start, int.from_bytes(os.urandom(8), "little")
        if type(seed) is not int or not 0 <= seed < SEED_LIMIT:
            return None, 0
        return start, seed

    def _converged(self, q: np.ndarray, stats: np.ndarray, dp: float, dr: float, t_start: float) -> IKResult:
        """The result of a converged solve that the judge confirmed (what the context's ``attempt`` and the
        driver would build, fewer steps)."""
        st = stats.tolist()
        sweeps, stalls = int(st[kernel.T_SWEEPS]), int(st[kernel.T_STALLS])
        diag = self.ctx.diagnostics(st)
        events = self.ctx.stall_events(stalls) if stalls else []
        return IKResult(q=q, success=True, status=Status.CONVERGED, position_error=dp, rotation_error=dr,
                        iterations=sweeps, restarts=max(0, int(st[kernel.T_ATTEMPTS]) - 1),
                        wall_time=time.perf_counter() - t_start, solver="frdm", mode=self.ctx.mode,
                        singular_events=events, diagnostics=diag, task=self.task_label, judge=self.judge)


class IK:
    """A solver prepared for one robot and one set of settings.

    Args:
        robot: the robot.
        positional: nothing: every setting is keyword-only.
        solver: "frdm", "biquat" or "dls"; "analytic" (the closed form, docs/analytic.md: ``solve`` returns the
            branch nearest ``q0``, ``solve_all`` every branch; refused here, by name, for a chain without one); or
            "auto" (``solve_all`` as :func:`kinelab.solve_all`'s default: the closed form where the chain has one,
            else FRDM's multistart; ``solve`` and ``solve_batch`` run FRDM). ``solve_all`` takes the route
            :func:`kinelab.solve_all` takes for the same solver and options.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget of each call [s] (None: none).
        max_restarts: random restarts after the first attempt.
        start_outside_limits: "project" (a start outside the limits is moved into them, with a warning) or
            "refuse".
        options: the solver's options object.
        task: "pose", "position", "axis" or "orientation".
        axis: the tool axis of task "axis".
        collisions: as :func:`kinelab.solve` (None, "self", an Environment or a Collisions): every answer of
            every call must be clear; the collision model is built here, once.
        solver_options: the solver's option fields as keyword arguments.

    Raises:
        TypeError: a setting given positionally.
        SolverNotFoundError, OptionError: a bad setting, named (once, here).
    """

    def __init__(self, robot: Robot, *positional: Any, solver: str = "frdm", tol_pos: float = 1e-6,
                 tol_rot: float = 1e-6, time_budget: float | None = 1.0, max_restarts: int = 1000,
                 start_outside_limits: str = "project", options: Any = None, task: str = "pose", axis: str = "z",
                 collisions: Any = None, **solver_options: Any):
        if positional:
            raise TypeError("IK() takes the robot positionally and every setting by keyword: pass "
                            f"solver={positional[0]!r}")
        check_robot(robot)
        self.robot = robot
        kind = capabilities(solver)
        self.analytic = kind.closed_form
        self.route = route_of(kind, options is not None or bool(solver_options))  # of solve_all, as kinelab's
        if self.analytic:
            refuse_options(options or solver_options)
        self.request: Request = make_request(kind.request_solver(solver), None, tol_pos, tol_rot, time_budget,
                                             max_restarts, start_outside_limits, options, task, axis, solver_options)
        spec = as_collisions(collisions)
        self.collisions = None if spec is None else collision_model(robot, spec)
        self._nearest: NearestBranch | None = None
        self._lean = self._prepare()
        # the usual call's one compiled call (kinelab.core._engine), where the solver has one
        self.engine: Engine | None = None if self.collisions is not None or self.analytic else self._engine()

    def _engine(self) -> Engine | None:
        """The solver's one-call engine: compiled FRDM's (its lean call's), or what the solver module's ``engine``
        (where it has one) makes for this robot and request."""
        if self._lean is not None:
            return self._lean.engine
        make = getattr(self.request.module, "engine", None)
        return None if make is None else make(self.robot, self.request)

    def _prepare(self) -> LeanFRDM | None:
        """Everything a call would otherwise build first: the closed form's class (a chain without one refused
        here, by name), or the solver's model and, for compiled FRDM, the lean call."""
        robot, req = self.robot, self.request
        if self.analytic:
            arm_of(robot, req)
            if self.collisions is None:  # the usual call's one compiled call: branches found and judged together
                form = prepared_form(robot, req)
                self._nearest = None if form is None else NearestBranch(robot, req, form)
            return None
        prepare_solver(req.module, robot, req.options)
        return LeanFRDM(robot, req) if capabilities(req.solver).compiled and req.options.compiled else None

    def _request(self, seed: int | None) -> Request:
        if seed is None:
            return self.request
        check_seed(seed)
        return replace(self.request, seed=seed)

    def solve(self, target: Any, *, q0: Any = None, seed: int | None = None) -> IKResult:
        """IK for one target (oMtarget in the base frame), as :func:`kinelab.solve` with these settings.

        Args:
            target: oMtarget (a ``pin.SE3``; three numbers [m] for task "position").
            q0: the first start [rad or m] (None: a seeded random one).
            seed: seed of the random starts (None: fresh entropy).

        Returns:
            The result, judged on the task's components within the limits (by the FK ``result.judge`` names).

        Raises:
            TargetError, ConfigurationError, JointLimitError, OptionError: a bad target, start or seed.
        """
        if self.engine is not None:  # the usual call, in one compiled call (None: the driver's general route)
            res = self.engine.solve(target, q0, seed)
            return solve_one(self.robot, target, q0, self._request(seed)) if res is None else res
        if self.analytic:
            return self._nearest_branch(target, q0)
        if self.collisions is not None:
            return solve_clear(self.robot, target, q0, self._request(seed), self.collisions)
        res = None if self._lean is None else self._lean.solve(target, q0, seed)
        return solve_one(self.robot, target, q0, self._request(seed)) if res is None else res

    def _nearest_branch(self, target: Any, q0: Any) -> IKResult:
        """Solver "analytic": the branch nearest q0 in one compiled call where that serves, else root by root."""
        ref = None if q0 is None else self.robot.check_q(q0, what="q0")
        found = None if self._nearest is None else self._nearest.solve(target, ref)
        return found or analytic_one(self.robot, as_target(target, self.request.task.name), self.request, ref,
                                     self.collisions)

    def solve_batch(self, targets: Any, *, q0: Any = None, seed: int | None = None) -> BatchIKResult:
        """Every target of a batch, as :func:`kinelab.solve_batch` with these settings (row b: seed + b).

        Args:
            targets: a sequence of ``pin.SE3`` or an (B, 4, 4) array.
            q0: None, one start for every row, or (B, n) starts [rad or m].
            seed: the base seed (None: one is drawn and reported).

        Returns:
            The batch result, every row judged (by the FK its ``judge`` names).

        Raises:
            TargetError, ConfigurationError, OptionError: named.
        """
        req = replace(self._request(seed), start_outside_limits="refuse")
        t0 = time.perf_counter()
        if self.analytic:
            return nearest_batch(self.robot, targets, q0, self.request, self.collisions)
        res = run_batch(self.robot, targets, q0, req)
        if self.collisions is None:
            return res
        return clear_batch(self.robot, stack_homogeneous(*as_target_arrays(targets)), res, req, self.collisions, t0)

    def solve_all(self, target: Any, *, seed: int | None = None, q_ref: Any = None,
                  max_solutions: int | None = None, stop_below: float | None = UNSEEN) -> Branches:
        """The distinct branches of ``target`` found within the time budget, as :func:`kinelab.solve_all`.

        Args:
            target: oMtarget.
            seed: base seed of the starts.
            q_ref: sort the branches by distance to this configuration.
            max_solutions: stop at this many branches.
            stop_below: the stopping rule's threshold, as :func:`kinelab.solve_all` (None: the whole budget).

        Returns:
            One result per distinct branch.

        Raises:
            TargetError, ConfigurationError, OptionError: named.
        """
        found = find_all(self.robot, target, replace(self._request(seed), max_restarts=0), q_ref=q_ref,
                         max_solutions=max_solutions, stop_below=stop_below,
                         method=self.route)
        return found if self.collisions is None else mark_colliding(found, self.collisions, drop=False)


PREPARED_PER_ROBOT = 16  # a caller sweeping settings: the prepared solvers kept stay bounded


def prepared(robot: Robot, settings: dict[str, Any], key: tuple[Any, ...] | None = None) -> IK:
    """The robot's prepared solver for these settings (``IK``'s keywords), built once and kept on the robot under
    ``key`` (default: the settings sorted) while the same settings come back (a loop of :func:`kinelab.solve`
    calls); settings that cannot be a key (a dict of kicks, say) get a new one each call. Either way the call takes
    the prepared solver's route.

    Raises:
        TypeError, SolverNotFoundError, OptionError: as ``IK``.
    """
    check_robot(robot)
    key = tuple(sorted(settings.items())) if key is None else key
    try:
        hash(key)
    except TypeError:
        return IK(robot, **settings)
    kept: dict[tuple[Any, ...], IK] = robot.derived("prepared solvers", _new_table)
    ik = kept.get(key)
    if ik is None:
        ik = IK(robot, **settings)
        if len(kept) >= PREPARED_PER_ROBOT:
            kept.clear()
        kept[key] = ik
    return ik


def kept_solver(robot: Robot, key: tuple[Any, ...]) -> IK | None:
    """The prepared solver :func:`prepared` keeps on the robot under ``key``, or None (none yet, or a key that
    cannot be one)."""
    try:
        return robot.derived("prepared solvers", _new_table).get(key)
    except TypeError:
        return None


def _new_table(_: Robot) -> dict[tuple[Any, ...], IK]:
    return {}
