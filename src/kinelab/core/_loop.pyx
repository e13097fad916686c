# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The loop equations of a revolute chain and their Jacobian, compiled (:mod:`kinelab.ik.analytic.certify`): the
certificates, Newton's polish and the splitting of close roots evaluate them several times per root.

The chain is a product of exponentials at q = 0 (base frame): unit axes h_i through points o_i, the tool at
(R0, N0). For a target H (4 × 4) the six equations are F = ((p − p*)/ℓ, ½ Σ_k R*e_k × R e_k) and their Jacobian's
column j is (ω_j × (p − o_j)/ℓ, ½(ω_j tr(R*ᵀR) − R R*ᵀ ω_j)), ω_j and o_j axis j and its point as the joints
before it carry them.
"""

from kinelab.core._geometry cimport rotm


def equations(const double[:, ::1] h, const double[:, ::1] o, const double[:, ::1] R0, const double[::1] N0,
              double scale, const double[:, ::1] q, const double[:, ::1] H, double[:, ::1] F,
              double[:, :, ::1] J):
    """F (m, 6) and J (m, 6, n) of the loop equations at the rows of q (m, n ≤ 8) [rad], written in place."""
    cdef Py_ssize_t m = q.shape[0], n = q.shape[1], row
    if n > MAX_JOINTS or h.shape[0] != n or o.shape[0] != n or H.shape[0] != 4 or H.shape[1] != 4 \
            or F.shape[0] != m or F.shape[1] != 6 or J.shape[0] != m or J.shape[1] != 6 or J.shape[2] != n:
        raise ValueError(f"equations: at most {MAX_JOINTS} joints, h and o (n, 3), H (4, 4), F (m, 6), J (m, 6, n)")
    with nogil:
        for row in range(m):
            loop_row(&h[0, 0], &o[0, 0], &R0[0, 0], &N0[0], scale, &q[row, 0], &H[0, 0], &F[row, 0], &J[row, 0, 0],
                     <int> n)


cdef void loop_row(const double* h, const double* o, const double* R0, const double* N0, double scale,
                   const double* q, const double* H, double* F, double* J, int n) noexcept nogil:
    """F (6,) and J (6 × n, row-major) of the chain (h, o: n × 3 row-major; R0 3 × 3; N0) at q for the target H
    (4 × 4, row-major)."""
    cdef double R[9]
    cdef double turn[9]
    cdef double nxt[9]
    cdef double t[3]
    cdef double d[3]
    cdef double w[MAX_JOINTS][3]
    cdef double at[MAX_JOINTS][3]
    cdef double Rt[9]
    cdef double p[3]
    cdef double M[9]
    cdef int k, a, b
    cdef double trace = 0.0
    for a in range(9):
        R[a] = 1.0 if a % 4 == 0 else 0.0
    t[0] = t[1] = t[2] = 0.0
    for k in range(n):
        _carried(R, t, h + 3 * k, o + 3 * k, w[k], at[k])
        rotm(h[3 * k], h[3 * k + 1], h[3 * k + 2], q[k], turn)
        for a in range(3):  # o_k − turn·o_k, carried by R
            d[a] = o[3 * k + a] - (turn[3 * a] * o[3 * k] + turn[3 * a + 1] * o[3 * k + 1] + turn[3 * a + 2] * o[3 * k + 2])
        for a in range(3):
            t[a] += R[3 * a] * d[0] + R[3 * a + 1] * d[1] + R[3 * a + 2] * d[2]
        for a in range(3):
            for b in range(3):
                nxt[3 * a + b] = R[3 * a] * turn[b] + R[3 * a + 1] * turn[3 + b] + R[3 * a + 2] * turn[6 + b]
        for a in range(9):
            R[a] = nxt[a]
    for a in range(3):
        for b in range(3):
            Rt[3 * a + b] = R[3 * a] * R0[b] + R[3 * a + 1] * R0[3 + b] + R[3 * a + 2] * R0[6 + b]
        p[a] = R[3 * a] * N0[0] + R[3 * a + 1] * N0[1] + R[3 * a + 2] * N0[2] + t[a]
        F[a] = (p[a] - H[4 * a + 3]) / scale
    _half_cross_sum(Rt, H, F)
    for a in range(3):
        for b in range(3):
            trace += H[4 * a + b] * Rt[3 * a + b]
            M[3 * a + b] = Rt[3 * a] * H[4 * b] + Rt[3 * a + 1] * H[4 * b + 1] + Rt[3 * a + 2] * H[4 * b + 2]
    for k in range(n):
        for a in range(3):
            d[a] = p[a] - at[k][a]
        J[k] = (w[k][1] * d[2] - w[k][2] * d[1]) / scale
        J[n + k] = (w[k][2] * d[0] - w[k][0] * d[2]) / scale
        J[2 * n + k] = (w[k][0] * d[1] - w[k][1] * d[0]) / scale
        for a in range(3):
            J[(3 + a) * n + k] = 0.5 * (w[k][a] * trace - (M[3 * a] * w[k][0] + M[3 * a + 1] * w[k][1]
                                                          + M[3 * a + 2] * w[k][2]))


cdef inline void _carried(const double* R, const double* t, const double* h, const double* o, double* w,
                          double* at) noexcept nogil:
    """Axis h and its point o as the joints before carry them (rotation R, translation t)."""
    cdef int a
    for a in range(3):
        w[a] = R[3 * a] * h[0] + R[3 * a + 1] * h[1] + R[3 * a + 2] * h[2]
        at[a] = R[3 * a] * o[0] + R[3 * a + 1] * o[1] + R[3 * a + 2] * o[2] + t[a]


cdef inline void _half_cross_sum(const double* Rt, const double* H, double* F) noexcept nogil:
    """F[3:6] = ½ Σ_k (column k of H's rotation) × (column k of Rt)."""
    cdef int k
    F[3] = F[4] = F[5] = 0.0
    for k in range(3):
        F[3] += 0.5 * (H[4 + k] * Rt[6 + k] - H[8 + k] * Rt[3 + k])
        F[4] += 0.5 * (H[8 + k] * Rt[k] - H[k] * Rt[6 + k])
        F[5] += 0.5 * (H[k] * Rt[3 + k] - H[4 + k] * Rt[k])
