"""The biquaternion solver's default preset compiled (numba): law (9), Euler with h·k = 1 and a joint-step
cap, the Cauchy problem q̇ = A⁻¹U integrated on the shared chain FK, with seeded restarts.

The Python integrators (:mod:`kinelab.ik.biquat.integrators`) are the reference and call the same laws
(:mod:`kinelab.ik.biquat.laws`); tests hold the two paths equal.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from kinelab.ik.biquat.laws import converged, error_biquaternion, joint_rates, simple_law
from kinelab.ik.chain import chain_fk, jacobian_local, random_configuration, wrap_into_limits

CONVERGED, SINGULAR, MAX_STEPS, OUTSIDE_LIMITS, BUDGET = 0, 1, 2, 3, 4
# slots of a multistart's statistics array
T_ATTEMPTS, T_STEPS, T_MODEL_TIME, T_OUTSIDE, T_SINGULAR, T_CUT, T_ATTEMPT_STEPS, T_ATTEMPT_TIME = range(8)
STATS_SIZE = 8


class Control(NamedTuple):
    """The target and the preset's settings."""

    pstar: np.ndarray  # (3,) target point [m], base frame
    Rstar: np.ndarray  # (3, 3) target rotation
    k: float  # gain [1/s]
    h: float  # step [s]
    max_step: float  # largest joint change per step [rad or m]
    max_steps: int  # steps per attempt
    eps_rot: float  # stop when |m⃗| < eps_rot (half the rotation tolerance)
    eps_dual: float  # and |m0⃗| < eps_dual (half the position tolerance) [m]
    damping: float  # λ of the damped pseudo-inverse (0: exact solve when n = 6)


Problem = Control  # its name before 0.2: numba caches written by 0.1 refer to it and must still load


@njit(cache=True)
def integrate(q, ch, pb, max_steps):
    """Euler steps of q̇ = A⁻¹U(M*) with law (9) (k0 = 0) from q, in place. Returns (code, steps, model time)."""
    n = q.shape[0]
    e = np.empty((n, 3))
    o = np.empty((n, 3))
    p = np.empty(3)
    R = np.empty((3, 3))
    twist = np.empty(6)
    t = 0.0
    for step in range(max_steps + 1):
        chain_fk(ch, q, e, o, p, R)
        M = error_biquaternion(p, R, pb.pstar, pb.Rstar)
        if converged(M, pb.eps_rot, pb.eps_dual):
            return CONVERGED, step, t
        if M[0] == 0.0:
            return SINGULAR, step, t
        if step == max_steps:
            return MAX_STEPS, step, t
        simple_law(M, pb.k, 0.0, pb.k, twist)
        if not (np.isfinite(twist[0]) and np.isfinite(twist[1]) and np.isfinite(twist[2]) and np.isfinite(twist[3])
                and np.isfinite(twist[4]) and np.isfinite(twist[5])):
            return SINGULAR, step, t  # the law overflowed (m^0 tiny against the gain)
        qd = joint_rates(jacobian_local(e, o, ch.kind, p, R), twist, pb.damping)
        fastest = 0.0
        for i in range(n):
            if not np.isfinite(qd[i]):
                return SINGULAR, step, t
            fastest = max(fastest, abs(qd[i]))
        dt = pb.h if fastest * pb.h <= pb.max_step else pb.max_step / fastest
        for i in range(n):
            q[i] += dt * qd[i]
        t += dt
    return MAX_STEPS, max_steps, t


@njit(cache=True)
def multistart(q, ch, lower, upper, pb, rng_state, max_attempts, step_budget, stats, restart_lower, restart_upper):
    """Attempts from q, then from seeded uniform starts in the restart windows (``restart_lower``,
    ``restart_upper``), until one converges inside the joint limits (``lower``, ``upper``).

    Called in chunks: an attempt that ``step_budget`` (a total) cuts is resumed by the next call from the
    same q with the steps it has left, so the answer does not depend on where the chunks end. stats has the
    slots T_*. Returns an integrate() code, or OUTSIDE_LIMITS, or BUDGET.
    """
    code = BUDGET
    for _ in range(max_attempts):
        if stats[T_CUT] == 0.0:
            if stats[T_ATTEMPTS] > 0.0:
                random_configuration(q, ch.kind, restart_lower, restart_upper, rng_state)
            stats[T_ATTEMPT_STEPS] = 0.0
            stats[T_ATTEMPT_TIME] = 0.0
        stats[T_CUT] = 0.0
        left = pb.max_steps - int(stats[T_ATTEMPT_STEPS])
        budget = min(left, int(step_budget - stats[T_STEPS]))
        code, steps, t = integrate(q, ch, pb, budget)
        stats[T_STEPS] += steps
        stats[T_ATTEMPT_STEPS] += steps
        stats[T_ATTEMPT_TIME] += t
        if code == MAX_STEPS and budget < left:  # cut by the chunk: the next call resumes this attempt
            stats[T_CUT] = 1.0
            return BUDGET
        stats[T_ATTEMPTS] += 1.0
        if code == CONVERGED:
            if wrap_into_limits(q, ch.kind, lower, upper):
                stats[T_MODEL_TIME] = stats[T_ATTEMPT_TIME]
                return CONVERGED
            stats[T_OUTSIDE] += 1.0
            code = OUTSIDE_LIMITS
        elif code == SINGULAR:
            stats[T_SINGULAR] += 1.0
        if stats[T_STEPS] >= step_budget:
            return BUDGET
    return code
