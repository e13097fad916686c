"""The prepared solver's lean call: compiled FRDM for one target with nothing checked twice.

:class:`kinelab.IK` checks its settings once; per call only the target and the start change. For the usual
call — a ``pin.SE3`` target, a float64 start of the right length (or none), an integer seed or none — on a robot
whose compiled FK is certified, one compiled call (:class:`kinelab.core._engine.FRDMEngine`) checks both (finite, a
proper rotation, the start within the limits, the target within the reach bound), runs the multistart and judges
the answer; the result is built directly, its diagnostics only when read. On a robot judged by Pinocchio's FK the
same steps run as three compiled calls with Pinocchio's verdict between them. Anything else (a point target, a
list start, a start outside the limits, a target beyond reach) returns None and the caller takes the general
driver, which names the problem, warns or answers UNREACHABLE exactly as :func:`kinelab.solve` does: the lean call
changes the cost, never the answer.
"""

from __future__ import annotations

import os
import time
from types import SimpleNamespace
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.core._engine import FRDMEngine
from kinelab.ik.driver import Call, compiled_result
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm import solver as frdm
from kinelab.ik.limits import turned_verdict
from kinelab.ik.request import Request, verdict_reserve
from kinelab.ik.result import IKResult, Status
from kinelab.ik.verdict import usual_inputs
from kinelab.ik.workspace import reach_bound
from kinelab.robot import Robot
from kinelab.robot.model import _compiled_judge

SEED_LIMIT = 1 << 64
OK = 0  # usual_inputs: the call is the usual one


class LeanFRDM:
    """The lean call of a prepared compiled-FRDM solver (see the module's docstring).

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
            anchor=self.anchor, radius=self.radius, pstar=ctx.pstar, Rstar=ctx.Rstar, order=ctx.order, cap=ctx.cap,
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
