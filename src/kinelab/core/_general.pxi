# The general 6R elimination, compiled (included by _analytic.pyx): the same steps as
# kinelab.ik.analytic.general.solve and its Newton polish, one pose at a time, with no Python in between.
#
# The arm's prepared data come packed in one array (general.packed, layout G_* below). Per pose: T' and the right
# side's 14 invariants at nine sample pairs (r₀, Q), Q's SVD (its left null space N and pseudo-inverse), the six
# equations' 12 × 12 matrix quadratic as a 24 × 24 pencil, LAPACK's QZ (dggev) with right eigenvectors, and for
# each eigenvalue within CLOSE_PAIR of the real line θ₃, θ₄, θ₅ from it and its eigenvector, θ₁, θ₂ from Q's
# pseudo-inverse, θ₆ from the rotation left, then Newton's method on the loop equations (_loop.pxd). The set's
# certificate (eigenvalue condition numbers, Kantorovich's test) is not computed here: the caller computes it
# when it is asked for (kinelab.ik.analytic.branches.certificate_of).

from kinelab.core._blas cimport dgecon, dgeev, dgesdd, dgetrf, dggev, ready
from kinelab.core._loop cimport loop_row
from libc.math cimport isfinite, sqrt

cdef enum:
    GENERAL_6R = 100  # the class code (kinelab.ik.analytic.kernel.GENERAL_6R)
    G_PHI = 0  # the offsets φ (6)
    G_G0I = 6  # G₀⁻¹ (4 × 4, row-major)
    G_G6I = 22  # G₆⁻¹
    G_FRAMES = 38  # G₁ … G₅ (5 × 4 × 4)
    G_LEFT = 118  # P's coefficients of 1, cos θ₃, sin θ₃ over x₄ⁱx₅ʲ (3 × 14 × 9)
    G_ONE = 496  # the constant monomial's row (9)
    G_RR = 505  # Rz(−b)·G₁⁻¹·Rz(−a) at the nine sample pairs: rotations (9 × 3 × 3)
    G_RT = 586  # and translations (9 × 3)
    G_FOURIER = 613  # samples → Fourier coefficients of two joints (9 × 9)
    G_TRIG = 694  # (1, c, s)⊗(1, c, s) → x₄ⁱx₅ʲ over (1 + x₄²)(1 + x₅²) (9 × 9)
    G_SCALE = 775  # the loop equations' length scale ℓ [m]
    GENERAL_SIZE = 776
    PENCIL = 24
    GGEV_WORK = 1536
    SVD_WORK = 1024
    POLISH_STEPS = 60  # as kinelab.ik.analytic.certify.MAX_STEPS
    STALLS = 3  # Newton steps in a row that do not shrink the residual before the polish stops

cdef double CLOSE_PAIR = 1e-6  # [chordal] an eigenvalue this near the real line may be a real root (general.py)
cdef double RANK_MARGIN = 1e-9  # Q's smallest singular value over its largest below which no root is given
cdef double SEPARATION = 1e-3  # [chordal] eigenvalues closer than this: their null vectors from QZ's eigenvectors
cdef double NEAR_REAL = 1e-3  # [chordal] the eigenvalues :func:`_crowded` looks at: within this of the real line
cdef double COMPANION_RCOND = 1e-6  # the x₃² coefficient's reciprocal condition above which the companion serves


cdef void _mm4(const double* A, const double* B, double* C) noexcept nogil:
    """C = A·B, 4 × 4 row-major (C not aliasing A or B)."""
    cdef int i, j
    for i in range(4):
        for j in range(4):
            C[4 * i + j] = A[4 * i] * B[j] + A[4 * i + 1] * B[4 + j] + A[4 * i + 2] * B[8 + j] + A[4 * i + 3] * B[12 + j]


cdef void _turned(double* M, double theta, const double* G, double* scratch) noexcept nogil:
    """M ← M·Rz(θ)·G (4 × 4 row-major)."""
    cdef double c = cos(theta), s = sin(theta), a, b
    cdef int i
    for i in range(4):
        a, b = M[4 * i], M[4 * i + 1]
        M[4 * i], M[4 * i + 1] = a * c + b * s, b * c - a * s
    _mm4(M, G, scratch)
    for i in range(16):
        M[i] = scratch[i]


cdef void _invariants(const double* l, const double* p, double* out) noexcept nogil:
    """Raghavan and Roth's 14 invariants of the line (l, p) (general.invariants)."""
    cdef double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2], pl = p[0] * l[0] + p[1] * l[1] + p[2] * l[2]
    cdef int a
    for a in range(3):
        out[a], out[3 + a], out[11 + a] = p[a], l[a], pp * l[a] - 2.0 * pl * p[a]
    out[6], out[7] = pp, pl
    out[8], out[9], out[10] = p[1] * l[2] - p[2] * l[1], p[2] * l[0] - p[0] * l[2], p[0] * l[1] - p[1] * l[0]


cdef void _right_side(const double* g, const double* H, double* Tp, double* r0, double* Q) noexcept nogil:
    """T' = G₀⁻¹·H·G₆⁻¹, r₀ (14) and Q (14 × 8, column-major) of the pose H (general._right)."""
    cdef double tmp[16]
    cdef double inv[9 * 14]
    cdef double l[3]
    cdef double p[3]
    cdef double v
    cdef int s, a, k, e
    _mm4(g + G_G0I, H, tmp)
    _mm4(tmp, g + G_G6I, Tp)
    for s in range(9):
        for a in range(3):
            l[a] = p[a] = 0.0
            for k in range(3):
                l[a] += g[G_RR + 9 * s + 3 * a + k] * Tp[4 * k + 2]
                p[a] += g[G_RR + 9 * s + 3 * a + k] * Tp[4 * k + 3]
            p[a] += g[G_RT + 3 * s + a]
        _invariants(l, p, inv + 14 * s)
    for k in range(9):
        for e in range(14):
            v = 0.0
            for s in range(9):
                v += g[G_FOURIER + 9 * k + s] * inv[14 * s + e]
            if k == 0:
                r0[e] = v
            else:
                Q[e + 14 * (k - 1)] = v


cdef double _null_and_pinv(double* Q, double* N, double* pinv) noexcept nogil:
    """From Q (14 × 8, column-major; overwritten): N (6 × 14, row-major) its left null space, pinv (8 × 14,
    row-major) its pseudo-inverse; returns the smallest singular value over the largest (0 when the SVD fails)."""
    cdef double U[196]
    cdef double VT[64]
    cdef double s[8]
    cdef double work[SVD_WORK]
    cdef int iwork[64]
    cdef int m = 14, n = 8, lwork = SVD_WORK, info = 0, r, e, k, j
    cdef char jobz = b'A'
    dgesdd(&jobz, &m, &n, Q, &m, s, U, &m, VT, &n, work, &lwork, iwork, &info)
    if info != 0 or not s[0] > 0.0:
        return 0.0
    for r in range(6):
        for e in range(14):
            N[14 * r + e] = U[e + 14 * (8 + r)]
    for k in range(8):
        for e in range(14):
            pinv[14 * k + e] = 0.0
            for j in range(8):
                pinv[14 * k + e] += VT[j + 8 * k] / s[j] * U[e + 14 * j]
    return s[7] / s[0]


cdef void _quadratic(const double* g, const double* N, const double* r0, double* M) noexcept nogil:
    """The six equations times x₄ as a 12 × 12 matrix quadratic in x₃: M (3 × 12 × 12, row-major), the coefficients
    of x₃², x₃ and 1 (general._pencil)."""
    cdef double E[3 * 54]
    cdef double nr
    cdef int c, r, n, e, i
    for c in range(3):
        for r in range(6):
            for n in range(9):
                E[54 * c + 9 * r + n] = 0.0
                for e in range(14):
                    E[54 * c + 9 * r + n] += N[14 * r + e] * g[G_LEFT + 126 * c + 9 * e + n]
    for r in range(6):
        nr = 0.0
        for e in range(14):
            nr += N[14 * r + e] * r0[e]
        for n in range(9):
            E[9 * r + n] -= nr * g[G_ONE + n]
    for i in range(3 * 144):
        M[i] = 0.0
    for r in range(6):
        for n in range(9):  # in the rows of x₄⁰ and (shifted) x₄¹
            M[12 * r + n] = M[12 * (r + 6) + n + 3] = E[9 * r + n] - E[54 + 9 * r + n]
            M[144 + 12 * r + n] = M[144 + 12 * (r + 6) + n + 3] = 2.0 * E[108 + 9 * r + n]
            M[288 + 12 * r + n] = M[288 + 12 * (r + 6) + n + 3] = E[9 * r + n] + E[54 + 9 * r + n]


cdef void _pencil(const double* M, double* A, double* B) noexcept nogil:
    """The quadratic M linearised: the 24 × 24 pencil (A, B), column-major, whose eigenvalues are x₃."""
    cdef int i, j
    for i in range(PENCIL * PENCIL):
        A[i] = B[i] = 0.0
    for i in range(12):
        A[i + PENCIL * (12 + i)] = 1.0
        B[i + PENCIL * i] = 1.0
        for j in range(12):
            A[12 + i + PENCIL * j] = -M[288 + 12 * i + j]
            A[12 + i + PENCIL * (12 + j)] = -M[144 + 12 * i + j]
            B[12 + i + PENCIL * (12 + j)] = M[12 * i + j]


cdef void _lu_solve(const double* L, const int* pivots, double* X, int n, int rhs) noexcept nogil:
    """X ← A⁻¹X for dgetrf's factors L of A (n × n) and X (n × rhs), both column-major. Written out rather than
    LAPACK's dgetrs: OpenBLAS runs its own getrs on threads whose hand-over costs more than these few hundred
    flops (and competes with the batch's threads)."""
    cdef int i, j, k
    for k in range(rhs):
        for i in range(n):  # the row interchanges, in dgetrf's order
            j = pivots[i] - 1
            if j != i:
                X[i + n * k], X[j + n * k] = X[j + n * k], X[i + n * k]
        for i in range(n):  # L (unit lower)
            for j in range(i):
                X[i + n * k] -= L[i + n * j] * X[j + n * k]
        for i in range(n - 1, -1, -1):  # U
            for j in range(i + 1, n):
                X[i + n * k] -= L[i + n * j] * X[j + n * k]
            X[i + n * k] /= L[i + n * i]


cdef bint _null_vector(const double* M, double a, double b, double* w) noexcept nogil:
    """w (12): the null vector of the quadratic M at x₃ = a/b, a²·M(x₃²) + ab·M(x₃) + b²·M(1), by one step of
    inverse iteration: LU with partial pivoting (LAPACK), a pivot below a rounding of the matrix's scale raised to
    it (the matrix is singular to rounding: its last pivot is often exactly 0); False when LAPACK fails."""
    cdef double S[144]
    cdef int pivots[12]
    cdef int n = 12, info = 0, i, j
    cdef double largest = 0.0, floor
    for i in range(12):
        w[i] = 1.0 + 0.1 * i  # a fixed start: along any null vector but for a set of measure zero
        for j in range(12):  # column-major for LAPACK
            S[i + 12 * j] = a * a * M[12 * i + j] + a * b * M[144 + 12 * i + j] + b * b * M[288 + 12 * i + j]
            largest = max(largest, fabs(S[i + 12 * j]))
    dgetrf(&n, &n, S, &n, pivots, &info)
    if info < 0 or not largest > 0.0:
        return False
    floor = 1e-15 * largest
    for i in range(12):
        if fabs(S[13 * i]) < floor:
            S[13 * i] = -floor if S[13 * i] < 0.0 else floor
    _lu_solve(S, pivots, w, 12, 1)
    return True


cdef double _half_angle(const double* v, int count) noexcept nogil:
    """The angle θ [rad] of v proportional to (1, x, x², …), x = tan(θ/2), from its best-scaled pair."""
    cdef int k, best = 0
    for k in range(1, count - 1):
        if fabs(v[k]) + fabs(v[k + 1]) > fabs(v[best]) + fabs(v[best + 1]):
            best = k
    return 2.0 * atan2(v[best + 1], v[best])


cdef (double, double) _wrist(const double* w) noexcept nogil:
    """θ₄, θ₅ [rad] from the null vector w (12: x₄ⁱx₅ʲ, i ≤ 3, j ≤ 2), its rank-one factors read from its largest
    column and row."""
    cdef double u[4]
    cdef double v[3]
    cdef int k, i, col = 0, row = 0
    cdef double size, cb = -1.0, rb = -1.0
    for k in range(3):
        size = fabs(w[k]) + fabs(w[3 + k]) + fabs(w[6 + k]) + fabs(w[9 + k])
        if size > cb:
            cb, col = size, k
    for i in range(4):
        size = fabs(w[3 * i]) + fabs(w[3 * i + 1]) + fabs(w[3 * i + 2])
        if size > rb:
            rb, row = size, i
    for i in range(4):
        u[i] = w[3 * i + col]
    for k in range(3):
        v[k] = w[3 * row + k]
    return _half_angle(u, 4), _half_angle(v, 3)


cdef void _shoulder_and_tool(const double* g, const double* r0, const double* pinv, const double* Tp,
                             double* t) noexcept nogil:
    """θ₁, θ₂ and θ₆ [rad] into t[0], t[1], t[5] from θ₃, θ₄, θ₅ in t[2:5] (general._shoulder_and_tool)."""
    cdef double m4[3]
    cdef double m5[3]
    cdef double m45[9]
    cdef double rhs[14]
    cdef double m12[8]
    cdef double M[16]
    cdef double scratch[16]
    cdef double c3 = cos(t[2]), s3 = sin(t[2])
    cdef int i, j, e, k
    m4[0], m4[1], m4[2], m5[0], m5[1], m5[2] = 1.0, cos(t[3]), sin(t[3]), 1.0, cos(t[4]), sin(t[4])
    for j in range(9):
        m45[j] = 0.0
        for i in range(9):
            m45[j] += m4[i // 3] * m5[i % 3] * g[G_TRIG + 9 * i + j]
    for e in range(14):
        rhs[e] = -r0[e]
        for j in range(9):
            rhs[e] += (g[G_LEFT + 9 * e + j] + c3 * g[G_LEFT + 126 + 9 * e + j]
                       + s3 * g[G_LEFT + 252 + 9 * e + j]) * m45[j]
    for k in range(8):
        m12[k] = 0.0
        for e in range(14):
            m12[k] += pinv[14 * k + e] * rhs[e]
    t[0], t[1] = atan2(m12[5], m12[2]), atan2(m12[1], m12[0])
    for i in range(16):
        M[i] = 1.0 if i % 5 == 0 else 0.0
    for k in range(5):
        _turned(M, t[k], g + G_FRAMES + 16 * k, scratch)
    t[5] = atan2(M[1] * Tp[0] + M[5] * Tp[4] + M[9] * Tp[8], M[0] * Tp[0] + M[4] * Tp[4] + M[8] * Tp[8])


cdef struct Chain:
    # the loop equations' chain (_loop.pxd): the arm's axes and points, its tool at q = 0, the length scale
    const double* h
    const double* o
    double R0[9]
    double N0[3]
    double scale


cdef double _residual(const Chain* c, const double* H, const double* q, double* F, double* J) noexcept nogil:
    """‖F‖ of the loop equations at q (F, J written; J column-major, as dgesv takes it)."""
    cdef double rows[36]
    cdef double size = 0.0
    cdef int i, j
    loop_row(c.h, c.o, c.R0, c.N0, c.scale, q, H, F, rows, 6)
    for i in range(6):
        size += F[i] * F[i]
        for j in range(6):
            J[i + 6 * j] = rows[6 * i + j]
    return sqrt(size)


cdef void _polish(const Chain* c, const double* H, double* q) noexcept nogil:
    """Newton's method on the loop equations from q (6) [rad], kept at its smallest residual, at most POLISH_STEPS
    steps, stopping at a residual below 1e-15 or after STALLS steps in a row that do not shrink it (beside a double
    root Newton's method only halves the error a step, and rounding can stall it for a step: certify.polish
    steps on while any root of the pose improves)."""
    cdef double x[6]
    cdef double F[6]
    cdef double J[36]
    cdef int pivots[6]
    cdef int six = 6, info = 0, step, k, stalled = 0
    cdef double low = _residual(c, H, q, F, J), size
    for k in range(6):
        x[k] = q[k]
    for step in range(POLISH_STEPS):
        if not low >= 1e-15 or not isfinite(F[0]):  # converged to rounding, or lost
            return
        dgetrf(&six, &six, J, &six, pivots, &info)
        if info != 0:
            return
        _lu_solve(J, pivots, F, 6, 1)
        for k in range(6):
            x[k] -= F[k]
        size = _residual(c, H, x, F, J)
        if size < low:
            low, stalled = size, 0
            for k in range(6):
                q[k] = x[k]
        else:
            stalled += 1
            if stalled >= STALLS:
                return


cdef int general_6r(const Arm* arm, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every real root of the pose (Rt, pt) (in the solved orientation) the elimination finds, polished, written
    into ``rows``; returns the rows written (none when Q's rank margin is below RANK_MARGIN or LAPACK fails: the
    caller's Python route then says why)."""
    cdef const double* g = arm.general
    cdef double H[16]
    cdef double Tp[16]
    cdef double r0[14]
    cdef double Q[112]
    cdef double N[84]
    cdef double pinv[112]
    cdef double M[3 * 144]
    cdef double x3[2 * PENCIL]
    cdef double w[PENCIL * 12]
    cdef double t[6]
    cdef int k, j, m, row = 0
    cdef Chain c
    c.h, c.o, c.scale = arm.h, arm.o, g[G_SCALE]
    c.R0[0], c.R0[1], c.R0[2], c.R0[3], c.R0[4], c.R0[5], c.R0[6], c.R0[7], c.R0[8] = arm.R0
    c.N0[0], c.N0[1], c.N0[2] = arm.N0
    H[0], H[1], H[2], H[3] = Rt[0], Rt[1], Rt[2], pt[0]
    H[4], H[5], H[6], H[7] = Rt[3], Rt[4], Rt[5], pt[1]
    H[8], H[9], H[10], H[11] = Rt[6], Rt[7], Rt[8], pt[2]
    H[12], H[13], H[14], H[15] = 0.0, 0.0, 0.0, 1.0
    _right_side(g, H, Tp, r0, Q)
    if not _null_and_pinv(Q, N, pinv) >= RANK_MARGIN:
        return 0
    _quadratic(g, N, r0, M)
    m = _real_eigenvalues(M, x3, w)
    for j in range(m):
        t[2] = 2.0 * atan2(x3[2 * j], x3[2 * j + 1])
        t[3], t[4] = _wrist(w + 12 * j)
        _shoulder_and_tool(g, r0, pinv, Tp, t)
        for k in range(6):
            t[k] += g[G_PHI + k]
        _polish(&c, H, t)
        row = _write(rows, row, t[0], t[1], t[2], t[3], t[4], t[5], False)
    return row


cdef int _real_eigenvalues(const double* M, double* x3, double* w) noexcept nogil:
    """The eigenvalues of the quadratic M within CLOSE_PAIR of the real line (chordal), each as the real unit pair
    (a, b), x₃ = a/b (∞ allowed), into x3 (2 × 24), and the null vector of M there (12 each) into w (24 × 12);
    returns how many (none when LAPACK fails). Where the x₃² coefficient is well conditioned (:func:`_companion`)
    the eigenvalues are the companion matrix's (LAPACK ``dgeev``, a third faster), else the pencil's by QZ
    (``dggev``, infinite eigenvalues included), no eigenvectors; each null vector by inverse iteration
    (:func:`_null_vector`). Where an eigenvalue near the real line lies within SEPARATION of another (:func:`_crowded`),
    inverse iteration at one cannot tell its null vector from the other's (the computed eigenvalue is off by more
    than they are apart, relatively): the pose is solved again by QZ with right eigenvectors (:func:`_with_vectors`)."""
    cdef double A[PENCIL * PENCIL]
    cdef double B[PENCIL * PENCIL]
    cdef double alphar[PENCIL]
    cdef double alphai[PENCIL]
    cdef double beta[PENCIL]
    cdef double work[GGEV_WORK]
    cdef double dummy[1]
    cdef int picked[PENCIL]
    cdef int n = PENCIL, one = 1, lwork = GGEV_WORK, info = 0, j, m, kept = 0
    cdef char no = b'N'
    if _companion(M, A):
        dgeev(&no, &no, &n, A, &n, alphar, alphai, dummy, &one, dummy, &one, work, &lwork, &info)
        for j in range(PENCIL):
            beta[j] = 1.0
    else:
        _pencil(M, A, B)
        dggev(&no, &no, &n, A, &n, B, &n, alphar, alphai, beta, dummy, &one, dummy, &one, work, &lwork, &info)
    if info != 0:
        return 0
    m = _near_real(alphar, alphai, beta, x3, picked, CLOSE_PAIR)
    if _crowded(alphar, alphai, beta):
        return _with_vectors(M, x3, w)
    for j in range(m):
        if _null_vector(M, x3[2 * j], x3[2 * j + 1], w + 12 * kept):
            x3[2 * kept], x3[2 * kept + 1] = x3[2 * j], x3[2 * j + 1]
            kept += 1
    return kept


cdef int _with_vectors(const double* M, double* x3, double* w) noexcept nogil:
    """:func:`_real_eigenvalues` by QZ with right eigenvectors (``dggev``): each null vector is its eigenvector's
    first or second half (the one nearer in scale: x₃ times the first), turned real by its largest entry's phase.
    Eigenvalues as far as NEAR_REAL from the real line are taken: at a double root the pair comes out complex by
    more than CLOSE_PAIR (the Python route takes it by its perturbation bound); both start Newton from the same
    point, and the two merged answers send the pose to the Python route, which splits or flags them."""
    cdef double A[PENCIL * PENCIL]
    cdef double B[PENCIL * PENCIL]
    cdef double VR[PENCIL * PENCIL]
    cdef double alphar[PENCIL]
    cdef double alphai[PENCIL]
    cdef double beta[PENCIL]
    cdef double work[GGEV_WORK]
    cdef double dummy[1]
    cdef int picked[PENCIL]
    cdef int n = PENCIL, one = 1, lwork = GGEV_WORK, info = 0, j, m
    cdef char no = b'N', yes = b'V'
    _pencil(M, A, B)
    dggev(&no, &yes, &n, A, &n, B, &n, alphar, alphai, beta, dummy, &one, VR, &n, work, &lwork, &info)
    if info != 0:
        return 0
    m = _near_real(alphar, alphai, beta, x3, picked, NEAR_REAL)
    for j in range(m):
        _real_vector(VR, alphai, picked[j], 0 if fabs(x3[2 * j]) <= fabs(x3[2 * j + 1]) else 12, w + 12 * j)
    return m


cdef void _real_vector(const double* VR, const double* alphai, int j, int off, double* w) noexcept nogil:
    """w (12): entries off … off + 11 of eigenvector j (LAPACK packs a complex pair's as two real columns: the
    real and imaginary parts, the second vector the conjugate), times the conjugate phase of its largest entry,
    real part."""
    cdef double re[12]
    cdef double im[12]
    cdef double best = -1.0
    cdef int k, big = 0
    for k in range(12):
        if alphai[j] == 0.0:
            re[k], im[k] = VR[off + k + PENCIL * j], 0.0
        elif alphai[j] > 0.0:
            re[k], im[k] = VR[off + k + PENCIL * j], VR[off + k + PENCIL * (j + 1)]
        else:
            re[k], im[k] = VR[off + k + PENCIL * (j - 1)], -VR[off + k + PENCIL * j]
        if hypot(re[k], im[k]) > best:
            best, big = hypot(re[k], im[k]), k
    for k in range(12):
        w[k] = (re[k] * re[big] + im[k] * im[big]) / best


cdef bint _crowded(const double* alphar, const double* alphai, const double* beta) noexcept nogil:
    """Whether an eigenvalue within NEAR_REAL of the real line (chordal) lies within SEPARATION (chordal:
    |a_j b_k − a_k b_j| of unit pairs) of another eigenvalue: two close real roots, which the companion matrix may
    even give as a complex pair farther than CLOSE_PAIR from the real line (its rounding is amplified by the
    leading coefficient's condition number; QZ on the pencil is not)."""
    cdef int j, k
    cdef double nj, nk, re, im
    for j in range(PENCIL):
        nj = hypot(hypot(alphar[j], alphai[j]), beta[j])
        if not nj > 0.0 or fabs(alphai[j] * beta[j]) / (nj * nj) > NEAR_REAL:
            continue
        for k in range(PENCIL):
            if k == j:
                continue
            nk = hypot(hypot(alphar[k], alphai[k]), beta[k])
            re = (alphar[j] * beta[k] - alphar[k] * beta[j]) / (nj * nk)
            im = (alphai[j] * beta[k] - alphai[k] * beta[j]) / (nj * nk)
            if hypot(re, im) < SEPARATION:
                return True
    return False


cdef int _near_real(const double* alphar, const double* alphai, const double* beta, double* x3,
                    int* picked, double within) noexcept nogil:
    """The homogeneous eigenvalues (α, β) within ``within`` of the real line (chordal), turned real by the larger
    one's phase and scaled to unit length, into x3, their indices into ``picked``; returns how many."""
    cdef int j, m = 0
    cdef double norm, size, a, b
    for j in range(PENCIL):
        size = hypot(alphar[j], alphai[j])
        norm = hypot(size, beta[j])
        if not norm > 0.0 or fabs(alphai[j] * beta[j]) / (norm * norm) > within:
            continue
        if size > fabs(beta[j]):
            a, b = size, beta[j] * alphar[j] / size
        else:
            a, b = (alphar[j] if beta[j] >= 0 else -alphar[j]), fabs(beta[j])
        x3[2 * m], x3[2 * m + 1], picked[m] = a / norm, b / norm, j
        m += 1
    return m


cdef bint _companion(const double* M, double* C) noexcept nogil:
    """C (24 × 24, column-major) = [[0, I], [−M₂⁻¹M₀, −M₂⁻¹M₁]] with M₂, M₁, M₀ the x₃², x₃, 1 coefficients, when
    M₂'s reciprocal condition number (LAPACK's estimate) is at least COMPANION_RCOND; False otherwise."""
    cdef double L[144]
    cdef double X[288]
    cdef double work[48]
    cdef int iwork[12]
    cdef int pivots[12]
    cdef int n = 12, info = 0, i, j
    cdef char one_norm = b'1'
    cdef double anorm = 0.0, column, rcond = 0.0
    for j in range(12):
        column = 0.0
        for i in range(12):
            L[i + 12 * j] = M[12 * i + j]
            X[i + 12 * j] = M[288 + 12 * i + j]
            X[i + 12 * (12 + j)] = M[144 + 12 * i + j]
            column += fabs(M[12 * i + j])
        anorm = max(anorm, column)
    dgetrf(&n, &n, L, &n, pivots, &info)
    if info != 0:
        return False
    dgecon(&one_norm, &n, L, &n, &anorm, &rcond, work, iwork, &info)
    if info != 0 or not rcond >= COMPANION_RCOND:
        return False
    _lu_solve(L, pivots, X, 12, 24)
    for i in range(PENCIL * PENCIL):
        C[i] = 0.0
    for i in range(12):
        C[i + PENCIL * (12 + i)] = 1.0
        for j in range(PENCIL):
            C[12 + i + PENCIL * j] = -X[i + 12 * j]
    return True


def general_roots(const double[::1] general, const double[:, ::1] h, const double[:, ::1] o, const double[:, :] R0,
                  const double[:] N0, const double[:, :] H):
    """The general elimination's roots of the pose H (4 × 4, base frame, the chain unmirrored) as the compiled
    kernel writes them before the limits: (m, 6) [rad] in (−π, π], roots within SAME of one another merged
    (for tests against kinelab.ik.analytic.general)."""
    cdef double raw[RAW_ROWS * 6]
    cdef unsigned char loose[RAW_ROWS]
    cdef long long hits[RAW_ROWS]
    cdef double lim[6]
    cdef Rows rows
    cdef Arm arm
    cdef int m, k
    if general.shape[0] != GENERAL_SIZE or h.shape[0] != 6 or o.shape[0] != 6 or H.shape[0] != 4 or H.shape[1] != 4:
        raise ValueError(f"general_roots: packed data ({GENERAL_SIZE}), h and o (6, 3), H (4, 4)")
    ready()
    for k in range(6):
        lim[k] = 0.0
    arm = _arm(GENERAL_6R, False, h, o, R0, N0, lim, lim, 1e-5, 0.0, &general[0])
    rows.out, rows.free, rows.hits, rows.n, rows.cap, rows.same, rows.dropped = raw, loose, hits, 6, RAW_ROWS, 1e-5, 0
    m = general_6r(&arm, _rotation_of(H), (H[0, 3], H[1, 3], H[2, 3]), &rows)
    return np.array([[raw[6 * k + j] for j in range(6)] for k in range(m)]).reshape(m, 6)
