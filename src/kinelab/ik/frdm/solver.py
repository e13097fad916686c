"""One FRDM solve (an attempt with the monitor and bypasses), and the compiled multistart.

:func:`attempt` runs the monitored Python loop of :mod:`kinelab.ik.frdm.monitor`; :func:`multistart`
runs attempts and seeded restarts inside the compiled kernel when the options name no bypass, policy,
polish or trace (``FRDMOptions.compiled``). Both return before kinelab's Pinocchio check, which
:func:`kinelab.solve` applies.
"""

from __future__ import annotations

import functools
import time
from dataclasses import replace

import numpy as np
import pinocchio as pin

from kinelab.core import _frdm
from kinelab.core._engine import FRDMEngine
from kinelab.core.spec import FRDMSpec
from kinelab.ik import dls
from kinelab.ik import multistart as restarts
from kinelab.ik.chain import CONTINUOUS, ChainModel, chain_model
from kinelab.ik.driver import engine_judge, engine_spec
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm.kernel import no_rest
from kinelab.ik.frdm.monitor import Bypass, Goal, Runner
from kinelab.ik.frdm.options import ORDERS, FRDMOptions
from kinelab.ik.multistart import clock_chunk
from kinelab.ik.request import Request
from kinelab.ik.result import Attempt, FRDMDiagnostics, SingularEvent, Status
from kinelab.robot import Chain

Options = FRDMOptions
# joint steps before the first look at the clock (most solves end within them: one kernel call), and then
# between two looks (≈ 0.03 ms of work: a budget is overrun by about that much whatever the chain's length)
JOINT_SWEEPS_PER_LOOK = 256
JOINT_SWEEPS_PER_LATER_LOOK = 64


def prepare(robot: Chain, options: FRDMOptions | None = None) -> None:
    """Build the chain model before a solve's clock starts (the kernels are compiled at install).

    Args:
        robot: the robot.
        options: the options of the solves to come (unused: every option runs compiled code built ahead).
    """
    chain_model(robot)


def attempt(robot: Chain, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float, deadline: float,
            options: FRDMOptions | None = None, **kwargs: object) -> Attempt:
    """One FRDM run from ``q0`` with the singularity monitor and the bypass policy.

    Args:
        robot: the robot.
        oMtarget: the wanted tool pose in the base frame.
        q0: start, one number per joint [rad or m].
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        deadline: ``time.perf_counter()`` value after which the attempt stops.
        options: an :class:`FRDMOptions`.
        kwargs: or its fields as keyword arguments.

    Returns:
        The attempt, before kinelab's Pinocchio check.

    Raises:
        OptionError: an option outside what it accepts; JointNotFoundError: a bypass names an unknown joint.
    """
    opts = FRDMOptions.of(options, **kwargs)
    bypass = Bypass(opts.kicks or {}, opts.intervals or {}, opts.freeze or {}, opts.policy, opts.active or ())
    if not opts.compiled:
        bypass.validate(robot)
    cm = chain_model(robot)
    prob = Goal(cm, oMtarget, opts, tol_pos, tol_rot)
    run = Runner(robot, cm, prob, opts)
    q = np.array(q0, dtype=float)
    for step in bypass.active:
        q = run.apply(bypass, step, q)
    status = run.solve(q, deadline, bypass, opts.max_bypass_events)
    diag = FRDMDiagnostics(sweeps=run.sweeps, accelerated_sweeps=run.accepted, order=opts.order, w_p=prob.w_p,
                       relax=opts.relax, objective=run.E, newton_steps=run.newton_steps,
                       trace=tuple(run.trace_values()) if opts.trace else None)
    att = Attempt(robot.wrap_continuous(run.q), status, run.sweeps, run.events, run.bypass_log, diag,
                  opts.label)
    if opts.polish and status != Status.CONVERGED:
        pol = dls.attempt(robot, oMtarget, run.q, tol_pos, tol_rot, deadline, max_iterations=20)
        att = Attempt(pol.q, pol.status, run.sweeps + pol.iterations, run.events, run.bypass_log,
                      replace(diag, polish_iterations=pol.iterations), "frdm+polish")
    return att


def multistart(robot: Chain, oMtarget: pin.SE3, q0: np.ndarray | None, tol_pos: float, tol_rot: float, deadline: float,
               seed: int | None, max_restarts: int, options: FRDMOptions | None = None) -> tuple[Attempt, int]:
    """FRDM from q0 and then from seeded random starts, all inside the compiled kernel.

    A stall is answered by a restart: with no bypass configured that is what the monitor's policy does
    for a local minimum. ``q0`` None: the first start is drawn from the seeded generator too (as
    :func:`kinelab.solve_batch` does). Returns the attempt kept and the number of restarts; the caller
    checks the answer with Pinocchio.
    """
    opts = options or FRDMOptions()
    ctx = _context(robot, opts, float(tol_pos), float(tol_rot))
    code, q, stats = ctx.run(oMtarget.homogeneous, q0, seed, max_restarts + 1, deadline)
    return ctx.attempt(code, q, stats, deadline), max(0, int(stats[kernel.T_ATTEMPTS]) - 1)


def engine(robot: Chain, req: Request) -> FRDMEngine | None:
    """The prepared solver's one-call engine (:class:`kinelab.core._engine.FRDMEngine`): the compiled multistart,
    judged by the robot's certified compiled FK, the result filled in C. It owns its context (the kernel's problem,
    settings and memory). None where the general route must serve: options the compiled multistart does not run
    (a bypass, a policy, polish, a trace), a robot judged by Pinocchio's FK.

    Args:
        robot: the robot.
        req: the prepared solver's request (solver "frdm").
    """
    opts, judge = req.options, engine_judge(robot, req.options)
    if judge is None:
        return None
    ctx = _Context(robot, opts, float(req.tol_pos), float(req.tol_rot))
    spec = engine_spec(robot, req, ctx.cm, ctx.attempt, ctx.mode, ctx.diagnostics_of, FRDMSpec, wrap_continuous=True,
                       pstar=ctx.pstar, Rstar=ctx.Rstar, order=ctx.order, cap=ctx.cap, first_chunk=ctx.chunk,
                       later_chunk=ctx.later_chunk, stall_events=ctx.stall_events)
    return FRDMEngine(ctx.packed, judge, spec)


class _Context:
    """Everything a compiled FRDM solve on one robot with one set of options and tolerances passes to the
    kernel, built once: per call only the target (copied into the problem's own arrays), the start, the
    seed and the budget change. Not for concurrent solves on one Chain (its Pinocchio data is shared too)."""

    def __init__(self, robot: Chain, opts: FRDMOptions, tol_pos: float, tol_rot: float):
        cm = chain_model(robot)
        self.robot, self.order_name = robot, opts.order
        self.cm, self.n, self.continuous = cm, cm.n, bool((cm.kind == CONTINUOUS).any())
        self.problem = _compiled_problem(cm, pin.SE3.Identity(), opts, tol_pos, tol_rot)
        self.pstar, self.Rstar = self.problem.pstar, self.problem.Rstar
        self.settings, self.order, self.cap = opts.settings(), ORDERS[opts.order], opts.sweep_cap
        self.chunk = float(clock_chunk(JOINT_SWEEPS_PER_LOOK, cm.n))
        self.later_chunk = float(clock_chunk(JOINT_SWEEPS_PER_LATER_LOOK, cm.n))
        self.mode = opts.label
        self.memory = kernel.new_memory(cm.n, opts.accel_m)  # reused: every attempt resets what it reads
        self.packed = _frdm.Packed(cm.chain, self.problem, self.settings, self.memory)
        self.seed: int | None = None
        self.seed_value = np.zeros(1, dtype=np.uint64)  # the generator state of ``self.seed``

    def run(self, H: np.ndarray, q0: np.ndarray | None, seed: int | None, attempts: int,
            deadline: float) -> tuple[int, np.ndarray, np.ndarray]:
        """(code, kept q (a new array), stats) of attempts towards the target H (oMtarget as a 4 × 4 matrix)
        from q0 (None: drawn) and seeded restarts."""
        self.pstar[:] = H[:3, 3]
        self.Rstar[:] = H[:3, :3]
        return self.run_aimed(q0, seed, attempts, deadline)

    def run_aimed(self, q0: np.ndarray | None, seed: int | None, attempts: int,
                  deadline: float) -> tuple[int, np.ndarray, np.ndarray]:
        """:meth:`run` with the target already in ``pstar`` and ``Rstar``."""
        if seed is None or seed != self.seed:  # a loop usually passes one seed: its state is made once
            self.seed_value = restarts.seed_state(seed)
            self.seed = seed
        rng_state = self.seed_value.copy()
        cm = self.cm
        q = restarts.first_start(q0, cm.kind, cm.lower, cm.upper, rng_state)
        best_q = q.copy()
        stats = np.zeros(kernel.STATS_SIZE)
        code = self.packed.solve(q, self.order, self.cap, rng_state, attempts, self.chunk, self.later_chunk, deadline,
                                 best_q, stats)
        return code, best_q, stats

    def attempt(self, code: int, q: np.ndarray, stats: np.ndarray, deadline: float) -> Attempt:
        """The :class:`Attempt` of a :meth:`run` (status, diagnostics, q with continuous joints wrapped)."""
        if code == kernel.CONVERGED:
            status = Status.CONVERGED
        elif time.perf_counter() > deadline:
            status = Status.TIME_BUDGET
        else:
            status = Status.STALLED if stats[kernel.T_STALLS] > 0 else Status.MAX_ITERATIONS
        st = stats.tolist()  # one conversion, then Python floats
        sweeps, stalls = int(st[kernel.T_SWEEPS]), int(st[kernel.T_STALLS])
        diag = self.diagnostics(st)
        return Attempt(self.robot.wrap_continuous(q) if self.continuous else q, status, sweeps,
                       self.stall_events(stalls) if stalls else [], [], diag, self.mode)

    def diagnostics(self, st: list[float]) -> FRDMDiagnostics:
        """The diagnostics of a run from its statistics (``stats.tolist()``: slots T_*)."""
        return FRDMDiagnostics.quick(sweeps=int(st[kernel.T_SWEEPS]), accelerated_sweeps=int(st[kernel.T_ACCEPTED]),
                                 order=self.order_name, w_p=self.problem.w_p, objective=st[kernel.T_BEST_E],
                                 attempts=int(st[kernel.T_ATTEMPTS]), stalls=int(st[kernel.T_STALLS]),
                                 polished=int(st[kernel.T_POLISHED]), newton_steps=int(st[kernel.T_NEWTON]),
                                 path="compiled")

    def diagnostics_of(self, stats: np.ndarray) -> FRDMDiagnostics:
        """:meth:`diagnostics` from the statistics array."""
        return self.diagnostics(stats.tolist())

    @staticmethod
    def stall_events(stalls: int) -> list[SingularEvent]:
        """The one event a compiled multistart reports: how many attempts stalled (each was restarted)."""
        return [SingularEvent("stall", "not diagnosed (compiled multistart: restarted)", count=stalls)]


def _context(robot: Chain, opts: FRDMOptions, tol_pos: float, tol_rot: float) -> _Context:
    """The robot's context for these options and tolerances (kept on the Chain, a few per robot)."""
    last = _LAST
    if last and last[0] is robot and last[1] is opts and last[2] == tol_pos and last[3] == tol_rot:
        return last[4]
    contexts: dict = robot.derived("frdm_contexts", _new_dict)
    key = (opts, tol_pos, tol_rot)
    ctx = contexts.get(key)
    if ctx is None:
        if len(contexts) >= 16:  # a caller sweeping tolerances: keep the memory bounded
            contexts.clear()
        ctx = contexts[key] = _Context(robot, opts, tol_pos, tol_rot)
    _LAST[:] = [robot, opts, tol_pos, tol_rot, ctx]
    return ctx


_LAST: list = []  # the context of the last call (a loop asks for the same one every time)


def _new_dict(_: Chain) -> dict:
    return {}


def _compiled_problem(cm: ChainModel, oMtarget: pin.SE3, opts: FRDMOptions, tol_pos: float,
                      tol_rot: float) -> kernel.Objective:
    """The kernel's problem for the multistart: no bypass ever changes its windows, so the chain's own
    limit arrays and one shared all-free mask serve (no copies: the per-call cost is what a loop pays)."""
    if opts.use_limits:
        lower, upper = cm.lower, cm.upper
    else:
        lower, upper = _unbounded(cm.n), _unbounded(cm.n, 1.0)
    return kernel.Objective(lower, upper, _all_free(cm.n), np.array(oMtarget.translation),
                          np.array(oMtarget.rotation, order="C"),
                          opts.position_weight(cm.length), opts.axis_weights(), float(tol_pos), float(tol_rot),
                          opts.mode != "orientation", opts.mode != "position",
                          no_rest(cm.n), 0.0, opts.rot_axis)


@functools.cache
def _all_free(n: int) -> np.ndarray:
    """Shared by every compiled solve; the kernel never writes it."""
    return np.ones(n, dtype=np.bool_)


@functools.cache
def _unbounded(n: int, sign: float = -1.0) -> np.ndarray:
    return np.full(n, sign * np.inf)
