"""The biquaternion solver's default preset compiled (numba): law (9)/(16), Euler with h·k = 1 and a
joint-step cap, the Cauchy problem q̇ = A⁻¹U integrated on the FRDM kernel's chain FK, with seeded
restarts. The Python integrator in :mod:`kinelab.ik.biquat` is the reference; tests hold the two equal.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.frdm.kernel import CONTINUOUS, PRISMATIC, _xorshift, chain_fk

CONVERGED, SINGULAR, MAX_STEPS, OUTSIDE_LIMITS, BUDGET = 0, 1, 2, 3, 4
TWO_PI = 2.0 * np.pi


@njit(cache=True)
def quat_wxyz(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix, w ≥ 0 (Shepperd)."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    q = np.empty(4)
    if t > 0.0:
        s = np.sqrt(t + 1.0) * 2.0
        q[0] = 0.25 * s
        q[1] = (R[2, 1] - R[1, 2]) / s
        q[2] = (R[0, 2] - R[2, 0]) / s
        q[3] = (R[1, 0] - R[0, 1]) / s
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2]) * 2.0
        q[0] = (R[2, 1] - R[1, 2]) / s
        q[1] = 0.25 * s
        q[2] = (R[0, 1] + R[1, 0]) / s
        q[3] = (R[0, 2] + R[2, 0]) / s
    elif R[1, 1] > R[2, 2]:
        s = np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2]) * 2.0
        q[0] = (R[0, 2] - R[2, 0]) / s
        q[1] = (R[0, 1] + R[1, 0]) / s
        q[2] = 0.25 * s
        q[3] = (R[1, 2] + R[2, 1]) / s
    else:
        s = np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1]) * 2.0
        q[0] = (R[1, 0] - R[0, 1]) / s
        q[1] = (R[0, 2] + R[2, 0]) / s
        q[2] = (R[1, 2] + R[2, 1]) / s
        q[3] = 0.25 * s
    if q[0] < 0.0:
        q = -q
    return q / np.sqrt(q @ q)


@njit(cache=True)
def error_biquaternion(p, R, pstar, Rstar):
    """M* = N̄∘Λ (8 numbers, m^0 ≥ 0): the tool's pose in the target frame."""
    Rrel = Rstar.T @ R
    t = Rstar.T @ (p - pstar)
    m = quat_wxyz(Rrel)
    tx, ty, tz = 0.5 * t[0], 0.5 * t[1], 0.5 * t[2]
    out = np.empty(8)
    out[:4] = m
    out[4] = -tx * m[1] - ty * m[2] - tz * m[3]
    out[5] = tx * m[0] + ty * m[3] - tz * m[2]
    out[6] = ty * m[0] + tz * m[1] - tx * m[3]
    out[7] = tz * m[0] + tx * m[2] - ty * m[1]
    return out


@njit(cache=True)
def jacobian_local(e, o, kind, p, R):
    """6 × n tool Jacobian in the tool frame (rows v, ω), from the chain's axes and points."""
    n = e.shape[0]
    J = np.empty((6, n))
    for i in range(n):
        if kind[i] == PRISMATIC:
            v = e[i]
            w = np.zeros(3)
        else:
            r = p - o[i]
            v = np.cross(e[i], r)
            w = e[i]
        J[:3, i] = R.T @ v
        J[3:, i] = R.T @ w
    return J


@njit(cache=True)
def integrate(q, PR, Pt, axis, kind, TR, Tt, pstar, Rstar, k, h, max_step, max_steps, eps_rot, eps_dual,
              damping):
    """Euler steps of q̇ = A⁻¹U(M*) with law (9) (k0 = 0) from q, in place. Returns (code, steps, model time)."""
    n = q.shape[0]
    e = np.empty((n, 3))
    o = np.empty((n, 3))
    p = np.empty(3)
    R = np.empty((3, 3))
    twist = np.empty(6)
    t = 0.0
    for step in range(max_steps + 1):
        chain_fk(PR, Pt, axis, kind, TR, Tt, q, e, o, p, R)
        M = error_biquaternion(p, R, pstar, Rstar)
        m0, d0 = M[0], M[4]
        if M[1] ** 2 + M[2] ** 2 + M[3] ** 2 < eps_rot ** 2 and M[5] ** 2 + M[6] ** 2 + M[7] ** 2 < eps_dual ** 2:
            return CONVERGED, step, t
        if step == max_steps or m0 == 0.0:
            return MAX_STEPS if m0 != 0.0 else SINGULAR, step, t
        for j in range(3):
            twist[3 + j] = -2.0 * k * M[1 + j] / m0  # ω
            twist[j] = -2.0 * k * (m0 * M[5 + j] - d0 * M[1 + j]) / (m0 * m0)  # v
        J = jacobian_local(e, o, kind, p, R)
        if n == 6 and damping == 0.0:
            if abs(np.linalg.det(J)) < 1e-300:
                return SINGULAR, step, t
            qd = np.linalg.solve(J, twist)
        else:
            U, s, Vt = np.linalg.svd(J, full_matrices=False)
            qd = Vt.T @ ((s / (s * s + damping * damping)) * (U.T @ twist))
        fastest = 0.0
        for i in range(n):
            if not np.isfinite(qd[i]):
                return SINGULAR, step, t
            fastest = max(fastest, abs(qd[i]))
        dt = h if fastest * h <= max_step else max_step / fastest
        for i in range(n):
            q[i] += dt * qd[i]
        t += dt
    return MAX_STEPS, max_steps, t


@njit(cache=True)
def wrap_into_limits(q, kind, lower, upper):
    """Wrap revolute joints by 2πk into their limits, continuous ones into (−π, π]; True if all fit."""
    ok = True
    for i in range(q.shape[0]):
        if kind[i] == CONTINUOUS:
            q[i] = np.arctan2(np.sin(q[i]), np.cos(q[i]))
        elif kind[i] != PRISMATIC and (q[i] < lower[i] or q[i] > upper[i]):
            shifted = q[i] + TWO_PI * np.ceil((lower[i] - q[i]) / TWO_PI)
            if shifted <= upper[i]:
                q[i] = shifted
        if kind[i] != CONTINUOUS and (q[i] < lower[i] - 1e-9 or q[i] > upper[i] + 1e-9):
            ok = False
    return ok


@njit(cache=True)
def multistart(q, PR, Pt, axis, kind, TR, Tt, lower, upper, pstar, Rstar, k, h, max_step, max_steps, eps_rot,
               eps_dual, damping, rng_state, max_attempts, step_budget, stats):
    """Attempts from q, then from seeded uniform starts, until one converges inside the joint limits.
    stats = [attempts, steps, model time of the answer, outside-limit answers, singular stops]."""
    n = q.shape[0]
    start = q.copy()
    code = BUDGET
    for a in range(max_attempts):
        if a > 0:
            for i in range(n):
                if kind[i] == CONTINUOUS:
                    start[i] = -np.pi + TWO_PI * _xorshift(rng_state)
                else:
                    start[i] = lower[i] + (upper[i] - lower[i]) * _xorshift(rng_state)
            q[:] = start
        code, steps, t = integrate(q, PR, Pt, axis, kind, TR, Tt, pstar, Rstar, k, h, max_step,
                                   min(max_steps, int(step_budget - stats[1])), eps_rot, eps_dual, damping)
        stats[0] += 1.0
        stats[1] += steps
        if code == CONVERGED:
            if wrap_into_limits(q, kind, lower, upper):
                stats[2] = t
                return CONVERGED
            stats[3] += 1.0
            code = OUTSIDE_LIMITS
        elif code == SINGULAR:
            stats[4] += 1.0
        if stats[1] >= step_budget:
            return BUDGET
    return code
