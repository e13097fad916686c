"""The compiled FRDM inner loop (numba): chain FK, the exact per-joint steps, sweeps, acceleration.

Everything here works on plain arrays of the vector model (:mod:`kinelab.ik.frdm.model`); the
readable reference of the same mathematics is :mod:`kinelab.ik.frdm.reference`, and the tests hold
the two together. Notation (methods.md §1): e, o = joint axis and a point on it (base frame), p = tool
point, R = tool rotation (columns u_x, u_y, u_z), starred = target. Objective

    E = w_p ‖p − p*‖² + Σ_j w_j ‖u_j − u*_j‖².

Joint kinds: 0 revolute with limits, 1 prismatic, 2 continuous (revolute without limits).
"""

from __future__ import annotations

import numpy as np
from numba import njit

REVOLUTE, PRISMATIC, CONTINUOUS = 0, 1, 2
TWO_PI = 2.0 * np.pi

REFRESH_SWEEPS = 8  # sweeps carried incrementally before the chain FK is recomputed
MIXED = 3  # multistart order code: alternate the sweep direction from one attempt to the next

# run() return codes
CONVERGED, STALL_STEP, STALL_WINDOW, BUDGET = 0, 1, 2, 3


@njit(cache=True, inline="always")
def _rotm(x, y, z, angle):
    """Rodrigues' rotation by ``angle`` [rad] about the unit vector (x, y, z), as 9 scalars row by row."""
    c, s = np.cos(angle), np.sin(angle)
    C = 1.0 - c
    return (c + x * x * C, x * y * C - z * s, x * z * C + y * s,
            y * x * C + z * s, c + y * y * C, y * z * C - x * s,
            z * x * C - y * s, z * y * C + x * s, c + z * z * C)


@njit(cache=True)
def rot(axis, angle):
    """Rotation matrix by ``angle`` [rad] about the unit vector ``axis``."""
    m = _rotm(axis[0], axis[1], axis[2], angle)
    R = np.empty((3, 3))
    for k in range(9):
        R[k // 3, k % 3] = m[k]
    return R


@njit(cache=True, inline="always")
def _mm_into(A, B, out):
    """out = A @ B for 3 × 3 matrices (loops: numba's @ calls BLAS, far slower at this size)."""
    for r in range(3):
        a0, a1, a2 = A[r, 0], A[r, 1], A[r, 2]
        for c in range(3):
            out[r, c] = a0 * B[0, c] + a1 * B[1, c] + a2 * B[2, c]


@njit(cache=True, inline="always")
def _rotate_rows(m, R):
    """R ← M R in place, M given as 9 scalars."""
    for c in range(3):
        x, y, z = R[0, c], R[1, c], R[2, c]
        R[0, c] = m[0] * x + m[1] * y + m[2] * z
        R[1, c] = m[3] * x + m[4] * y + m[5] * z
        R[2, c] = m[6] * x + m[7] * y + m[8] * z


@njit(cache=True, inline="always")
def _rotate_about(m, ox, oy, oz, v):
    """v ← o + M (v − o) in place."""
    x, y, z = v[0] - ox, v[1] - oy, v[2] - oz
    v[0] = ox + m[0] * x + m[1] * y + m[2] * z
    v[1] = oy + m[3] * x + m[4] * y + m[5] * z
    v[2] = oz + m[6] * x + m[7] * y + m[8] * z


@njit(cache=True)
def chain_fk(PR, Pt, axis, kind, TR, Tt, q, e_out, o_out, p_out, R_out):
    """FK of the chain at q: joint axes ``e_out`` and origins ``o_out`` and the tool pose (p, R), base frame.

    PR, Pt: placement of each joint frame in its parent's at q = 0; axis: local joint axes;
    TR, Tt: tool frame in the last joint's frame.
    """
    Rw = np.eye(3)
    tmp = np.empty((3, 3))
    t0 = t1 = t2 = 0.0
    for i in range(q.shape[0]):
        P = Pt[i]
        t0, t1, t2 = (t0 + Rw[0, 0] * P[0] + Rw[0, 1] * P[1] + Rw[0, 2] * P[2],
                      t1 + Rw[1, 0] * P[0] + Rw[1, 1] * P[1] + Rw[1, 2] * P[2],
                      t2 + Rw[2, 0] * P[0] + Rw[2, 1] * P[1] + Rw[2, 2] * P[2])
        _mm_into(Rw, PR[i], tmp)
        a = axis[i]
        e0 = tmp[0, 0] * a[0] + tmp[0, 1] * a[1] + tmp[0, 2] * a[2]
        e1 = tmp[1, 0] * a[0] + tmp[1, 1] * a[1] + tmp[1, 2] * a[2]
        e2 = tmp[2, 0] * a[0] + tmp[2, 1] * a[1] + tmp[2, 2] * a[2]
        if kind[i] == PRISMATIC:
            t0, t1, t2 = t0 + e0 * q[i], t1 + e1 * q[i], t2 + e2 * q[i]
            Rw[:, :] = tmp
        else:
            # Rw ← tmp·Rot(a, q) about the exact unit local axis: the world axis e carries rounding, and a
            # rotation about it would feed that back into Rw and grow along a long chain
            m = _rotm(a[0], a[1], a[2], q[i])
            for r in range(3):
                x, y, z = tmp[r, 0], tmp[r, 1], tmp[r, 2]
                Rw[r, 0] = x * m[0] + y * m[3] + z * m[6]
                Rw[r, 1] = x * m[1] + y * m[4] + z * m[7]
                Rw[r, 2] = x * m[2] + y * m[5] + z * m[8]
        e_out[i, 0], e_out[i, 1], e_out[i, 2] = e0, e1, e2
        o_out[i, 0], o_out[i, 1], o_out[i, 2] = t0, t1, t2
    for r in range(3):
        p_out[r] = (t0, t1, t2)[r] + Rw[r, 0] * Tt[0] + Rw[r, 1] * Tt[1] + Rw[r, 2] * Tt[2]
    _mm_into(Rw, TR, R_out)


@njit(cache=True)
def objective(p, R, pstar, Rstar, w_p, w_ax):
    d0, d1, d2 = p[0] - pstar[0], p[1] - pstar[1], p[2] - pstar[2]
    E = w_p * (d0 * d0 + d1 * d1 + d2 * d2)
    for j in range(3):
        u0 = R[0, j] - Rstar[0, j]
        u1 = R[1, j] - Rstar[1, j]
        u2 = R[2, j] - Rstar[2, j]
        E += w_ax[j] * (u0 * u0 + u1 * u1 + u2 * u2)
    return E


@njit(cache=True)
def rotation_angle(R, Rstar):
    """Angle [rad] of R*ᵀR, accurate near 0 and near π (atan2 of the sine and cosine parts)."""
    M = np.empty((3, 3))
    _mm_into(Rstar.T, R, M)
    sx = 0.5 * (M[2, 1] - M[1, 2])
    sy = 0.5 * (M[0, 2] - M[2, 0])
    sz = 0.5 * (M[1, 0] - M[0, 1])
    c = 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)
    return np.arctan2(np.sqrt(sx * sx + sy * sy + sz * sz), c)


@njit(cache=True, inline="always")
def _within(p, R, pstar, Rstar, tol_pos, tol_rot, check_pos, check_rot):
    """Both tolerances met (those checked): position [m] and rotation angle [rad]."""
    dp = np.sqrt((p[0] - pstar[0]) ** 2 + (p[1] - pstar[1]) ** 2 + (p[2] - pstar[2]) ** 2)
    return (not check_pos or dp <= tol_pos) and (not check_rot or rotation_angle(R, Rstar) <= tol_rot)


@njit(cache=True, inline="always")
def _bc(e0, e1, e2, o0, o1, o2, p, R, pstar, Rstar, w_p, w_ax):
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about the line (e, o)."""
    r0, r1, r2 = p[0] - o0, p[1] - o1, p[2] - o2
    d0, d1, d2 = pstar[0] - o0, pstar[1] - o1, pstar[2] - o2
    er = e0 * r0 + e1 * r1 + e2 * r2
    ed = e0 * d0 + e1 * d1 + e2 * d2
    B = w_p * (d0 * r0 + d1 * r1 + d2 * r2 - ed * er)  # d⊥·r⊥
    C = w_p * (e0 * (r1 * d2 - r2 * d1) + e1 * (r2 * d0 - r0 * d2) + e2 * (r0 * d1 - r1 * d0))  # e·(r×d)
    for j in range(3):
        w = w_ax[j]
        if w != 0.0:
            u0, u1, u2 = R[0, j], R[1, j], R[2, j]
            s0, s1, s2 = Rstar[0, j], Rstar[1, j], Rstar[2, j]
            eu = e0 * u0 + e1 * u1 + e2 * u2
            es = e0 * s0 + e1 * s1 + e2 * s2
            B += w * (s0 * u0 + s1 * u1 + s2 * u2 - es * eu)
            C += w * (e0 * (u1 * s2 - u2 * s1) + e1 * (u2 * s0 - u0 * s2) + e2 * (u0 * s1 - u1 * s0))
    return B, C


@njit(cache=True)
def revolute_BC(e, o, p, R, pstar, Rstar, w_p, w_ax):
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about (e, o) (array arguments)."""
    return _bc(e[0], e[1], e[2], o[0], o[1], o[2], p, R, pstar, Rstar, w_p, w_ax)


@njit(cache=True)
def revolute_angle(B, C, lo, hi, continuous):
    """The exact minimiser of E(θ) over the window [lo, hi] ∋ 0 (methods.md §1.5)."""
    if B == 0.0 and C == 0.0:
        return 0.0
    t = np.arctan2(C, B)
    if continuous:
        return t
    best = 0.0
    found = False
    for k in (-1.0, 0.0, 1.0):
        cand = t + k * TWO_PI
        if lo <= cand <= hi and (not found or abs(cand) < abs(best)):
            best = cand
            found = True
    if found:
        return best
    return lo if np.cos(lo - t) >= np.cos(hi - t) else hi


@njit(cache=True)
def sweep(q, e, o, kind, lower, upper, free, p, R, pstar, Rstar, w_p, w_ax, relax, base_to_tip):
    """One sweep over the free joints, tip → base or base → tip; updates q, p, R in place.

    ``e``, ``o`` must hold the axes at the sweep's starting q (from ``chain_fk``). Tip → base needs
    nothing more (a joint never moves the joints upstream of it); base → tip carries the rigid motion
    (Rg, tg) of the joints already stepped to the downstream axes, and leaves e, o at the new q (tip →
    base leaves them stale). Returns Σ|Δq_i|.
    """
    n = q.shape[0]
    total = 0.0
    Rg = np.eye(3)
    tg = np.zeros(3)
    moved_any = False
    for k in range(n):
        i = k if base_to_tip else n - 1 - k
        if moved_any:
            e0 = Rg[0, 0] * e[i, 0] + Rg[0, 1] * e[i, 1] + Rg[0, 2] * e[i, 2]
            e1 = Rg[1, 0] * e[i, 0] + Rg[1, 1] * e[i, 1] + Rg[1, 2] * e[i, 2]
            e2 = Rg[2, 0] * e[i, 0] + Rg[2, 1] * e[i, 1] + Rg[2, 2] * e[i, 2]
            norm = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)  # keep rounding in Rg from compounding
            e0, e1, e2 = e0 / norm, e1 / norm, e2 / norm
            o0 = Rg[0, 0] * o[i, 0] + Rg[0, 1] * o[i, 1] + Rg[0, 2] * o[i, 2] + tg[0]
            o1 = Rg[1, 0] * o[i, 0] + Rg[1, 1] * o[i, 1] + Rg[1, 2] * o[i, 2] + tg[1]
            o2 = Rg[2, 0] * o[i, 0] + Rg[2, 1] * o[i, 1] + Rg[2, 2] * o[i, 2] + tg[2]
            # base → tip, no later step moves joint i's axis: written back, e and o hold the axes at the
            # new q when the sweep ends, and the next sweep needs no chain FK
            e[i, 0], e[i, 1], e[i, 2] = e0, e1, e2
            o[i, 0], o[i, 1], o[i, 2] = o0, o1, o2
        else:
            e0, e1, e2 = e[i, 0], e[i, 1], e[i, 2]
            o0, o1, o2 = o[i, 0], o[i, 1], o[i, 2]
        if not free[i]:
            continue
        lo = lower[i] - q[i]
        hi = upper[i] - q[i]
        if kind[i] == PRISMATIC:
            s = 0.0
            if w_p > 0.0:
                s = relax * (e0 * (pstar[0] - p[0]) + e1 * (pstar[1] - p[1]) + e2 * (pstar[2] - p[2]))
            s = min(max(s, lo), hi)
            if s == 0.0:
                continue
            p[0] += e0 * s
            p[1] += e1 * s
            p[2] += e2 * s
            if base_to_tip:
                tg[0] += e0 * s
                tg[1] += e1 * s
                tg[2] += e2 * s
            step = s
        else:
            B, C = _bc(e0, e1, e2, o0, o1, o2, p, R, pstar, Rstar, w_p, w_ax)
            theta = revolute_angle(B, C, lo, hi, kind[i] == CONTINUOUS)
            if relax != 1.0:
                theta = relax * theta
                if kind[i] != CONTINUOUS:
                    theta = min(max(theta, lo), hi)
            if theta == 0.0:
                continue
            m = _rotm(e0, e1, e2, theta)
            _rotate_about(m, o0, o1, o2, p)
            _rotate_rows(m, R)
            if base_to_tip:
                _rotate_rows(m, Rg)
                _rotate_about(m, o0, o1, o2, tg)
            step = theta
        moved_any = base_to_tip
        q[i] += step
        total += abs(step)
    return total


@njit(cache=True)
def _anderson(X, G, count, m, x, g, out, dG, dX, A, rhs, gamma):
    """Type-II Anderson mixing of the last ``count`` (x, g = F(x) − x) pairs; result in ``out``.

    Solves the small least-squares problem min ‖g − ΔG γ‖ by a regularised Cholesky factorisation.
    dG, dX (n × m), A (m × m), rhs, gamma (m): work arrays, allocated once per run (allocation inside
    the sweep loop cost more than the arithmetic).
    """
    k = min(count, m)
    n = x.shape[0]
    for c in range(k):
        a = (count - k + c) % (m + 1)
        b = (count - k + c + 1) % (m + 1)
        for i in range(n):
            dG[i, c] = G[b, i] - G[a, i]
            dX[i, c] = X[b, i] - X[a, i]
    for r in range(k):
        rhs[r] = 0.0
        for i in range(n):
            rhs[r] += dG[i, r] * g[i]
        for c in range(r + 1):
            acc = 0.0
            for i in range(n):
                acc += dG[i, r] * dG[i, c]
            A[r, c] = acc
            A[c, r] = acc
    trace = 0.0
    for r in range(k):
        trace += A[r, r]
    if trace <= 0.0:  # no change in the residuals: nothing to extrapolate
        out[:] = x + g
        return
    for r in range(k):
        A[r, r] += 1e-10 * trace
    # Cholesky A = L Lᵀ in place (lower triangle), then two triangular solves
    for j in range(k):
        acc = A[j, j]
        for t in range(j):
            acc -= A[j, t] * A[j, t]
        A[j, j] = np.sqrt(max(acc, 1e-300))
        for r in range(j + 1, k):
            acc = A[r, j]
            for t in range(j):
                acc -= A[r, t] * A[j, t]
            A[r, j] = acc / A[j, j]
    for r in range(k):
        gamma[r] = rhs[r]
    for r in range(k):
        for t in range(r):
            gamma[r] -= A[r, t] * gamma[t]
        gamma[r] /= A[r, r]
    for r in range(k - 1, -1, -1):
        for t in range(r + 1, k):
            gamma[r] -= A[t, r] * gamma[t]
        gamma[r] /= A[r, r]
    for i in range(n):
        acc = x[i] + g[i]
        for c in range(k):
            acc -= (dX[i, c] + dG[i, c]) * gamma[c]
        out[i] = acc


@njit(cache=True)
def run(
    q, PR, Pt, axis, kind, TR, Tt, lower, upper, free, pstar, Rstar, w_p, w_ax, relax, order,
    tol_pos, tol_rot, check_pos, check_rot, max_sweeps, eps_q, window, window_rel,
    accel_m, X, G, state, trace,
):
    """Sweep until converged, stalled or ``max_sweeps`` sweeps; q is updated in place.

    order: 0 tip → base, 1 base → tip, 2 alternating. accel_m: Anderson memory (0 = plain FRDM).
    X, G: (accel_m + 1) × n history rings; state: [history count, sweeps done, E at window start,
    sweep at window start, accepted accelerations, E, next sweep base → tip (after a kick)];
    trace: per-sweep objective (−1 where unused). Returns (code, sweeps in this call).
    """
    n = q.shape[0]
    e = np.empty((n, 3))
    o = np.empty((n, 3))
    p = np.empty(3)
    R = np.empty((3, 3))
    pc = np.empty(3)
    Rc = np.empty((3, 3))
    x_old = np.empty(n)
    cand = np.empty(n)
    g = np.empty(n)
    ec = np.empty((n, 3))
    oc = np.empty((n, 3))
    m = max(accel_m, 1)
    dG, dX, A = np.empty((n, m)), np.empty((n, m)), np.empty((m, m))
    rhs, gamma = np.empty(m), np.empty(m)
    fresh = False  # e, o, p, R hold the state at q (carried by the last sweep or an accepted extrapolation)
    since_fk = 0  # sweeps since p, R came from a chain FK (incremental updates carry rounding)
    for s in range(max_sweeps):
        if not fresh or since_fk >= REFRESH_SWEEPS:
            chain_fk(PR, Pt, axis, kind, TR, Tt, q, e, o, p, R)
            since_fk = 0
        if state[1] == 0.0:
            state[2] = objective(p, R, pstar, Rstar, w_p, w_ax)
        converged = _within(p, R, pstar, Rstar, tol_pos, tol_rot, check_pos, check_rot)
        if converged and since_fk > 0:  # converged only on an exact FK
            chain_fk(PR, Pt, axis, kind, TR, Tt, q, e, o, p, R)
            since_fk = 0
            converged = _within(p, R, pstar, Rstar, tol_pos, tol_rot, check_pos, check_rot)
        if converged:
            state[5] = objective(p, R, pstar, Rstar, w_p, w_ax)
            return CONVERGED, s
        x_old[:] = q
        base_to_tip = order == 1 or (order == 2 and int(state[1]) % 2 == 1) or state[6] != 0.0
        state[6] = 0.0
        moved = sweep(q, e, o, kind, lower, upper, free, p, R, pstar, Rstar, w_p, w_ax, relax, base_to_tip)
        fresh = base_to_tip
        since_fk += 1
        E1 = objective(p, R, pstar, Rstar, w_p, w_ax)
        state[1] += 1.0
        if int(state[1]) - 1 < trace.shape[0]:
            trace[int(state[1]) - 1] = E1
        if moved < eps_q:
            state[5] = E1
            return STALL_STEP, s + 1
        if accel_m > 0:
            cnt = int(state[0])
            slot = cnt % (accel_m + 1)
            for i in range(n):
                g[i] = q[i] - x_old[i]
                X[slot, i] = x_old[i]
                G[slot, i] = g[i]
            state[0] = cnt + 1.0
            if cnt >= 1:
                _anderson(X, G, cnt, accel_m, x_old, g, cand, dG, dX, A, rhs, gamma)
                finite = True
                for i in range(n):
                    finite = finite and np.isfinite(cand[i])
                if not finite:  # a degenerate history: drop it, keep the plain sweep
                    state[0] = 0.0
                    cand[:] = q
                for i in range(n):
                    if kind[i] != CONTINUOUS:
                        cand[i] = min(max(cand[i], lower[i]), upper[i])
                    if not free[i]:
                        cand[i] = q[i]
                chain_fk(PR, Pt, axis, kind, TR, Tt, cand, ec, oc, pc, Rc)
                Ec = objective(pc, Rc, pstar, Rstar, w_p, w_ax)
                if Ec < E1:
                    q[:] = cand
                    e, ec = ec, e
                    o, oc = oc, o
                    p, pc = pc, p
                    R, Rc = Rc, R
                    fresh = True
                    since_fk = 0
                    E1 = Ec
                    state[4] += 1.0
        state[5] = E1
        if state[1] - state[3] >= window:
            if state[2] - E1 <= window_rel * state[2]:
                return STALL_WINDOW, s + 1
            state[2] = E1
            state[3] = state[1]
    return BUDGET, max_sweeps


@njit(cache=True)
def _xorshift(state):
    """xorshift64*: a small seeded generator for restarts inside the kernel; returns a float in [0, 1)."""
    x = state[0]
    x ^= x >> np.uint64(12)
    x ^= x << np.uint64(25)
    x ^= x >> np.uint64(27)
    state[0] = x
    return float((x * np.uint64(2685821657736338717)) >> np.uint64(11)) / 9007199254740992.0


@njit(cache=True)
def multistart(
    q, PR, Pt, axis, kind, TR, Tt, lower, upper, free, pstar, Rstar, w_p, w_ax, relax, order,
    tol_pos, tol_rot, check_pos, check_rot, max_sweeps, eps_q, window, window_rel, accel_m,
    rng_state, max_attempts, sweep_budget, best_q, stats,
):
    """Attempts from q, then from seeded uniform starts, until one converges, ``max_attempts`` have run or
    ``sweep_budget`` sweeps are spent. A stall ends an attempt (a restart, not a bypass).

    On return q holds the converged configuration (or the last start), best_q the lowest-objective one;
    stats = [attempts, sweeps, stalls, accepted accelerations, best objective]. Returns a run() code.
    """
    n = q.shape[0]
    X = np.zeros((accel_m + 1, n))
    G = np.zeros((accel_m + 1, n))
    state = np.zeros(7)
    trace = np.zeros(0)
    best = np.inf
    for a in range(max_attempts):
        if a > 0:
            for i in range(n):
                if kind[i] == CONTINUOUS:
                    q[i] = -np.pi + 2.0 * np.pi * _xorshift(rng_state)
                else:
                    q[i] = lower[i] + (upper[i] - lower[i]) * _xorshift(rng_state)
        for k in range(7):
            state[k] = 0.0
        budget = min(max_sweeps, int(sweep_budget - stats[1]))
        attempt_order = order
        if order == MIXED:  # base → tip on the first attempt and every other restart, tip → base between
            attempt_order = 1 if int(stats[0]) % 2 == 0 else 0
        code, s = run(q, PR, Pt, axis, kind, TR, Tt, lower, upper, free, pstar, Rstar, w_p, w_ax, relax, attempt_order,
                      tol_pos, tol_rot, check_pos, check_rot, budget, eps_q, window, window_rel, accel_m, X, G,
                      state, trace)
        stats[0] += 1.0
        stats[1] += s
        stats[3] += state[4]
        if state[5] < best:
            best = state[5]
            best_q[:] = q
        if code == CONVERGED:
            best_q[:] = q
            stats[4] = state[5]
            return CONVERGED
        if code == STALL_STEP or code == STALL_WINDOW:  # noqa: SIM109 - plain comparisons for numba
            stats[2] += 1.0
        if stats[1] >= sweep_budget:
            stats[4] = best
            return BUDGET
    stats[4] = best
    return code
