"""One FRDM solve (an attempt with the monitor and bypasses), and the compiled multistart.

:func:`attempt` runs the monitored Python loop of :mod:`kinelab.ik.frdm.monitor`; :func:`multistart`
runs attempts and seeded restarts inside the compiled kernel when the options name no bypass, policy,
polish or trace (``FRDMOptions.compiled``). Both return before kinelab's Pinocchio check, which
:func:`kinelab.solve` applies.
"""

from __future__ import annotations

import functools
import time
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.ik import dls
from kinelab.ik import multistart as restarts
from kinelab.ik.chain import ChainModel, chain_model
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm.kernel import no_rest
from kinelab.ik.frdm.monitor import Bypass, Problem, Runner
from kinelab.ik.frdm.options import ORDERS, FRDMOptions
from kinelab.ik.multistart import TypedKernel, clock_chunk
from kinelab.ik.result import Attempt, SingularEvent, Status
from kinelab.robot import Robot

Options = FRDMOptions
_MULTISTART = TypedKernel(kernel.multistart)
# joint steps between two looks at the clock (≈ 0.2 ms of work at 0.07 µs per joint step): a budget is then
# overrun by about that much whatever the chain's length
JOINT_SWEEPS_PER_LOOK = 2048


def prepare(robot: Robot) -> None:
    """Build the chain model and compile (or load) both kernels: done before a solve's clock starts."""
    chain_model(robot)
    if not _COMPILED:
        target = pin.SE3.Identity()
        attempt(robot, target, robot.neutral(), 1e-6, 1e-6, np.inf, max_sweeps=2, policy=())
        multistart(robot, target, robot.neutral(), 1e-6, 1e-6, np.inf, 0, 0)
        _COMPILED.append(True)


_COMPILED: list[bool] = []  # one compilation per process, whatever the robot


def attempt(robot: Robot, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float, deadline: float,
            options: FRDMOptions | None = None, **kwargs: Any) -> Attempt:
    """One FRDM run from ``q0`` with the singularity monitor and the bypass policy.

    Args:
        robot: the robot.
        oMtarget: the wanted tool pose in the base frame.
        q0: start, one number per joint [rad or m].
        tol_pos: position tolerance [m]; tol_rot: rotation tolerance [rad].
        deadline: ``time.perf_counter()`` value after which the attempt stops.
        options: an :class:`FRDMOptions`, or its fields as keyword arguments.

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
    prob = Problem(cm, oMtarget, opts, tol_pos, tol_rot)
    run = Runner(robot, cm, prob, opts)
    q = np.array(q0, dtype=float)
    for step in bypass.active:
        q = run.apply(bypass, step, q)
    status = run.solve(q, deadline, bypass, opts.max_bypass_events)
    info = {"mode": "frdm" + (" (plain)" if opts.plain else ""), "sweeps": run.sweeps,
            "accelerated_sweeps": run.accepted, "order": opts.order, "w_p": prob.w_p, "relax": opts.relax,
            "objective": run.E}
    if opts.trace:
        info["trace"] = run.trace_values()
    att = Attempt(robot.wrap_continuous(run.q), status, run.sweeps, run.events, run.bypass_log, info)
    if opts.polish and status != Status.CONVERGED:
        pol = dls.attempt(robot, oMtarget, run.q, tol_pos, tol_rot, deadline, max_iterations=20)
        att = Attempt(pol.q, pol.status, run.sweeps + pol.iterations, run.events, run.bypass_log,
                      {**info, "mode": "frdm+polish", "polish_iterations": pol.iterations})
    return att


def multistart(robot: Robot, oMtarget: pin.SE3, q0: np.ndarray | None, tol_pos: float, tol_rot: float, deadline: float,
               seed: int | None, max_restarts: int, options: FRDMOptions | None = None) -> tuple[Attempt, int]:
    """FRDM from q0 and then from seeded random starts, all inside the compiled kernel.

    A stall is answered by a restart: with no bypass configured that is what the monitor's policy does
    for a local minimum. ``q0`` None: the first start is drawn from the seeded generator too (as
    :func:`kinelab.solve_batch` does). Returns the attempt kept and the number of restarts; the caller checks the
    answer with Pinocchio.
    """
    opts = options or FRDMOptions()
    cm = chain_model(robot)
    prob = _compiled_problem(cm, oMtarget, opts, tol_pos, tol_rot)
    rng_state = restarts.seed_state(seed)
    q = restarts.first_start(q0, cm.kind, cm.lower, cm.upper, rng_state)
    best_q = q.copy()
    stats = np.zeros(kernel.STATS_SIZE)
    settings = opts.settings()
    order = ORDERS[opts.order]
    chunk_sweeps = clock_chunk(JOINT_SWEEPS_PER_LOOK, cm.n)

    def chunk(attempts_left: int) -> int:
        return _MULTISTART(q, cm.chain, prob, settings, order, opts.sweep_cap, rng_state, attempts_left,
                           float(stats[kernel.T_SWEEPS] + chunk_sweeps), best_q, stats)

    code = restarts.run_in_chunks(chunk, max_restarts + 1, stats, deadline, kernel.CONVERGED)
    if code == kernel.CONVERGED:
        status = Status.CONVERGED
    elif time.perf_counter() > deadline:
        status = Status.TIME_BUDGET
    else:
        status = Status.STALLED if stats[kernel.T_STALLS] > 0 else Status.MAX_ITERATIONS
    stalls = int(stats[kernel.T_STALLS])
    info = {"mode": "frdm" + (" (plain)" if opts.plain else ""), "sweeps": int(stats[kernel.T_SWEEPS]),
            "accelerated_sweeps": int(stats[kernel.T_ACCEPTED]), "order": opts.order, "w_p": prob.w_p,
            "objective": float(stats[kernel.T_BEST_E]), "attempts": int(stats[kernel.T_ATTEMPTS]),
            "stalls": stalls, "path": "compiled"}
    events = [SingularEvent("stall", "not diagnosed (compiled multistart: restarted)", count=stalls)] if stalls else []
    attempts = int(stats[kernel.T_ATTEMPTS])
    return Attempt(robot.wrap_continuous(best_q), status, int(stats[kernel.T_SWEEPS]), events, [], info), \
        max(0, attempts - 1)


def _compiled_problem(cm: ChainModel, oMtarget: pin.SE3, opts: FRDMOptions, tol_pos: float,
                      tol_rot: float) -> kernel.Problem:
    """The kernel's problem for the multistart: no bypass ever changes its windows, so the chain's own
    limit arrays and one shared all-free mask serve (no copies: the per-call cost is what a loop pays)."""
    if opts.use_limits:
        lower, upper = cm.lower, cm.upper
    else:
        lower, upper = _unbounded(cm.n), _unbounded(cm.n, 1.0)
    return kernel.Problem(lower, upper, _all_free(cm.n), oMtarget.translation, np.ascontiguousarray(oMtarget.rotation),
                          opts.position_weight(cm.length), opts.axis_weights(), float(tol_pos), float(tol_rot),
                          opts.mode != "orientation", opts.mode != "position",
                          no_rest(cm.n), 0.0)


@functools.cache
def _all_free(n: int) -> np.ndarray:
    """Shared by every compiled solve; the kernel never writes it."""
    return np.ones(n, dtype=np.bool_)


@functools.cache
def _unbounded(n: int, sign: float = -1.0) -> np.ndarray:
    return np.full(n, sign * np.inf)
