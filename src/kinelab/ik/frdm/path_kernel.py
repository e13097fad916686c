"""The compiled path follower: every sample of a path solved inside one kernel call, warm-started from
the sample before (FRDM's direct-control use, Danilov 2019).

Each sample runs in two phases. The first minimises E plus a rest term pulling towards the previous
sample's answer (``w_rest`` Σ 2(1 − cos Δq)): among the configurations that reach the target it
prefers the nearest one, which on a redundant arm keeps the self-motion from drifting into a joint
limit or a branch jump. The second, run only when the first has not met the tolerances, is plain
FRDM from where the first stopped, so the rest term never costs accuracy. Near a singular point FRDM
crawls (its rate tends to 1); with ``lm_iterations`` > 0 a sample it leaves short of the tolerances
gets damped Gauss–Newton steps (Levenberg–Marquardt): not an FRDM step, so the follower reports that
mode under its own name.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.frdm.kernel import CONVERGED, STATE_SIZE, Memory, Objective, run
from kinelab.ik.frdm.newton import lm_polish


@njit(cache=True)
def follow(Q, q0, ch, lower, upper, free, pstars, Rstars, w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
           st, order, max_sweeps, w_rest, rest_sweeps, centre, pull, lm_iterations, codes, sweeps):
    """Solve sample k of the path (pstars[k], Rstars[k]) from the answer to sample k − 1 (q0 for the first).

    Inputs, in order:
        Q (np.ndarray): (N, n) output, one configuration per sample [rad or m].
        q0 (np.ndarray): (n,) configuration before the first sample.
        ch (Chain): the chain.
        lower, upper, free (np.ndarray): joint windows and free mask, shared by every sample.
        pstars (np.ndarray): (N, 3) target points [m]; Rstars: (N, 3, 3) target rotations (base frame).
        w_p (float), w_ax (np.ndarray): objective weights; tol_pos [m], tol_rot [rad], check_pos, check_rot.
        st (Settings), order (int): sweep settings and order code.
        max_sweeps (int): sweep cap of each phase.
        w_rest (float): weight of the rest term in the first phase (0: one plain phase).
        rest_sweeps (int): sweep cap of the first phase.
        centre (np.ndarray), pull (float): the rest configuration is q_prev + s (centre − q_prev), s = pull times
            the joint's limit measure (see :func:`_limit_pull`).
        lm_iterations (int): Levenberg–Marquardt steps after FRDM for a sample still short (0: none).
        codes, sweeps (np.ndarray): (N,) outputs: run() code and sweeps spent per sample.
    """
    n = q0.shape[0]
    mem = Memory(np.zeros((st.accel_m + 1, n)), np.zeros((st.accel_m + 1, n)), np.zeros(STATE_SIZE), np.zeros(0),
                 np.zeros((2 * n + 4, 3)))
    q = q0.copy()
    q_prev = q0.copy()
    rest = q0.copy()
    for k in range(Q.shape[0]):
        spent = 0
        code = -1
        if w_rest > 0.0:
            for i in range(n):
                rest[i] = q_prev[i] + _limit_pull(q_prev[i], lower[i], upper[i], pull) * (centre[i] - q_prev[i])
            pb = Objective(lower, upper, free, pstars[k], Rstars[k], w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
                         rest, w_rest, -1)
            mem.state[:] = 0.0
            code, spent = run(q, ch, pb, st, order, rest_sweeps, mem)
        if code != CONVERGED:
            pb = Objective(lower, upper, free, pstars[k], Rstars[k], w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
                         q_prev, 0.0, -1)
            mem.state[:] = 0.0
            code, more = run(q, ch, pb, st, order, max_sweeps, mem)
            spent += more
        if code != CONVERGED and lm_iterations > 0:
            code, more = lm_polish(q, ch, pb, lm_iterations)
            spent += more
        Q[k] = q
        q_prev[:] = q
        codes[k] = code
        sweeps[k] = spent


@njit(cache=True)
def _limit_pull(x, lo, hi, pull):
    """The share of the way to mid-range the rest configuration takes for a joint at x: ``pull`` times the
    Chan–Dubey measure (hi − lo)² / (4 (x − lo)(hi − x)), 1 at mid-range and growing without bound at a
    limit, capped at 1/2: a joint in mid-range is left where it is, one near a limit is drawn back."""
    dl, du = x - lo, hi - x
    if not (dl > 0.0 and du > 0.0) or dl + du == np.inf:
        return pull if dl + du != np.inf else 0.0
    return min(0.5, pull * (dl + du) * (dl + du) / (4.0 * dl * du))
