"""The compiled multistart: FRDM attempts from a start and then from seeded random ones, and the damped
Gauss–Newton (Levenberg–Marquardt) steps that finish an attempt FRDM leaves short of the tolerances.

FRDM's sweeps are coordinate descent: near a singular configuration, or on a task that leaves the arm
redundant (task "axis" on a 6-joint arm), their rate tends to 1 and an attempt stalls a little short of
1e-6 (5e-4 m on a Stanford target with the boom nearly retracted). A few Gauss–Newton steps from there
converge where a restart would start over: ``FRDMOptions.stall_polish`` steps are tried on each stalled
attempt before the restart (0: the paper's FRDM alone), counted in ``diagnostics.polished``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.chain import PRISMATIC, chain_fk, random_configuration
from kinelab.ik.frdm.kernel import (
    BASE_TO_TIP,
    BUDGET,
    CONVERGED,
    MIXED,
    S_ACCEPTED,
    S_E,
    S_SWEEPS,
    STALL_STEP,
    STALL_WINDOW,
    T_ACCEPTED,
    T_ATTEMPTS,
    T_BEST_E,
    T_CUT,
    T_POLISHED,
    T_STALLS,
    T_SWEEPS,
    TIP_TO_BASE,
    _within,
    run,
    total_objective,
)


@njit(cache=True)
def multistart(q, ch, pb, st, order, max_sweeps, rng_state, max_attempts, sweep_budget, best_q, stats, mem):
    """Attempts from q, then from seeded uniform starts, until one converges, ``max_attempts`` have run or
    ``sweep_budget`` sweeps (a total) are spent. A stall ends an attempt (a restart, not a bypass).

    Called in chunks: an attempt the sweep budget cuts is resumed by the next call from where it stopped, its
    Anderson history and monitor state kept in ``mem`` (stats[T_CUT] = 1 meanwhile), so the answer does not
    depend on where the chunks end. On return q holds the converged configuration (or the current one),
    best_q the lowest-objective one; stats has the slots T_*. Returns a run() code.
    """
    best = stats[T_BEST_E] if stats[T_ATTEMPTS] > 0.0 or stats[T_CUT] != 0.0 else np.inf
    code = BUDGET
    done = 0
    while done < max_attempts:
        if stats[T_CUT] == 0.0:
            if stats[T_ATTEMPTS] > 0.0:
                random_configuration(q, ch.kind, pb.lower, pb.upper, rng_state)
            mem.state[:] = 0.0
        stats[T_CUT] = 0.0
        left = max_sweeps - int(mem.state[S_SWEEPS])
        budget = min(left, int(sweep_budget - stats[T_SWEEPS]))
        attempt_order = order
        if order == MIXED:  # base → tip on the first attempt and every other restart, tip → base between
            attempt_order = BASE_TO_TIP if int(stats[T_ATTEMPTS]) % 2 == 0 else TIP_TO_BASE
        code, s = run(q, ch, pb, st, attempt_order, budget, mem)
        stats[T_SWEEPS] += s
        if code == BUDGET and budget < left:  # cut by the chunk: the next call resumes this attempt
            stats[T_CUT] = 1.0
            stats[T_BEST_E] = best
            return BUDGET
        stats[T_ATTEMPTS] += 1.0
        done += 1
        stats[T_ACCEPTED] += mem.state[S_ACCEPTED]
        if mem.state[S_E] < best:
            best = mem.state[S_E]
            best_q[:] = q
        if code == CONVERGED:
            best_q[:] = q
            stats[T_BEST_E] = mem.state[S_E]
            return CONVERGED
        if code == STALL_STEP or code == STALL_WINDOW:  # noqa: SIM109 - plain comparisons for numba
            stats[T_STALLS] += 1.0
            if st.polish > 0 and _polished(q, ch, pb, st.polish, stats, mem):
                best_q[:] = q
                return CONVERGED
        if stats[T_SWEEPS] >= sweep_budget:
            stats[T_BEST_E] = best
            return BUDGET
    stats[T_BEST_E] = best
    return code


@njit(cache=True)
def _polished(q, ch, pb, iterations, stats, mem):
    """Gauss–Newton steps from a stalled attempt's q; True (q converged, its objective in mem) if they meet
    the tolerances, else q is left where the attempt stalled."""
    q_stalled = q.copy()
    code, _ = lm_polish(q, ch, pb, iterations)
    if code == CONVERGED:
        stats[T_POLISHED] += 1.0
        n = q.shape[0]
        e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
        chain_fk(ch, q, e, o, p, R)
        mem.state[S_E] = total_objective(q, ch.kind, p, R, pb)
        stats[T_BEST_E] = mem.state[S_E]
        return True
    q[:] = q_stalled
    return False


@njit(cache=True)
def lm_polish(q, ch, pb, iterations):
    """Levenberg–Marquardt on the world-frame error of the constrained components, steps kept in the windows:
    [p* − p; log(R* Rᵀ)], or for task "axis" [p* − p; a* − a] with a the tool axis (da/dq_i = e_i × a).

    Returns (CONVERGED or −1, iterations spent); q is updated in place.
    """
    n = q.shape[0]
    e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
    J = np.empty((6, n))
    err = np.empty(6)
    for it in range(iterations):
        chain_fk(ch, q, e, o, p, R)
        if _within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis):
            return CONVERGED, it
        _world_error(p, R, pb, err)
        _world_jacobian(e, o, p, R, ch.kind, pb, J)
        A = J.T @ J
        damping = 1e-9 + 1e-3 * (err @ err)
        for i in range(n):
            A[i, i] += damping
        dq = np.linalg.solve(A, J.T @ err)
        for i in range(n):
            q[i] = min(max(q[i] + dq[i], pb.lower[i]), pb.upper[i])
    chain_fk(ch, q, e, o, p, R)
    if _within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis):
        return CONVERGED, iterations
    return -1, iterations


@njit(cache=True)
def _world_jacobian(e, o, p, R, kind, pb, J):
    """J ← the error's Jacobian rows (position; rotation, or the tool axis of task "axis"); unchecked rows 0."""
    for i in range(e.shape[0]):
        if kind[i] == PRISMATIC:
            J[0:3, i] = e[i]
            J[3:6, i] = 0.0
        else:
            J[0:3, i] = np.cross(e[i], p - o[i])
            J[3:6, i] = e[i] if pb.rot_axis < 0 else np.cross(e[i], R[:, pb.rot_axis])
        if not pb.check_pos:
            J[0:3, i] = 0.0
        if not pb.check_rot:
            J[3:6, i] = 0.0


@njit(cache=True)
def _world_error(p, R, pb, err):
    """err = [p* − p; log(R* Rᵀ) or a* − a] with the constrained components only (an unchecked component
    must not pull)."""
    for k in range(3):
        err[k] = pb.pstar[k] - p[k] if pb.check_pos else 0.0
    if pb.rot_axis >= 0:
        for k in range(3):
            err[3 + k] = pb.Rstar[k, pb.rot_axis] - R[k, pb.rot_axis] if pb.check_rot else 0.0
        return
    M = pb.Rstar @ R.T
    cos_a = min(1.0, max(-1.0, (M[0, 0] + M[1, 1] + M[2, 2] - 1.0) / 2.0))
    angle = np.arccos(cos_a)
    scale = 0.5 if angle < 1e-8 else angle / (2.0 * np.sin(angle))
    w = (M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1])
    for k in range(3):
        err[3 + k] = scale * w[k] if pb.check_rot else 0.0
