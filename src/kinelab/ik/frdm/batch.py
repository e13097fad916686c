"""FRDM on a batch of targets: one compiled call, the targets spread over every core (numba ``prange``).

Target b is solved exactly as :func:`kinelab.solve` solves it alone with ``seed = seed + b`` and the
same start: its own generator state, the same restarts, and the same chunks of sweeps (the points at
which the single solve looks at the clock), so the answer does not depend on the thread count or on
the other targets.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from kinelab.geometry import wrap_to_pi
from kinelab.ik.chain import CONTINUOUS, chain_model, random_configuration
from kinelab.ik.compiling import announce
from kinelab.ik.frdm import solver
from kinelab.ik.frdm.attempts import multistart
from kinelab.ik.frdm.kernel import (
    CONVERGED,
    STATE_SIZE,
    STATS_SIZE,
    T_ATTEMPTS,
    T_STALLS,
    T_SWEEPS,
    Memory,
    Objective,
)
from kinelab.ik.frdm.options import ORDERS, FRDMOptions
from kinelab.ik.multistart import clock_chunk, first_start
from kinelab.ik.result import Status
from kinelab.robot import Robot

NOT_STARTED, STOPPED = -2, -3  # a row's code when the budget ran out before it started, or while it ran


@dataclass
class Rows:
    """Raw batch answers before Pinocchio's verdict: q (B, n), status strings, iterations, restarts."""

    Q: np.ndarray
    status: np.ndarray
    iterations: np.ndarray
    restarts: np.ndarray

    @classmethod
    def unsolved(cls, count: int, n: int) -> Rows:
        """Rows not reached by the budget: NaN q, status time_budget."""
        return cls(np.full((count, n), np.nan), np.full(count, Status.TIME_BUDGET.value, dtype="<U14"),
                   np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64))


def prepare(robot: Robot) -> None:
    """Compile (or load) the batch kernel: outside the batch's clock, announced when it compiles."""
    chain_model(robot)
    if not _COMPILED:
        announce("the FRDM batch", [solve_rows])
        one = np.ones(1, dtype=np.int64)
        run(robot, np.zeros((1, 3)), np.eye(3)[None], None, np.ones((1, 1), dtype=np.uint64), one, 1e-6, 1e-6,
            np.inf, FRDMOptions())
        _COMPILED.append(True)


_COMPILED: list[bool] = []


def run(robot: Robot, points: np.ndarray, rotations: np.ndarray, starts: np.ndarray | None, rng_states: np.ndarray,
        attempts: np.ndarray, tol_pos: float, tol_rot: float, deadline: float, opts: FRDMOptions) -> Rows:
    """Solve every row in one parallel kernel call; with a deadline, a timer stops the rows at it (each row looks
    between its chunks of sweeps, the points at which the single solve looks at the clock).

    Args:
        robot: the robot.
        points: (B, 3) target points [m] (base frame).
        rotations: (B, 3, 3) target rotations.
        starts: (B, n) starts, or None (each row draws its start from its generator).
        rng_states: (B, 1) generator states.
        attempts: (B,) attempts per row.
        tol_pos: [m].
        tol_rot: [rad].
        deadline: a ``time.perf_counter()`` value.
        opts: compiled FRDM options.

    Returns:
        Rows with the kernel's status (converged, stalled, max_iterations; time_budget for a row the deadline
        stopped, with its best answer so far, and for one it reached before the row started, with NaN).
    """
    cm = chain_model(robot)
    count = points.shape[0]
    rows = Rows.unsolved(count, cm.n)
    Q = np.zeros((count, cm.n)) if starts is None else np.array(starts, dtype=float)
    if starts is None and not opts.use_limits:  # drawn within the file's limits, as the single solve draws them
        for b in range(count):
            Q[b] = first_start(None, cm.kind, cm.lower, cm.upper, rng_states[b])
        starts = Q
    codes, stats = np.zeros(count, dtype=np.int64), np.zeros((count, STATS_SIZE))
    lower, upper = (cm.lower, cm.upper) if opts.use_limits else (np.full(cm.n, -np.inf), np.full(cm.n, np.inf))
    stop = np.zeros(1, dtype=np.int64)  # set by a timer thread at the deadline; every row looks between chunks
    timer = None if deadline == np.inf else threading.Timer(max(0.0, deadline - time.perf_counter()),
                                                             stop.fill, (1,))
    if timer is not None:
        timer.daemon = True
        timer.start()
    try:
        solve_rows(Q, starts is None, cm.chain, lower, upper, np.ones(cm.n, dtype=np.bool_), points, rotations,
                   opts.position_weight(cm.length), opts.axis_weights(), float(tol_pos), float(tol_rot),
                   opts.mode != "orientation", opts.mode != "position", opts.rot_axis, opts.settings(),
                   ORDERS[opts.order], opts.sweep_cap, rng_states, attempts,
                   float(clock_chunk(solver.JOINT_SWEEPS_PER_LOOK, cm.n)),
                   float(clock_chunk(solver.JOINT_SWEEPS_PER_LATER_LOOK, cm.n)), codes, stats, stop)
    finally:
        if timer is not None:
            timer.cancel()
    started = codes != NOT_STARTED
    rows.Q[started] = Q[started]
    rows.status[started] = np.where(codes[started] == CONVERGED, Status.CONVERGED.value,
                                    np.where(codes[started] == STOPPED, Status.TIME_BUDGET.value,
                                             np.where(stats[started, T_STALLS] > 0, Status.STALLED.value,
                                                      Status.MAX_ITERATIONS.value)))
    rows.iterations[:] = stats[:, T_SWEEPS]
    rows.restarts[:] = np.maximum(0, stats[:, T_ATTEMPTS] - 1)
    continuous = cm.kind == CONTINUOUS
    if continuous.any():
        rows.Q[:, continuous] = wrap_to_pi(rows.Q[:, continuous])
    return rows


@njit(cache=True)
def chunked(q, ch, pb, st, order, max_sweeps, rng_state, attempts, chunk_sweeps, later_sweeps, best_q, stats, mem,
            stop):
    """The kernel's multistart in chunks of ``chunk_sweeps`` sweeps, then ``later_sweeps``, as the timed single
    solve runs it (:func:`kinelab.ik.multistart.run_in_chunks`), looking at ``stop[0]`` (set at the deadline)
    where the single solve looks at the clock. Returns the last code (NOT_STARTED, STOPPED at the deadline)."""
    code = -1
    chunk = chunk_sweeps
    while attempts > 0:
        if stop[0] != 0:
            return STOPPED if stats[T_ATTEMPTS] > 0 else NOT_STARTED
        before = stats[T_ATTEMPTS]
        code = multistart(q, ch, pb, st, order, max_sweeps, rng_state, attempts, stats[T_SWEEPS] + chunk,
                          best_q, stats, mem)
        chunk = later_sweeps
        attempts -= int(stats[T_ATTEMPTS] - before)
        if code == CONVERGED:
            break
    return code


@njit(cache=True, parallel=True, nogil=True)  # nogil: the deadline timer thread must run meanwhile
def solve_rows(Q, draw_start, ch, lower, upper, free, pstars, Rstars, w_p, w_ax, tol_pos, tol_rot, check_pos,
               check_rot, rot_axis, st, order, max_sweeps, rng_states, attempts, chunk_sweeps, later_sweeps, codes,
               stats, stop):
    """Solve rows [0, B) in parallel; row b's start is Q[b] (drawn from its generator when draw_start).

    Inputs, in order:
        Q (np.ndarray): (B, n) starts; on return the answers [rad or m].
        draw_start (bool): draw every start from its row's generator (the single solve's ``q0=None``).
        ch, lower, upper, free: the chain, its windows and free mask (shared).
        pstars (np.ndarray): (B, 3) target points [m]; Rstars: (B, 3, 3) target rotations.
        w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot, rot_axis, st, order, max_sweeps: as the single solve.
        rng_states (np.ndarray): (B, 1) uint64 generator state per row.
        attempts (np.ndarray): (B,) attempts allowed per row (1 for a target proved out of reach).
        chunk_sweeps, later_sweeps (float): sweeps of the first chunk and of the later ones (the single solve's).
        codes (np.ndarray): (B,) run() code per row; stats: (B, STATS_SIZE) the slots T_* per row.
        stop (np.ndarray): (1,) int64, non-zero once the deadline has passed (written by another thread).
    """
    n = Q.shape[1]
    rest = np.zeros(n)
    for b in prange(Q.shape[0]):
        q = Q[b].copy()
        if draw_start:
            random_configuration(q, ch.kind, lower, upper, rng_states[b])
        pb = Objective(lower, upper, free, pstars[b], Rstars[b], w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
                     rest, 0.0, rot_axis)
        best_q = q.copy()
        row_stats = np.zeros(STATS_SIZE)
        mem = Memory(np.zeros((st.accel_m + 1, n)), np.zeros((st.accel_m + 1, n)), np.zeros(STATE_SIZE), np.zeros(0),
                     np.zeros((2 * n + 4, 3)))
        codes[b] = chunked(q, ch, pb, st, order, max_sweeps, rng_states[b], attempts[b], chunk_sweeps, later_sweeps,
                           best_q, row_stats, mem, stop)
        Q[b] = best_q
        stats[b] = row_stats
