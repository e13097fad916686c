# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""FRDM's inner loop, compiled when kinelab is installed: exact per-joint steps, sweeps, Anderson acceleration,
the Newton finish, the monitor's stall tests and the seeded multistart (docs/methods.md §1).

The arithmetic is the readable reference's (:mod:`kinelab.ik.frdm.reference`) written for speed, operation for
operation in the order kinelab 0.2's kernel computed it, so the pinned answers of the paper's FRDM are
reproduced bit for bit. Notation: e, o = joint axis and a point on it (base frame), p = tool point, R = tool
rotation (row-major 3 × 3, columns the tool axes), starred = target. Objective

    E = w_p ‖p − p*‖² + Σ_j w_j ‖u_j − u*_j‖²  (+ the rest term of the path follower).

Python reaches this module through :class:`Kernel` (one object per prepared solve: the chain, the problem,
the settings and the memory packed once) and the functions at the end; the C functions are declared in
``_frdm.pxd`` for the compiled batch and path follower.
"""

from libc.math cimport acos, atan2, cos, fabs, isfinite, sin, sqrt, INFINITY, M_PI
from libc.stdlib cimport free, malloc
from posix.time cimport clock_gettime, timespec, CLOCK_MONOTONIC
from cython.parallel cimport prange

from kinelab.core._blas cimport ddot, dgemm, dgemv, dgesv, ready
from kinelab.core._geometry cimport rotm, rotm_cs

import numpy as np

cdef double TWO_PI = 2.0 * M_PI
cdef int REFRESH_SWEEPS = 8  # sweeps carried incrementally before the chain FK is recomputed

cdef double now() noexcept nogil:
    """The monotonic clock [s]: the one ``time.perf_counter()`` reads on Linux."""
    cdef timespec ts
    clock_gettime(CLOCK_MONOTONIC, &ts)
    return <double> ts.tv_sec + <double> ts.tv_nsec * 1e-9


cdef inline double _max(double a, double b) noexcept nogil:
    """Python's max(a, b): b only when b > a."""
    return b if b > a else a


cdef inline double _min(double a, double b) noexcept nogil:
    """Python's min(a, b): b only when b < a."""
    return b if b < a else a


cdef inline void _mm(const double* A, const double* B, double* out) noexcept nogil:
    """out = A B for row-major 3 × 3 matrices."""
    cdef int r, c
    cdef double a0, a1, a2
    for r in range(3):
        a0, a1, a2 = A[3 * r], A[3 * r + 1], A[3 * r + 2]
        for c in range(3):
            out[3 * r + c] = a0 * B[c] + a1 * B[3 + c] + a2 * B[6 + c]


cdef inline void _rotate_rows(const double* m, double* R) noexcept nogil:
    """R ← M R in place."""
    cdef int c
    cdef double x, y, z
    for c in range(3):
        x, y, z = R[c], R[3 + c], R[6 + c]
        R[c] = m[0] * x + m[1] * y + m[2] * z
        R[3 + c] = m[3] * x + m[4] * y + m[5] * z
        R[6 + c] = m[6] * x + m[7] * y + m[8] * z


cdef inline void _rotate_about(const double* m, double ox, double oy, double oz, double* v) noexcept nogil:
    """v ← o + M (v − o) in place."""
    cdef double x = v[0] - ox, y = v[1] - oy, z = v[2] - oz
    v[0] = ox + m[0] * x + m[1] * y + m[2] * z
    v[1] = oy + m[3] * x + m[4] * y + m[5] * z
    v[2] = oz + m[6] * x + m[7] * y + m[8] * z


cdef inline void _turn_columns(const double* T, const double* a, double angle, double* out) noexcept nogil:
    """out = T·Rot(a, angle) (row-major 3 × 3) for the unit local axis a. About ±x, ±y or ±z (the usual joint)
    only the terms Rodrigues' product does not multiply by zero are computed: the same bits, a third of the work."""
    cdef double c = cos(angle), s = sin(angle), x, y, z, axial
    cdef double m[9]
    cdef int r, j = -1, k = 0, l = 0
    if a[0] == 0.0 and a[1] == 0.0 and (a[2] == 1.0 or a[2] == -1.0):
        j, k, l, s = 0, 1, 2, a[2] * s
    elif a[2] == 0.0 and a[0] == 0.0 and (a[1] == 1.0 or a[1] == -1.0):
        j, k, l, s = 2, 0, 1, a[1] * s
    elif a[1] == 0.0 and a[2] == 0.0 and (a[0] == 1.0 or a[0] == -1.0):
        j, k, l, s = 1, 2, 0, a[0] * s
    if j >= 0:
        axial = c + (1.0 - c)  # Rodrigues' diagonal term on the axis, rounded as the full product rounds it
        for r in range(3):
            x, y = T[3 * r + j], T[3 * r + k]
            out[3 * r + j] = x * c + y * s
            out[3 * r + k] = y * c - x * s
            out[3 * r + l] = T[3 * r + l] * axial
        return
    rotm_cs(a[0], a[1], a[2], c, s, m)
    for r in range(3):
        x, y, z = T[3 * r], T[3 * r + 1], T[3 * r + 2]
        out[3 * r] = x * m[0] + y * m[3] + z * m[6]
        out[3 * r + 1] = x * m[1] + y * m[4] + z * m[7]
        out[3 * r + 2] = x * m[2] + y * m[5] + z * m[8]


cdef void chain_fk(const Chain* ch, const double* q, double* e, double* o, double* p, double* R) noexcept nogil:
    """FK at q: joint axes e and origins o (n × 3) and the tool pose (p [m], R), all in the base frame."""
    cdef double Rw[9]
    cdef double tmp[9]
    cdef double t0 = 0.0, t1 = 0.0, t2 = 0.0, n0, n1, n2, e0, e1, e2
    cdef const double* P
    cdef const double* a
    cdef int i, r
    for r in range(9):
        Rw[r] = 1.0 if r % 4 == 0 else 0.0
    for i in range(ch.n):
        P = ch.Pt + 3 * i
        n0 = t0 + Rw[0] * P[0] + Rw[1] * P[1] + Rw[2] * P[2]
        n1 = t1 + Rw[3] * P[0] + Rw[4] * P[1] + Rw[5] * P[2]
        n2 = t2 + Rw[6] * P[0] + Rw[7] * P[1] + Rw[8] * P[2]
        t0, t1, t2 = n0, n1, n2
        _mm(Rw, ch.PR + 9 * i, tmp)
        a = ch.axis + 3 * i
        e0 = tmp[0] * a[0] + tmp[1] * a[1] + tmp[2] * a[2]
        e1 = tmp[3] * a[0] + tmp[4] * a[1] + tmp[5] * a[2]
        e2 = tmp[6] * a[0] + tmp[7] * a[1] + tmp[8] * a[2]
        if ch.kind[i] == PRISMATIC:
            t0, t1, t2 = t0 + e0 * q[i], t1 + e1 * q[i], t2 + e2 * q[i]
            for r in range(9):
                Rw[r] = tmp[r]
        else:
            # Rw ← tmp·Rot(a, q) about the exact unit local axis: the world axis e carries rounding, and a
            # rotation about it would feed that back into Rw and grow along a long chain
            _turn_columns(tmp, a, q[i], Rw)
        e[3 * i], e[3 * i + 1], e[3 * i + 2] = e0, e1, e2
        o[3 * i], o[3 * i + 1], o[3 * i + 2] = t0, t1, t2
    p[0] = t0 + Rw[0] * ch.Tt[0] + Rw[1] * ch.Tt[1] + Rw[2] * ch.Tt[2]
    p[1] = t1 + Rw[3] * ch.Tt[0] + Rw[4] * ch.Tt[1] + Rw[5] * ch.Tt[2]
    p[2] = t2 + Rw[6] * ch.Tt[0] + Rw[7] * ch.Tt[1] + Rw[8] * ch.Tt[2]
    _mm(Rw, ch.TR, R)


cdef double rotation_angle(const double* R, const double* Rstar) noexcept nogil:
    """Angle [rad] of R*ᵀR, accurate near 0 and near π (atan2 of the sine and cosine parts)."""
    cdef double M[9]
    cdef int r, c
    for r in range(3):
        for c in range(3):
            M[3 * r + c] = Rstar[r] * R[c] + Rstar[3 + r] * R[3 + c] + Rstar[6 + r] * R[6 + c]
    cdef double sx = 0.5 * (M[7] - M[5]), sy = 0.5 * (M[2] - M[6]), sz = 0.5 * (M[3] - M[1])
    cdef double cs = 0.5 * (M[0] + M[4] + M[8] - 1.0)
    return atan2(sqrt(sx * sx + sy * sy + sz * sz), cs)


cdef int within(const double* p, const double* R, const Objective* pb) noexcept nogil:
    """Both tolerances met (those checked): position [m] and rotation angle [rad] (of R*ᵀR, or with
    ``rot_axis`` ≥ 0 between that tool axis and the target's)."""
    cdef const double* S = pb.Rstar
    cdef double d0 = p[0] - pb.pstar[0], d1 = p[1] - pb.pstar[1], d2 = p[2] - pb.pstar[2]
    cdef double dp = sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    cdef int k = pb.rot_axis
    if pb.check_pos and not dp <= pb.tol_pos:
        return 0
    if not pb.check_rot:
        return 1
    if k < 0:
        return rotation_angle(R, S) <= pb.tol_rot
    cdef double c0 = R[3 + k] * S[6 + k] - R[6 + k] * S[3 + k]
    cdef double c1 = R[6 + k] * S[k] - R[k] * S[6 + k]
    cdef double c2 = R[k] * S[3 + k] - R[3 + k] * S[k]
    cdef double dot = R[k] * S[k] + R[3 + k] * S[3 + k] + R[6 + k] * S[6 + k]
    return atan2(sqrt(c0 * c0 + c1 * c1 + c2 * c2), dot) <= pb.tol_rot


cdef inline double _objective(const double* p, const double* R, const Objective* pb) noexcept nogil:
    """FRDM's weighted objective at the tool pose (p, R) (docs/methods.md §1.2)."""
    cdef double d0 = p[0] - pb.pstar[0], d1 = p[1] - pb.pstar[1], d2 = p[2] - pb.pstar[2]
    cdef double E = pb.w_p * (d0 * d0 + d1 * d1 + d2 * d2)
    cdef double u0, u1, u2
    cdef int j
    for j in range(3):
        u0 = R[j] - pb.Rstar[j]
        u1 = R[3 + j] - pb.Rstar[3 + j]
        u2 = R[6 + j] - pb.Rstar[6 + j]
        E += pb.w_ax[j] * (u0 * u0 + u1 * u1 + u2 * u2)
    return E


cdef double total_objective(const double* q, const Chain* ch, const double* p, const double* R,
                            const Objective* pb) noexcept nogil:
    """The objective plus the rest term w_rest Σ 2(1 − cos(q_i − r_i)) (revolute) + w_rest Σ (q_i − r_i)²
    (prismatic)."""
    cdef double acc = 0.0, d, rest = 0.0
    cdef int i
    if pb.w_rest != 0.0:
        for i in range(ch.n):
            d = q[i] - pb.q_rest[i]
            acc += d * d if ch.kind[i] == PRISMATIC else 2.0 * (1.0 - cos(d))
        rest = pb.w_rest * acc
    return _objective(p, R, pb) + rest


cdef inline void _bc(double e0, double e1, double e2, double o0, double o1, double o2, const double* p,
                     const double* R, const Objective* pb, double* B, double* C) noexcept nogil:
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about the line (e, o)."""
    cdef const double* ps = pb.pstar
    cdef const double* S = pb.Rstar
    cdef double r0 = p[0] - o0, r1 = p[1] - o1, r2 = p[2] - o2
    cdef double d0 = ps[0] - o0, d1 = ps[1] - o1, d2 = ps[2] - o2
    cdef double er = e0 * r0 + e1 * r1 + e2 * r2
    cdef double ed = e0 * d0 + e1 * d1 + e2 * d2
    cdef double b = pb.w_p * (d0 * r0 + d1 * r1 + d2 * r2 - ed * er)  # d⊥·r⊥
    cdef double c = pb.w_p * (e0 * (r1 * d2 - r2 * d1) + e1 * (r2 * d0 - r0 * d2) + e2 * (r0 * d1 - r1 * d0))
    cdef double w, u0, u1, u2, s0, s1, s2, eu, es
    cdef int j
    for j in range(3):
        w = pb.w_ax[j]
        if w != 0.0:
            u0, u1, u2 = R[j], R[3 + j], R[6 + j]
            s0, s1, s2 = S[j], S[3 + j], S[6 + j]
            eu = e0 * u0 + e1 * u1 + e2 * u2
            es = e0 * s0 + e1 * s1 + e2 * s2
            b += w * (s0 * u0 + s1 * u1 + s2 * u2 - es * eu)
            c += w * (e0 * (u1 * s2 - u2 * s1) + e1 * (u2 * s0 - u0 * s2) + e2 * (u0 * s1 - u1 * s0))
    B[0] = b
    C[0] = c


cdef inline double _revolute_angle(double B, double C, double lo, double hi, int continuous) noexcept nogil:
    """The exact minimiser of E(θ) over the window [lo, hi] ∋ 0 (methods.md §1.5)."""
    if B == 0.0 and C == 0.0:
        return 0.0
    cdef double t = atan2(C, B), best = 0.0, cand
    cdef int found = 0, k
    if continuous:
        return t
    for k in range(-1, 2):
        cand = t + <double> k * TWO_PI
        if lo <= cand <= hi and (not found or fabs(cand) < fabs(best)):
            best = cand
            found = 1
    if found:
        return best
    return lo if cos(lo - t) >= cos(hi - t) else hi


cdef inline void _carry_axis(const double* Rg, const double* tg, double* e, double* o) noexcept nogil:
    """Move one joint's axis (e, o) by the rigid motion (Rg, tg) of the joints stepped before it, in place."""
    cdef double e0 = Rg[0] * e[0] + Rg[1] * e[1] + Rg[2] * e[2]
    cdef double e1 = Rg[3] * e[0] + Rg[4] * e[1] + Rg[5] * e[2]
    cdef double e2 = Rg[6] * e[0] + Rg[7] * e[1] + Rg[8] * e[2]
    cdef double norm = sqrt(e0 * e0 + e1 * e1 + e2 * e2)  # keep rounding in Rg from compounding
    cdef double o0 = Rg[0] * o[0] + Rg[1] * o[1] + Rg[2] * o[2] + tg[0]
    cdef double o1 = Rg[3] * o[0] + Rg[4] * o[1] + Rg[5] * o[2] + tg[1]
    cdef double o2 = Rg[6] * o[0] + Rg[7] * o[1] + Rg[8] * o[2] + tg[2]
    e[0], e[1], e[2] = e0 / norm, e1 / norm, e2 / norm
    o[0], o[1], o[2] = o0, o1, o2


cdef inline double _slide(double e0, double e1, double e2, const double* p, const Objective* pb, double relax,
                          double off_rest) noexcept nogil:
    """A prismatic joint's exact step [m]: the position error's projection, weighed against the rest term."""
    if pb.w_p <= 0.0 and pb.w_rest <= 0.0:
        return 0.0
    cdef double along = e0 * (pb.pstar[0] - p[0]) + e1 * (pb.pstar[1] - p[1]) + e2 * (pb.pstar[2] - p[2])
    return relax * (pb.w_p * along - pb.w_rest * off_rest) / (pb.w_p + pb.w_rest)


cdef double _sweep(double* q, double* e, double* o, const Chain* ch, const Objective* pb, double* p, double* R,
                   double relax, int base_to_tip) noexcept nogil:
    """One sweep over the free joints, tip → base or base → tip; updates q, p, R in place and returns Σ|Δq_i|.

    e, o hold the axes at the sweep's starting q. Base → tip carries the rigid motion (Rg, tg) of the joints
    already stepped to the downstream axes and leaves e, o at the new q (tip → base leaves them stale).
    """
    cdef int n = ch.n, k, i, moved_any = 0
    cdef double total = 0.0, lo, hi, s, B, C, theta, step, e0, e1, e2, o0, o1, o2
    cdef double Rg[9]
    cdef double tg[3]
    cdef double m[9]
    for k in range(9):
        Rg[k] = 1.0 if k % 4 == 0 else 0.0
    tg[0] = tg[1] = tg[2] = 0.0
    for k in range(n):
        i = k if base_to_tip else n - 1 - k
        if moved_any:
            _carry_axis(Rg, tg, e + 3 * i, o + 3 * i)
        e0, e1, e2 = e[3 * i], e[3 * i + 1], e[3 * i + 2]
        o0, o1, o2 = o[3 * i], o[3 * i + 1], o[3 * i + 2]
        if not pb.free[i]:
            continue
        lo = pb.lower[i] - q[i]
        hi = pb.upper[i] - q[i]
        if ch.kind[i] == PRISMATIC:
            s = _min(_max(_slide(e0, e1, e2, p, pb, relax, q[i] - pb.q_rest[i]), lo), hi)
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
            _bc(e0, e1, e2, o0, o1, o2, p, R, pb, &B, &C)
            if pb.w_rest != 0.0:
                B += pb.w_rest * cos(q[i] - pb.q_rest[i])
                C -= pb.w_rest * sin(q[i] - pb.q_rest[i])
            theta = _revolute_angle(B, C, lo, hi, ch.kind[i] == CONTINUOUS)
            if relax != 1.0:
                theta = relax * theta
                if ch.kind[i] != CONTINUOUS:
                    theta = _min(_max(theta, lo), hi)
            if theta == 0.0:
                continue
            rotm(e0, e1, e2, theta, m)
            _rotate_about(m, o0, o1, o2, p)
            _rotate_rows(m, R)
            if base_to_tip:
                _rotate_rows(m, Rg)
                _rotate_about(m, o0, o1, o2, tg)
            step = theta
        moved_any = base_to_tip
        q[i] += step
        total += fabs(step)
    return total


cdef void _cholesky_solve(double* A, const double* rhs, double* gamma, int k, int stride) noexcept nogil:
    """gamma = A⁻¹ rhs for the symmetric positive definite leading k × k block of A (row stride ``stride``;
    A is overwritten)."""
    cdef int j, t, r
    cdef double acc
    for j in range(k):
        acc = A[j * stride + j]
        for t in range(j):
            acc -= A[j * stride + t] * A[j * stride + t]
        A[j * stride + j] = sqrt(_max(acc, 1e-300))
        for r in range(j + 1, k):
            acc = A[r * stride + j]
            for t in range(j):
                acc -= A[r * stride + t] * A[j * stride + t]
            A[r * stride + j] = acc / A[j * stride + j]
    for r in range(k):
        gamma[r] = rhs[r]
        for t in range(r):
            gamma[r] -= A[r * stride + t] * gamma[t]
        gamma[r] /= A[r * stride + r]
    for r in range(k - 1, -1, -1):
        for t in range(r + 1, k):
            gamma[r] -= A[t * stride + r] * gamma[t]
        gamma[r] /= A[r * stride + r]


cdef void _anderson(const double* X, const double* G, int count, int m, int n, const double* x, const double* g,
                    double* out, double* dG, double* dX, double* A, double* rhs, double* gamma) noexcept nogil:
    """Type-II Anderson mixing of the last ``count`` (x, g = F(x) − x) pairs into ``out``: the small
    least-squares problem min ‖g − ΔG γ‖ by a regularised Cholesky factorisation. dG, dX (m × n, one difference
    per row, so the dot products run along memory), A (m × m), rhs, gamma (m): work arrays."""
    cdef int k = count if count < m else m
    cdef int c, a, b, i, r
    cdef double trace = 0.0, acc
    for c in range(k):
        a = (count - k + c) % (m + 1)
        b = (count - k + c + 1) % (m + 1)
        for i in range(n):
            dG[c * n + i] = G[b * n + i] - G[a * n + i]
            dX[c * n + i] = X[b * n + i] - X[a * n + i]
    for r in range(k):  # the normal equations A = ΔGᵀΔG, rhs = ΔGᵀg
        acc = 0.0
        for i in range(n):
            acc += dG[r * n + i] * g[i]
        rhs[r] = acc
        for c in range(r + 1):
            acc = 0.0
            for i in range(n):
                acc += dG[r * n + i] * dG[c * n + i]
            A[r * m + c] = acc
            A[c * m + r] = acc
        trace += A[r * m + r]
    if trace <= 0.0:  # no change in the residuals: nothing to extrapolate
        for i in range(n):
            out[i] = x[i] + g[i]
        return
    for r in range(k):
        A[r * m + r] += 1e-10 * trace
    _cholesky_solve(A, rhs, gamma, k, m)
    for i in range(n):
        acc = x[i] + g[i]
        for c in range(k):
            acc -= (dX[c * n + i] + dG[c * n + i]) * gamma[c]
        out[i] = acc


cdef struct Work:
    # the arrays one run() call works in (one allocation)
    double* e
    double* o
    double* p
    double* R
    double* ec
    double* oc
    double* pc
    double* Rc
    double* x_old
    double* cand
    double* g
    double* dG
    double* dX
    double* A
    double* rhs
    double* gamma
    int m


cdef double* _work(Work* w, int n, int accel_m) noexcept nogil:
    """Carve the work arrays of a run out of one allocation (returned, for free()); NULL when out of memory."""
    cdef int m = accel_m if accel_m > 1 else 1
    cdef double* block = <double*> malloc(sizeof(double) * (4 * 3 * n + 24 + 3 * n + 2 * n * m + m * m + 2 * m))
    if block == NULL:
        return NULL
    w.m = m
    w.e, w.o, w.p, w.R = block, block + 3 * n, block + 6 * n, block + 6 * n + 3
    w.ec, w.oc = block + 6 * n + 12, block + 9 * n + 12
    w.pc, w.Rc = block + 12 * n + 12, block + 12 * n + 15
    w.x_old, w.cand, w.g = block + 12 * n + 24, block + 13 * n + 24, block + 14 * n + 24
    w.dG = block + 15 * n + 24
    w.dX = w.dG + n * m
    w.A = w.dX + n * m
    w.rhs = w.A + m * m
    w.gamma = w.rhs + m
    return block


cdef int _extrapolate(double* q, const Chain* ch, const Objective* pb, const Settings* st, Memory* mem, Work* w,
                      double E1, double* E_out) noexcept nogil:
    """Record the sweep in the history and try the Anderson extrapolation; keep it only if it lowers E.

    Returns 1 when accepted: then q and the candidate FK arrays (w.ec, w.oc, w.pc, w.Rc) hold the new state.
    E_out: the objective after this step.
    """
    cdef int n = ch.n, i
    cdef double* state = mem.state
    cdef int cnt = <int> state[S_HISTORY]
    cdef int slot = cnt % (st.accel_m + 1)
    cdef int finite = 1
    cdef double Ec
    for i in range(n):
        w.g[i] = q[i] - w.x_old[i]
        mem.X[slot * n + i] = w.x_old[i]
        mem.G[slot * n + i] = w.g[i]
    state[S_HISTORY] = cnt + 1.0
    E_out[0] = E1
    if cnt < 1:
        return 0
    _anderson(mem.X, mem.G, cnt, st.accel_m, n, w.x_old, w.g, w.cand, w.dG, w.dX, w.A, w.rhs, w.gamma)
    for i in range(n):
        finite = finite and isfinite(w.cand[i])
    if not finite:  # a degenerate history: drop it, keep the plain sweep
        state[S_HISTORY] = 0.0
        for i in range(n):
            w.cand[i] = q[i]
    for i in range(n):
        if ch.kind[i] != CONTINUOUS:
            w.cand[i] = _min(_max(w.cand[i], pb.lower[i]), pb.upper[i])
        if not pb.free[i]:
            w.cand[i] = q[i]
    chain_fk(ch, w.cand, w.ec, w.oc, w.pc, w.Rc)
    Ec = total_objective(w.cand, ch, w.pc, w.Rc, pb)
    if Ec < E1:
        for i in range(n):
            q[i] = w.cand[i]
        state[S_ACCEPTED] += 1.0
        E_out[0] = Ec
        return 1
    return 0


cdef int _finished(double* q, const Chain* ch, const Objective* pb, int steps, double* state) noexcept nogil:
    """The Newton finish, tried once per attempt: 1 (q converged, its objective in state) if Gauss–Newton steps
    from q meet the tolerances, else q is left exactly as it was and the sweeps go on."""
    cdef int n = ch.n, i, spent = 0, code
    cdef double* block = <double*> malloc(sizeof(double) * (7 * n + 12))
    if block == NULL:
        return 0
    for i in range(n):
        block[i] = q[i]
    code = lm_polish(q, ch, pb, steps, INFINITY, &spent)
    state[S_NEWTON] += spent
    if code == CONVERGED:
        state[S_FINISH] = 2.0
        chain_fk(ch, q, block + n, block + 4 * n, block + 7 * n, block + 7 * n + 3)
        state[S_E] = total_objective(q, ch, block + 7 * n, block + 7 * n + 3, pb)
    else:
        state[S_FINISH] = 1.0
        for i in range(n):
            q[i] = block[i]
    free(block)
    return code == CONVERGED


cdef inline int _converged_here(double* q, const Chain* ch, const Objective* pb, Work* w, int since_fk,
                                double* state) noexcept nogil:
    """Both tolerances met at q on an exact FK (the carried state only says where to look); then the
    objective goes into state[S_E]."""
    if not within(w.p, w.R, pb):
        return 0
    if since_fk > 0:
        chain_fk(ch, q, w.e, w.o, w.p, w.R)
        if not within(w.p, w.R, pb):
            return 0
    state[S_E] = total_objective(q, ch, w.p, w.R, pb)
    return 1


cdef inline int _finish_due(const Settings* st, const double* state) noexcept nogil:
    """The Newton finish is on, not yet tried in this attempt, and the objective at q is below its threshold."""
    cdef double E_now = state[S_E_WINDOW] if state[S_SWEEPS] == 0.0 else state[S_E]
    return st.finish_below > 0.0 and state[S_FINISH] == 0.0 and E_now < st.finish_below


cdef inline int _window_stalled(double* state, const Settings* st, double E1) noexcept nogil:
    """The monitor's window test: 1 when E fell by less than window_rel over the last window."""
    if state[S_SWEEPS] - state[S_WINDOW_START] >= st.window:
        if state[S_E_WINDOW] - E1 <= st.window_rel * state[S_E_WINDOW]:
            return 1
        state[S_E_WINDOW] = E1
        state[S_WINDOW_START] = state[S_SWEEPS]
    return 0


cdef inline int _base_to_tip(int order, double* state) noexcept nogil:
    """This sweep's direction: the order's, base → tip after a kick; clears the kick flag."""
    cdef int forward = order == BASE_TO_TIP or (order == ALTERNATE and (<long long> state[S_SWEEPS]) % 2 == 1) \
        or state[S_KICKED] != 0.0
    state[S_KICKED] = 0.0
    return forward


cdef inline void _swap(double** a, double** b) noexcept nogil:
    cdef double* t = a[0]
    a[0] = b[0]
    b[0] = t


cdef inline void _copy(double* dst, const double* src, int count) noexcept nogil:
    cdef int i
    for i in range(count):
        dst[i] = src[i]


cdef int _resume(Memory* mem, Work* w, int n, int* since_fk) noexcept nogil:
    """The held state of a cut run back into e, o, p, R; returns 1 (fresh) when there was one."""
    if mem.state[S_HELD] == 0.0:
        since_fk[0] = 0
        return 0
    _copy(w.e, mem.held, 3 * n)
    _copy(w.o, mem.held + 3 * n, 3 * n)
    _copy(w.p, mem.held + 6 * n, 3)
    _copy(w.R, mem.held + 6 * n + 3, 9)
    mem.state[S_HELD] = 0.0
    since_fk[0] = <int> mem.state[S_SINCE_FK]
    return 1


cdef void _hold(Memory* mem, Work* w, int n, int since_fk) noexcept nogil:
    """Keep the carried state of a cut run, so that resuming it repeats exactly what one run would do."""
    _copy(mem.held, w.e, 3 * n)
    _copy(mem.held + 3 * n, w.o, 3 * n)
    _copy(mem.held + 6 * n, w.p, 3)
    _copy(mem.held + 6 * n + 3, w.R, 9)
    mem.state[S_HELD] = 1.0
    mem.state[S_SINCE_FK] = since_fk


cdef int run(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
             Memory* mem, int* sweeps) noexcept nogil:
    """Sweep until converged, stalled or ``max_sweeps`` sweeps; q is updated in place. Returns the code
    (CONVERGED, STALL_STEP, STALL_WINDOW, BUDGET; −1 out of memory), the sweeps of this call in ``sweeps``;
    the state slots carry the rest."""
    cdef Work w
    cdef double* block = _work(&w, ch.n, st.accel_m)
    cdef int code = _run(q, ch, pb, st, order, max_sweeps, mem, &w, sweeps) if block != NULL else -1
    free(block)
    return code


cdef int _run(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
              Memory* mem, Work* w, int* sweeps) noexcept nogil:
    cdef double* state = mem.state
    cdef int n = ch.n, s, since_fk, fresh, base_to_tip
    cdef double moved, E1
    sweeps[0] = max_sweeps
    fresh = _resume(mem, w, n, &since_fk)
    for s in range(max_sweeps):
        sweeps[0] = s
        if not fresh or since_fk >= REFRESH_SWEEPS:
            chain_fk(ch, q, w.e, w.o, w.p, w.R)
            since_fk = 0
        if state[S_SWEEPS] == 0.0:
            state[S_E_WINDOW] = total_objective(q, ch, w.p, w.R, pb)
        if _converged_here(q, ch, pb, w, since_fk, state):
            return CONVERGED
        if _finish_due(st, state) and _finished(q, ch, pb, st.finish_steps, state):
            return CONVERGED
        _copy(w.x_old, q, n)
        base_to_tip = _base_to_tip(order, state)
        moved = _sweep(q, w.e, w.o, ch, pb, w.p, w.R, st.relax, base_to_tip)
        fresh = base_to_tip
        since_fk += 1
        E1 = total_objective(q, ch, w.p, w.R, pb)
        state[S_SWEEPS] += 1.0
        if <int> state[S_SWEEPS] - 1 < mem.trace_len:
            mem.trace[<int> state[S_SWEEPS] - 1] = E1
        sweeps[0] = s + 1
        if moved < st.eps_q:
            state[S_E] = E1
            return STALL_STEP
        if st.accel_m > 0 and _extrapolate(q, ch, pb, st, mem, w, E1, &E1):
            _swap(&w.e, &w.ec)
            _swap(&w.o, &w.oc)
            _swap(&w.p, &w.pc)
            _swap(&w.R, &w.Rc)
            fresh = 1
            since_fk = 0
        state[S_E] = E1
        if _window_stalled(state, st, E1):
            return STALL_WINDOW
    sweeps[0] = max_sweeps
    if fresh:
        _hold(mem, w, n, since_fk)
    return BUDGET


# ---- the Newton finish: damped Gauss–Newton (Levenberg–Marquardt) on the world-frame error ----

cdef void _gemm3_abt(const double* A, const double* B, double* M) noexcept nogil:
    """M = A Bᵀ (row-major 3 × 3) by BLAS, called as NumPy's matmul calls it, so the rounding is NumPy's."""
    cdef int three = 3
    cdef double one = 1.0, zero = 0.0
    cdef char t = b't', nt = b'n'
    dgemm(&t, &nt, &three, &three, &three, &one, <double*> B, &three, <double*> A, &three, &zero, M, &three)


cdef void world_error(const double* p, const double* R, const Objective* pb, double* err) noexcept nogil:
    """err = [p* − p; log(R* Rᵀ) or a* − a] with the constrained components only."""
    cdef int k, a = pb.rot_axis, r, c
    cdef double M[9]
    cdef double w[3]
    cdef double cos_a, angle, scale
    for k in range(3):
        err[k] = pb.pstar[k] - p[k] if pb.check_pos else 0.0
    if a >= 0:
        for k in range(3):
            err[3 + k] = pb.Rstar[3 * k + a] - R[3 * k + a] if pb.check_rot else 0.0
        return
    _gemm3_abt(pb.Rstar, R, M)
    cos_a = _min(1.0, _max(-1.0, (M[0] + M[4] + M[8] - 1.0) / 2.0))
    angle = acos(cos_a)
    scale = 0.5 if angle < 1e-8 else angle / (2.0 * sin(angle))
    w[0], w[1], w[2] = M[7] - M[5], M[2] - M[6], M[3] - M[1]
    for k in range(3):
        err[3 + k] = scale * w[k] if pb.check_rot else 0.0


cdef void world_jacobian(const double* e, const double* o, const double* p, const double* R, const Chain* ch,
                          const Objective* pb, double* J) noexcept nogil:
    """J (6 × n, row-major) ← the error's Jacobian (position; rotation, or the tool axis of task "axis");
    unchecked rows and the columns of frozen joints 0."""
    cdef int n = ch.n, i, k, a = pb.rot_axis
    cdef double r0, r1, r2, e0, e1, e2
    for i in range(n):
        e0, e1, e2 = e[3 * i], e[3 * i + 1], e[3 * i + 2]
        if not pb.free[i]:
            for k in range(6):
                J[k * n + i] = 0.0
        elif ch.kind[i] == PRISMATIC:
            J[i], J[n + i], J[2 * n + i] = e0, e1, e2
            J[3 * n + i] = J[4 * n + i] = J[5 * n + i] = 0.0
        else:
            r0, r1, r2 = p[0] - o[3 * i], p[1] - o[3 * i + 1], p[2] - o[3 * i + 2]
            J[i], J[n + i], J[2 * n + i] = e1 * r2 - e2 * r1, e2 * r0 - e0 * r2, e0 * r1 - e1 * r0
            if a < 0:
                J[3 * n + i], J[4 * n + i], J[5 * n + i] = e0, e1, e2
            else:
                r0, r1, r2 = R[a], R[3 + a], R[6 + a]
                J[3 * n + i], J[4 * n + i], J[5 * n + i] = e1 * r2 - e2 * r1, e2 * r0 - e0 * r2, e0 * r1 - e1 * r0
        if not pb.check_pos:
            J[i] = J[n + i] = J[2 * n + i] = 0.0
        if not pb.check_rot:
            J[3 * n + i] = J[4 * n + i] = J[5 * n + i] = 0.0


cdef int lm_polish(double* q, const Chain* ch, const Objective* pb, int iterations, double max_step,
                   int* spent) noexcept nogil:
    """Levenberg–Marquardt on the world-frame error of the constrained components, steps kept in the windows;
    ``max_step`` [rad or m] caps every step's largest joint change (a trust region: near a singular configuration
    a Gauss–Newton step can throw the arm onto another branch). Returns CONVERGED or −1, the iterations spent in
    ``spent``; q is updated in place. The linear algebra is BLAS and LAPACK's, called as NumPy calls them."""
    cdef int n = ch.n, it, i, code = -1
    cdef double largest
    cdef double p[3]
    cdef double R[9]
    cdef double err[6]
    cdef double* block = <double*> malloc(sizeof(double) * (6 * n + 6 * n + 2 * n * n + n))
    cdef int* pivots = <int*> malloc(sizeof(int) * (n if n > 0 else 1))
    if block == NULL or pivots == NULL:
        free(block)
        free(pivots)
        spent[0] = 0
        return -1
    cdef double* e = block
    cdef double* o = block + 3 * n
    cdef double* J = block + 6 * n
    cdef double* A = block + 12 * n
    cdef double* dq = A + 2 * n * n
    spent[0] = iterations
    for it in range(iterations):
        chain_fk(ch, q, e, o, p, R)
        if within(p, R, pb):
            spent[0] = it
            code = CONVERGED
            break
        world_error(p, R, pb, err)
        world_jacobian(e, o, p, R, ch, pb, J)
        if _gauss_newton_step(J, err, n, A, dq, pivots) != 0:
            break
        if max_step < INFINITY:
            largest = 0.0
            for i in range(n):
                largest = _max(largest, fabs(dq[i]))
            if largest > max_step:
                for i in range(n):
                    dq[i] *= max_step / largest
        for i in range(n):
            q[i] = _min(_max(q[i] + dq[i], pb.lower[i]), pb.upper[i])
    else:
        chain_fk(ch, q, e, o, p, R)
        if within(p, R, pb):
            code = CONVERGED
    free(block)
    free(pivots)
    return code


cdef int _gauss_newton_step(double* J, double* err, int n, double* A, double* dq, int* pivots) noexcept nogil:
    """dq = (JᵀJ + λI)⁻¹ Jᵀ err with λ = 1e-9 + 1e-3 ‖err‖² (J: 6 × n row-major; A: 2n² work values). Returns
    LAPACK's info (0: solved)."""
    cdef int six = 6, one_i = 1, info = 0, i, j
    cdef double one = 1.0, zero = 0.0, damping
    cdef char t = b't', nt = b'n'
    cdef double* F = A + n * n
    dgemm(&nt, &t, &n, &n, &six, &one, J, &n, J, &n, &zero, A, &n)
    damping = 1e-9 + 1e-3 * ddot(&six, err, &one_i, err, &one_i)
    for i in range(n):
        A[i * n + i] += damping
    for i in range(n):  # the matrix in Fortran order, as NumPy hands it to LAPACK
        for j in range(n):
            F[i + j * n] = A[i * n + j]
    dgemv(&nt, &n, &six, &one, J, &n, err, &one_i, &zero, dq, &one_i)
    dgesv(&n, &one_i, F, &n, pivots, dq, &n, &info)
    return info


# ---- the multistart ----

cdef double uniform(unsigned long long* state) noexcept nogil:
    """xorshift64*: a small seeded generator for restarts; returns a float in [0, 1)."""
    cdef unsigned long long x = state[0]
    x ^= x >> 12
    x ^= x << 25
    x ^= x >> 27
    state[0] = x
    return <double> ((x * 2685821657736338717ULL) >> 11) / 9007199254740992.0


cdef void restart_windows(const Chain* ch, const double* q, const double* pstar, const double* lower,
                          const double* upper, const unsigned char* wide, double length, double* scratch,
                          double* out_lower, double* out_upper) noexcept nogil:
    """Where restarts are drawn (:func:`kinelab.ik.multistart.restart_windows`): [lower, upper], except at a
    ``wide`` base joint, within ``length`` [m] of the value that carries the tool from where it is at q to the
    target point pstar along the joint's axis, clipped to the limits. ``scratch``: 6n + 12 doubles."""
    cdef int i, n = ch.n
    cdef double* e = scratch
    cdef double* p = scratch + 6 * n
    cdef double d0, d1, d2, centre
    chain_fk(ch, q, e, e + 3 * n, p, p + 3)
    d0, d1, d2 = pstar[0] - p[0], pstar[1] - p[1], pstar[2] - p[2]
    for i in range(n):
        out_lower[i], out_upper[i] = lower[i], upper[i]
        if wide[i]:
            centre = q[i] + (e[3 * i] * d0 + e[3 * i + 1] * d1 + e[3 * i + 2] * d2)
            out_lower[i] = _clip(centre - length, lower[i], upper[i])
            out_upper[i] = _clip(centre + length, lower[i], upper[i])


cdef inline double _clip(double x, double lower, double upper) noexcept nogil:
    """x within [lower, upper] (numpy's clip: the larger of x and lower, then the smaller of that and upper)."""
    x = lower if x < lower else x
    return upper if x > upper else x


cdef void random_configuration(double* q, const long long* kind, const double* lower, const double* upper, int n,
                               unsigned long long* rng_state) noexcept nogil:
    """q ← a seeded uniform configuration within the limits; a joint without a finite window draws on [−π, π)
    when it turns and keeps its value when it slides."""
    cdef int i
    cdef double u, span
    for i in range(n):
        u = uniform(rng_state)
        if isfinite(lower[i]) and isfinite(upper[i]) and kind[i] != CONTINUOUS:
            span = upper[i] - lower[i]
            # a window of ±1e308 overflows its width: then the same draw as a blend of the two ends
            q[i] = lower[i] + span * u if isfinite(span) else lower[i] * (1.0 - u) + upper[i] * u
        elif kind[i] != PRISMATIC:
            q[i] = -M_PI + TWO_PI * u


cdef int _polished(double* q, const Chain* ch, const Objective* pb, int iterations, double* stats,
                   Memory* mem) noexcept nogil:
    """Gauss–Newton steps from a stalled attempt's q; 1 (q converged, its objective in mem) if they meet the
    tolerances, else q is left where the attempt stalled."""
    cdef int n = ch.n, spent = 0, ok
    cdef double* block = <double*> malloc(sizeof(double) * (7 * n + 12))
    if block == NULL:
        return 0
    _copy(block, q, n)
    ok = lm_polish(q, ch, pb, iterations, INFINITY, &spent) == CONVERGED
    if ok:
        stats[T_POLISHED] += 1.0
        chain_fk(ch, q, block + n, block + 4 * n, block + 7 * n, block + 7 * n + 3)
        mem.state[S_E] = total_objective(q, ch, block + 7 * n, block + 7 * n + 3, pb)
        stats[T_BEST_E] = mem.state[S_E]
    else:
        _copy(q, block, n)
    free(block)
    return ok


cdef int multistart(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
                    unsigned long long* rng_state, int max_attempts, double sweep_budget, double* best_q,
                    double* stats, Memory* mem, double deadline) noexcept nogil:
    """Attempts from q, then from seeded uniform starts, until one converges, ``max_attempts`` have run,
    ``sweep_budget`` sweeps (a total) are spent or, after an attempt, the clock has passed ``deadline`` [s] (inf:
    never looked at); a stall ends an attempt (a restart, not a bypass).

    Called in chunks: an attempt the sweep budget cuts is resumed by the next call where it stopped (stats[T_CUT]
    = 1 meanwhile), so the answer does not depend on where the chunks end. On return q holds the converged
    configuration (or the current one), best_q the lowest-objective one. Returns a run() code.
    """
    cdef double best = stats[T_BEST_E] if stats[T_ATTEMPTS] > 0.0 or stats[T_CUT] != 0.0 else INFINITY
    cdef int code = BUDGET, done = 0, left, budget, attempt_order, s = 0, i, n = ch.n
    cdef double spare
    while done < max_attempts:
        if stats[T_CUT] == 0.0:
            if stats[T_ATTEMPTS] > 0.0:
                random_configuration(q, ch.kind, pb.lower, pb.upper, n, rng_state)
            for i in range(STATE_SIZE):
                mem.state[i] = 0.0
        stats[T_CUT] = 0.0
        left = max_sweeps - <int> mem.state[S_SWEEPS]
        spare = sweep_budget - stats[T_SWEEPS]
        budget = left if spare >= 2e9 or left < <int> spare else <int> spare
        attempt_order = order
        if order == MIXED:  # base → tip on the first attempt and every other restart, tip → base between
            attempt_order = BASE_TO_TIP if (<long long> stats[T_ATTEMPTS]) % 2 == 0 else TIP_TO_BASE
        code = run(q, ch, pb, st, attempt_order, budget, mem, &s)
        if code < 0:
            return code
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
            _copy(best_q, q, n)
        if code == CONVERGED:
            _copy(best_q, q, n)
            stats[T_BEST_E] = mem.state[S_E]
            return CONVERGED
        if code == STALL_STEP or code == STALL_WINDOW:
            stats[T_STALLS] += 1.0
            if st.polish > 0 and _polished(q, ch, pb, st.polish, stats, mem):
                _copy(best_q, q, n)
                return CONVERGED
        if stats[T_SWEEPS] >= sweep_budget or (deadline < INFINITY and now() > deadline):
            stats[T_BEST_E] = best
            return BUDGET
    stats[T_BEST_E] = best
    return code


# ---- Python's side: the kernel's arrays packed once ----

cdef object _doubles(object array, Py_ssize_t size, str name, list keep):
    """``array`` as a C-contiguous float64 array of ``size`` values, kept alive in ``keep``: the same object when
    it already is one (a caller writes a target into it in place), else a copy."""
    cdef object a = np.asarray(array, dtype=np.float64, order="C")
    if a.size != size:
        raise ValueError(f"{name}: {size} values expected, got shape {np.shape(array)}")
    keep.append(a)
    return a


cdef const double* _cptr(object a):
    cdef const double[::1] view = a.reshape(-1)
    return &view[0] if view.shape[0] else NULL


cdef double* _mptr(object a):
    cdef double[::1] view = a.reshape(-1)
    return &view[0] if view.shape[0] else NULL


cdef class Packed:
    """The C view of one solve's chain, problem, settings and memory (the NamedTuples of
    :mod:`kinelab.ik.chain` and :mod:`kinelab.ik.frdm.kernel`), packed once; the arrays stay shared, so a
    target written into the problem's ``pstar`` and ``Rstar`` in place is the next call's target."""

    def __init__(self, chain, objective, settings, memory=None):
        ready()  # the kernels' BLAS and LAPACK, loaded by the first solve of the process
        cdef int n = len(chain.kind)
        cdef list keep = []
        self.keep, self.n = keep, n
        kind = np.asarray(chain.kind, dtype=np.int64, order="C")
        if kind.shape != (n,):
            raise ValueError("chain.kind: one code per joint expected")
        keep.append(kind)
        cdef const long long[::1] kinds = kind
        self.ch.n = n
        self.ch.kind = &kinds[0] if n else NULL
        self.ch.PR = _cptr(_doubles(chain.placement_R, 9 * n, "placement_R", keep))
        self.ch.Pt = _cptr(_doubles(chain.placement_t, 3 * n, "placement_t", keep))
        self.ch.axis = _cptr(_doubles(chain.axis_local, 3 * n, "axis_local", keep))
        self.ch.TR = _cptr(_doubles(chain.tool_R, 9, "tool_R", keep))
        self.ch.Tt = _cptr(_doubles(chain.tool_t, 3, "tool_t", keep))
        self._objective(objective)
        self._settings(settings)
        self._memory(memory)

    cdef void _objective(self, pb) except *:
        cdef int n = self.n
        keep = self.keep
        self.pb.lower = _cptr(_doubles(pb.lower, n, "lower", keep))
        self.pb.upper = _cptr(_doubles(pb.upper, n, "upper", keep))
        mask = np.ascontiguousarray(pb.free, dtype=np.bool_).view(np.uint8)
        if mask.shape != (n,):
            raise ValueError("free: one flag per joint expected")
        keep.append(mask)
        cdef const unsigned char[::1] flags = mask
        self.pb.free = &flags[0] if n else NULL
        self.pb.pstar = _cptr(_doubles(pb.pstar, 3, "pstar", keep))
        self.pb.Rstar = _cptr(_doubles(pb.Rstar, 9, "Rstar", keep))
        self.pb.w_ax = _cptr(_doubles(pb.w_ax, 3, "w_ax", keep))
        self.pb.q_rest = _cptr(_doubles(pb.q_rest, n, "q_rest", keep))
        self.pb.w_p, self.pb.tol_pos, self.pb.tol_rot = pb.w_p, pb.tol_pos, pb.tol_rot
        self.pb.check_pos, self.pb.check_rot = bool(pb.check_pos), bool(pb.check_rot)
        self.pb.w_rest, self.pb.rot_axis = pb.w_rest, pb.rot_axis

    cdef void _settings(self, st) except *:
        self.st.relax, self.st.eps_q, self.st.window, self.st.window_rel = st.relax, st.eps_q, st.window, st.window_rel
        self.st.accel_m, self.st.polish = st.accel_m, st.polish
        self.st.finish_below, self.st.finish_steps = st.finish_below, st.finish_steps

    cdef void _memory(self, mem) except *:
        if mem is None:
            self.mem.X = self.mem.G = self.mem.state = self.mem.trace = self.mem.held = NULL
            return
        cdef int n = self.n, rows = self.st.accel_m + 1
        self.mem.X = _mptr(self._written(mem.X, rows * n, "X"))
        self.mem.G = _mptr(self._written(mem.G, rows * n, "G"))
        self.mem.state = _mptr(self._written(mem.state, STATE_SIZE, "state"))
        self.mem.trace_len = len(mem.trace)
        self.mem.trace = _mptr(self._written(mem.trace, self.mem.trace_len, "trace"))
        self.mem.held = _mptr(self._written(mem.held, 3 * (2 * n + 4), "held"))

    cdef object _written(self, object array, Py_ssize_t size, str name):
        """An array the kernel writes and its caller reads: it must be used as it is, never copied."""
        a = _doubles(array, size, name, self.keep)
        if a is not array:
            raise ValueError(f"{name}: a C-contiguous float64 array expected (the kernel writes into it)")
        return a

    cdef void _check(self, double[::1] q, str name) except *:
        if q.shape[0] != self.n:
            raise ValueError(f"{name}: {self.n} values expected, got {q.shape[0]}")
        if self.mem.state == NULL:
            raise ValueError("no memory given: this kernel only reads")

    cdef void _check_multistart(self, double[::1] q, double[::1] best_q, double[::1] stats,
                                unsigned long long[::1] rng_state) except *:
        self._check(q, "q")
        self._check(best_q, "best_q")
        if stats.shape[0] < STATS_SIZE or rng_state.shape[0] < 1:
            raise ValueError("stats and rng_state are too short")

    def run(self, double[::1] q, int order, int max_sweeps):
        """Sweep until converged, stalled or ``max_sweeps`` sweeps (q updated in place): (code, sweeps)."""
        self._check(q, "q")
        cdef int code, sweeps = 0
        with nogil:
            code = run(&q[0], &self.ch, &self.pb, &self.st, order, max_sweeps, &self.mem, &sweeps)
        return code, sweeps

    def multistart(self, double[::1] q, int order, int max_sweeps, unsigned long long[::1] rng_state,
                   int max_attempts, double sweep_budget, double[::1] best_q, double[::1] stats):
        """One chunk of the multistart (see ``multistart`` in the C part): returns a run() code."""
        self._check_multistart(q, best_q, stats, rng_state)
        cdef int code
        with nogil:
            code = multistart(&q[0], &self.ch, &self.pb, &self.st, order, max_sweeps, &rng_state[0], max_attempts,
                              sweep_budget, &best_q[0], &stats[0], &self.mem, INFINITY)
        return code

    def solve(self, double[::1] q, int order, int max_sweeps, unsigned long long[::1] rng_state, int attempts,
              double first_chunk, double later_chunk, double deadline, double[::1] best_q, double[::1] stats):
        """The timed multistart: a first chunk of ``first_chunk`` sweeps, then chunks of ``later_chunk`` until an
        attempt converges, ``attempts`` have run or the clock (``time.perf_counter()``'s) passes ``deadline``
        [s], looked at between chunks. Returns the last run() code."""
        self._check_multistart(q, best_q, stats, rng_state)
        cdef int code
        with nogil:
            code = timed(&q[0], &self.ch, &self.pb, &self.st, order, max_sweeps, &rng_state[0], attempts,
                          first_chunk, later_chunk, deadline, 0, &best_q[0], &stats[0], &self.mem)
        return code


cdef int timed(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
               unsigned long long* rng_state, int attempts, double first_chunk, double later_chunk, double deadline,
               int stop_before, double* best_q, double* stats, Memory* mem) noexcept nogil:
    """The multistart in chunks of sweeps, the clock looked at between them. ``stop_before``: also before the
    first chunk (the batch's rows: NOT_STARTED when the deadline passed before the row began, STOPPED when it
    passed while it ran); else the first chunk always runs (the single solve's)."""
    cdef int code = -1 if stop_before or attempts > 0 else BUDGET
    cdef double chunk = first_chunk, before
    while attempts > 0:
        if (stop_before or code != -1) and now() > deadline:
            if stop_before:
                return STOPPED if stats[T_ATTEMPTS] > 0 else NOT_STARTED
            return code
        before = stats[T_ATTEMPTS]
        code = multistart(q, ch, pb, st, order, max_sweeps, rng_state, attempts, stats[T_SWEEPS] + chunk, best_q,
                          stats, mem, deadline)
        chunk = later_chunk
        attempts -= <int> (stats[T_ATTEMPTS] - before)
        if code == CONVERGED or code < 0:
            break
    return code


def run_kernel(q, chain, objective, settings, int order, int max_sweeps, memory):
    """kinelab 0.2's ``run(q, ch, pb, st, order, max_sweeps, mem)``: (code, sweeps of this call)."""
    return Packed(chain, objective, settings, memory).run(q, order, max_sweeps)


def pack_chain(chain) -> Packed:
    """The chain packed alone (an empty problem and settings): for kernels that read only the chain."""
    return Packed(chain, _Nothing(len(chain.kind)), _Nothing(0))


class _Nothing:
    """A problem and settings with nothing in them (no target, no weights, one plain sweep setting)."""

    def __init__(self, n):
        self.lower = self.upper = self.q_rest = np.zeros(n)
        self.free = np.ones(n, dtype=np.bool_)
        self.pstar, self.Rstar, self.w_ax = np.zeros(3), np.eye(3), np.zeros(3)
        self.w_p = self.tol_pos = self.tol_rot = self.w_rest = 0.0
        self.check_pos = self.check_rot = False
        self.rot_axis = -1
        self.relax, self.eps_q, self.window, self.window_rel = 1.0, 0.0, 1, 0.0
        self.accel_m, self.polish, self.finish_below, self.finish_steps = 0, 0, 0.0, 1


def fk(chain, double[::1] q, double[:, ::1] e, double[:, ::1] o, double[::1] p, double[:, ::1] R):
    """The chain's FK at q: axes e, origins o (n × 3), tool point p [m] and rotation R (base frame), in place."""
    cdef list keep = []
    cdef int n = len(chain.kind)
    if q.shape[0] != n or e.shape[0] != n or o.shape[0] != n or e.shape[1] != 3 or o.shape[1] != 3 \
            or p.shape[0] != 3 or R.shape[0] != 3 or R.shape[1] != 3:
        raise ValueError(f"fk: q (n,), e and o (n, 3), p (3,), R (3, 3) with n = {n}")
    cdef Chain ch
    kind = np.asarray(chain.kind, dtype=np.int64, order="C")
    cdef const long long[::1] kinds = kind
    ch.n = n
    ch.kind = &kinds[0] if n else NULL
    ch.PR = _cptr(_doubles(chain.placement_R, 9 * n, "placement_R", keep))
    ch.Pt = _cptr(_doubles(chain.placement_t, 3 * n, "placement_t", keep))
    ch.axis = _cptr(_doubles(chain.axis_local, 3 * n, "axis_local", keep))
    ch.TR = _cptr(_doubles(chain.tool_R, 9, "tool_R", keep))
    ch.Tt = _cptr(_doubles(chain.tool_t, 3, "tool_t", keep))
    if n:
        chain_fk(&ch, &q[0], &e[0, 0], &o[0, 0], &p[0], &R[0, 0])
    else:
        chain_fk(&ch, NULL, NULL, NULL, &p[0], &R[0, 0])


def draw_configuration(double[::1] q, const long long[::1] kind, const double[::1] lower, const double[::1] upper,
                       unsigned long long[::1] rng_state):
    """q ← a seeded uniform configuration within [lower, upper] (the restarts' draw; the generator advances)."""
    cdef int n = q.shape[0]
    if kind.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n or rng_state.shape[0] < 1:
        raise ValueError("draw_configuration: q, kind, lower and upper of one length, and a generator state")
    if n:
        random_configuration(&q[0], &kind[0], &lower[0], &upper[0], n, &rng_state[0])


def windows_of(chain, const double[::1] q, const double[::1] pstar, const double[::1] lower,
               const double[::1] upper, const unsigned char[::1] wide, double length):
    """(lower, upper) of the restarts from the start q and the target point pstar [m] (see ``restart_windows``)."""
    cdef Packed packed = pack_chain(chain)
    cdef int n = packed.n
    if q.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n or wide.shape[0] != n or pstar.shape[0] != 3:
        raise ValueError("windows_of: q, the limits and wide one value per joint, pstar (3,)")
    out_lower, out_upper, scratch = np.empty(n), np.empty(n), np.empty(6 * n + 12)
    cdef double[::1] lo = out_lower, hi = out_upper, work = scratch
    if n:
        restart_windows(&packed.ch, &q[0], &pstar[0], &lower[0], &upper[0], &wide[0], length, &work[0], &lo[0],
                        &hi[0])
    return out_lower, out_upper


def solve_rows(double[:, ::1] Q, bint draw_start, chain, objective, const double[:, ::1] pstars,
               const double[:, :, ::1] Rstars, settings, int order, int max_sweeps,
               unsigned long long[:, ::1] rng_states, const long long[::1] attempts, double first_chunk,
               double later_chunk, double deadline, long long[::1] codes, double[:, ::1] stats, int threads):
    """Solve rows [0, B) in parallel (``threads`` OpenMP threads), each exactly as the single solve with its own
    generator state would: the same chunks, the clock looked at between them.

    Args:
        Q: (B, n) starts; on return each row's best answer [rad or m].
        draw_start: draw every start from its row's generator (the single solve's ``q0=None``).
        chain, objective, settings: as :class:`Packed` (the objective's own target is not read).
        pstars, Rstars: (B, 3) target points [m] and (B, 3, 3) rotations, base frame.
        rng_states: (B, 1) generator states; attempts: (B,) attempts per row.
        first_chunk, later_chunk: sweeps of the first chunk and of the later ones.
        deadline: a ``time.perf_counter()`` value [s] (inf: none).
        codes: (B,) out: run() code per row (NOT_STARTED, STOPPED at the deadline); stats: (B, STATS_SIZE) out.
        threads: OpenMP threads (≥ 1).
    """
    cdef Packed packed = Packed(chain, objective, settings)
    cdef Py_ssize_t B = Q.shape[0], b
    cdef int n = packed.n
    if Q.shape[1] != n or pstars.shape[0] != B or Rstars.shape[0] != B or rng_states.shape[0] != B \
            or attempts.shape[0] != B or codes.shape[0] != B or stats.shape[0] != B or stats.shape[1] < STATS_SIZE \
            or pstars.shape[1] != 3 or Rstars.shape[1] != 3 or Rstars.shape[2] != 3 or rng_states.shape[1] < 1:
        raise ValueError("solve_rows: inconsistent shapes")
    if B == 0 or n == 0:
        return
    cdef const Chain* ch = &packed.ch
    cdef const Objective* pb = &packed.pb
    cdef const Settings* st = &packed.st
    with nogil:
        for b in prange(B, num_threads=max(1, threads), schedule="dynamic"):
            codes[b] = _row(ch, pb, st, &Q[b, 0], draw_start, &pstars[b, 0], &Rstars[b, 0, 0], order, max_sweeps,
                            &rng_states[b, 0], <int> attempts[b], first_chunk, later_chunk, deadline, &stats[b, 0])


cdef int _row(const Chain* ch, const Objective* shared, const Settings* st, double* q_out, bint draw_start, const double* pstar, const double* Rstar,
              int order, int max_sweeps, unsigned long long* rng_state, int attempts, double first_chunk,
              double later_chunk, double deadline, double* stats) noexcept nogil:
    """One batch row: its own problem (the shared one with this row's target) and memory."""
    cdef int n = ch.n, rows = st.accel_m + 1, i, code
    cdef Objective pb = shared[0]
    cdef Memory mem
    cdef double* block = <double*> malloc(sizeof(double) * (2 * n + 2 * rows * n + STATE_SIZE + 3 * (2 * n + 4)))
    if block == NULL:
        return -1
    cdef double* q = block
    cdef double* best_q = block + n
    mem.X = block + 2 * n
    mem.G = mem.X + rows * n
    mem.state = mem.G + rows * n
    mem.held = mem.state + STATE_SIZE
    mem.trace = NULL
    mem.trace_len = 0
    for i in range(2 * n + 2 * rows * n + STATE_SIZE + 3 * (2 * n + 4)):
        block[i] = 0.0
    for i in range(STATS_SIZE):
        stats[i] = 0.0
    pb.pstar = pstar
    pb.Rstar = Rstar
    _copy(q, q_out, n)
    if draw_start:
        random_configuration(q, ch.kind, pb.lower, pb.upper, n, rng_state)
    _copy(best_q, q, n)
    code = timed(q, ch, &pb, st, order, max_sweeps, rng_state, attempts, first_chunk, later_chunk,
                  deadline, 1, best_q, stats, &mem)
    _copy(q_out, best_q, n)
    free(block)
    return code


def revolute_bc(const double[::1] e, const double[::1] o, const double[::1] p, const double[:, :] R,
                const double[::1] pstar, const double[:, :] Rstar, double w_p, const double[::1] w_ax):
    """(B, C) of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about the line (e, o) (docs/methods.md §1.3)."""
    cdef Objective pb
    cdef double Rc[9]
    cdef double Sc[9]
    cdef double B, C
    cdef int i, j
    if e.shape[0] != 3 or o.shape[0] != 3 or p.shape[0] != 3 or pstar.shape[0] != 3 or w_ax.shape[0] != 3 \
            or R.shape[0] != 3 or R.shape[1] != 3 or Rstar.shape[0] != 3 or Rstar.shape[1] != 3:
        raise ValueError("revolute_bc: 3-vectors and 3 × 3 rotations expected")
    for i in range(3):
        for j in range(3):
            Rc[3 * i + j], Sc[3 * i + j] = R[i, j], Rstar[i, j]
    pb.pstar, pb.Rstar, pb.w_p, pb.w_ax = &pstar[0], Sc, w_p, &w_ax[0]
    _bc(e[0], e[1], e[2], o[0], o[1], o[2], &p[0], Rc, &pb, &B, &C)
    return B, C


def sweep_once(double[::1] q, double[:, ::1] e, double[:, ::1] o, const long long[::1] kind,
               const double[::1] lower, const double[::1] upper, const unsigned char[::1] free, double[::1] p,
               double[:, ::1] R, const double[::1] pstar, const double[:, ::1] Rstar, double w_p,
               const double[::1] w_ax, double relax, bint base_to_tip, const double[::1] q_rest,
               double w_rest) -> float:
    """One FRDM sweep over the free joints (``free`` a bool array's ``view(np.uint8)``), tip → base or base → tip,
    from the axes e, o and tool pose p, R at q: q, p, R (and e, o base → tip) updated in place; returns Σ|Δq_i|."""
    cdef int n = q.shape[0]
    if e.shape[0] != n or o.shape[0] != n or kind.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n \
            or free.shape[0] != n or q_rest.shape[0] != n or p.shape[0] != 3 or pstar.shape[0] != 3 \
            or w_ax.shape[0] != 3 or n == 0:
        raise ValueError("sweep_once: one value per joint, (n, 3) axes and points, 3-vectors, 3 × 3 rotations")
    cdef Chain ch
    cdef Objective pb
    ch.n, ch.kind = n, &kind[0]
    pb.lower, pb.upper, pb.free, pb.pstar, pb.Rstar = &lower[0], &upper[0], &free[0], &pstar[0], &Rstar[0, 0]
    pb.w_p, pb.w_ax, pb.q_rest, pb.w_rest = w_p, &w_ax[0], &q_rest[0], w_rest
    return _sweep(&q[0], &e[0, 0], &o[0, 0], &ch, &pb, &p[0], &R[0, 0], relax, base_to_tip)
