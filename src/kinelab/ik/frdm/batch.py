"""FRDM on a batch of targets: one compiled call, the targets spread over the cores (OpenMP threads).

Target b is solved exactly as :func:`kinelab.solve` solves it alone with ``seed = seed + b`` and the
same start: its own generator state, the same restarts, and the same chunks of sweeps (the points at
which the single solve looks at the clock), so the answer does not depend on the thread count or on
the other targets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinelab.core import _frdm, threads
from kinelab.geometry import wrap_to_pi
from kinelab.ik.chain import CONTINUOUS, chain_model
from kinelab.ik.codes import NOT_STARTED, STOPPED
from kinelab.ik.frdm import solver
from kinelab.ik.frdm.kernel import CONVERGED, STATS_SIZE, T_ATTEMPTS, T_STALLS, T_SWEEPS, Objective, no_rest
from kinelab.ik.frdm.options import ORDERS, FRDMOptions
from kinelab.ik.multistart import clock_chunk, first_start
from kinelab.ik.result import Status
from kinelab.robot import Chain


@dataclass
class Rows:
    """Raw batch answers before Pinocchio's verdict: q (B, n), :class:`Status` codes, iterations, restarts."""

    Q: np.ndarray
    code: np.ndarray
    iterations: np.ndarray
    restarts: np.ndarray

    @classmethod
    def unsolved(cls, count: int, n: int) -> Rows:
        """Rows not reached by the budget: NaN q, status time_budget."""
        return cls(np.full((count, n), np.nan), np.full(count, Status.TIME_BUDGET.code, dtype=np.int8),
                   np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64))


def run(robot: Chain, points: np.ndarray, rotations: np.ndarray, starts: np.ndarray | None, rng_states: np.ndarray,
        attempts: np.ndarray, tol_pos: float, tol_rot: float, deadline: float, opts: FRDMOptions) -> Rows:
    """Solve every row in one parallel compiled call; each row looks at the clock between its chunks of sweeps (the
    points at which the single solve looks at it) and stops once the deadline has passed.

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
    Q = np.zeros((count, cm.n)) if starts is None else np.array(starts, dtype=float, order="C")
    if starts is None and not opts.use_limits:  # drawn within the file's limits, as the single solve draws them
        for b in range(count):
            Q[b] = first_start(None, cm.kind, cm.lower, cm.upper, rng_states[b])
        starts = Q
    codes, stats = np.zeros(count, dtype=np.int64), np.zeros((count, STATS_SIZE))
    lower, upper = (cm.lower, cm.upper) if opts.use_limits else (np.full(cm.n, -np.inf), np.full(cm.n, np.inf))
    shared = Objective(lower, upper, np.ones(cm.n, dtype=np.bool_), np.zeros(3), np.eye(3),
                       opts.position_weight(cm.length), opts.axis_weights(), float(tol_pos), float(tol_rot),
                       opts.mode != "orientation", opts.mode != "position", no_rest(cm.n), 0.0, opts.rot_axis)
    _frdm.solve_rows(Q, starts is None, cm.chain, shared, np.ascontiguousarray(points, dtype=float),
                     np.ascontiguousarray(rotations, dtype=float), opts.settings(), ORDERS[opts.order], opts.sweep_cap,
                     np.ascontiguousarray(rng_states, dtype=np.uint64), np.ascontiguousarray(attempts, dtype=np.int64),
                     float(clock_chunk(solver.JOINT_SWEEPS_PER_LOOK, cm.n)),
                     float(clock_chunk(solver.JOINT_SWEEPS_PER_LATER_LOOK, cm.n)), float(deadline), codes, stats,
                     threads.count())
    started = codes != NOT_STARTED
    rows.Q[started] = Q[started]
    rows.code[started] = np.where(codes[started] == CONVERGED, Status.CONVERGED.code,
                                  np.where(codes[started] == STOPPED, Status.TIME_BUDGET.code,
                                           np.where(stats[started, T_STALLS] > 0, Status.STALLED.code,
                                                    Status.MAX_ITERATIONS.code)))
    rows.iterations[:] = stats[:, T_SWEEPS]
    rows.restarts[:] = np.maximum(0, stats[:, T_ATTEMPTS] - 1)
    continuous = cm.kind == CONTINUOUS
    if continuous.any():
        rows.Q[:, continuous] = wrap_to_pi(rows.Q[:, continuous])
    return rows
