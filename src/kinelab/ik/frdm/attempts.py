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

from kinelab.ik.chain import chain_fk, random_configuration
from kinelab.ik.frdm.kernel import (
    BASE_TO_TIP,
    BUDGET,
    CONVERGED,
    MIXED,
    S_ACCEPTED,
    S_E,
    S_NEWTON,
    S_SWEEPS,
    STALL_STEP,
    STALL_WINDOW,
    T_ACCEPTED,
    T_ATTEMPTS,
    T_BEST_E,
    T_CUT,
    T_NEWTON,
    T_POLISHED,
    T_STALLS,
    T_SWEEPS,
    TIP_TO_BASE,
    run,
    total_objective,
)
from kinelab.ik.frdm.newton import lm_polish


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
        stats[T_NEWTON] += mem.state[S_NEWTON]
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
