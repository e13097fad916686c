# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""All the branches of one pose in closed form, compiled, for the arms of the analytic classes
(docs/analytic.md): the canonical subproblems (Paden–Kahan, in the form of Elias & Wen's IK-Geo) and the
classes' decompositions.

Each subproblem solves one rotation about a unit axis k [rad]:

- subproblem 1: the angle θ with R(k, θ)·p₁ = p₂ (p₁, p₂ with the same component along k);
- subproblem 4: the angles θ with hᵀ·R(k, θ)·p = d (none, one double root, or two);
- subproblem 3, the angles θ with ‖R(k, θ)·p₁ − p₂‖ = d, is subproblem 4 with h = p₂ and
  d' = (‖p₁‖² + ‖p₂‖² − d²)/2, and is written that way where it is used.

Degenerate cases are reported, not guessed: subproblem 1 when p₁ lies on k (every θ serves), subproblem 4 when
hᵀ·R(k, θ)·p does not depend on θ.

The chain is written as a product of exponentials at q = 0, everything in the base frame: unit axes h_i, points
o_i on them, the tool's rotation R0 and point N0. With R = R_target·R0ᵀ and v the target point less what the last
joints carry, the parallel triple leaves joint 1 one scalar equation (subproblem 4), the wrist angles follow from
the orientation (subproblems 4 and 1), the sum θ₂ + θ₃ + θ₄ from the rotation left over (subproblem 1), and the
planar elbow from a distance (subproblem 3) and an angle (subproblem 1). A spherical wrist (axes 4, 5, 6 meeting
at w) with h₂ ∥ h₃ is solved the classical way: the target fixes the wrist point, which joints 1–3 alone move;
the rotation left for the wrist gives joint 5 (subproblem 4), then joints 4 and 6 (subproblem 1 each). With axes
1 and 2 meeting at s instead, the wrist point's distance from s fixes joint 3 (subproblem 3) and the turn of
joints 1 and 2 onto it is subproblem 4 for joint 1, then subproblem 1 for joint 2. With h₁ ∥ h₂ and h₃ ∥ h₄ ∥ h₅
(a turning platform carrying a planar arm) the rotation is R(h₁, θ₁)·R(h₃, θ₃)·R(h₆, q₆) with θ₁ = q₁ ± q₂ and
θ₃ = q₃ ± q₄ ± q₅.

Rows hold angles in (−π, π], one row per root combination; ``free`` marks rows where a subproblem was degenerate
and its angle was set to 0 (a continuum of answers: a wrist or shoulder singularity). Vectors are C tuples of 3
numbers and rotations of 9 (row by row): they live in registers.
"""

import numpy as np
cimport numpy as cnp

from libc.math cimport acos, atan2, cos, fabs, hypot, remainder, rint, sin, INFINITY, M_PI, NAN
from libc.stdlib cimport free as release, malloc
from cython.parallel cimport prange

from kinelab.core._chain cimport Judge
from kinelab.core._frdm cimport now
from kinelab.core._geometry cimport rotm, wrap
from kinelab.core._verdict cimport pose_defect_of, pose_defect_row_major, pose_errors

cnp.import_array()

ctypedef (double, double, double) V3
ctypedef (double, double, double, double, double, double, double, double, double) M9
ctypedef (int, double, double) Roots  # (count, θ₁, θ₂)
ctypedef (int, double) Angle  # (status, θ)

cdef enum:
    DEGENERATE = -1  # every angle serves (the caller picks one and marks the answer a continuum)
    MAX_ROWS = 16  # distinct branches of a pose (a cuspidal 6R has up to 16)
    RAW_ROWS = 32  # distinct roots a class writes before the caller places them (coincident ones merge as written)
    GROWN_ROWS = 512  # the room a pose gets when RAW_ROWS was not enough (a continuum sampled at many points)
    PARALLEL_5R = 0
    PARALLEL_6R = 1
    SPHERICAL_6R = 2
    MEETING_6R = 3
    TWO_THREE_6R = 4
    NOT_STARTED = 2  # a batch's near[b]: the pose was not started before the deadline

ROW_NOT_STARTED = NOT_STARTED  # for Python: a batch row left when the deadline passed (its near[b])
cdef double TANGENT_SLACK = 1e-9  # |cos| above 1 by this much is a double root met to rounding, beyond it no root
cdef double FLAT = 1e-12  # a length below this is treated as zero
cdef double SINGULAR_WRIST = 1e-6  # [rad] q5's two roots closer than twice this are the singular wrist's double root
cdef double TWO_PI = 2.0 * M_PI


cdef inline V3 row3(const double* a, int i) noexcept nogil:
    return (a[3 * i], a[3 * i + 1], a[3 * i + 2])


cdef inline double dot3(V3 a, V3 b) noexcept nogil:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


cdef inline V3 cross3(V3 a, V3 b) noexcept nogil:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


cdef inline V3 sub3(V3 a, V3 b) noexcept nogil:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


cdef inline V3 add3(V3 a, V3 b) noexcept nogil:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


cdef inline V3 scale3(V3 a, double s) noexcept nogil:
    return (a[0] * s, a[1] * s, a[2] * s)


cdef inline V3 mv(M9 M, V3 v) noexcept nogil:
    return (M[0] * v[0] + M[1] * v[1] + M[2] * v[2], M[3] * v[0] + M[4] * v[1] + M[5] * v[2],
            M[6] * v[0] + M[7] * v[1] + M[8] * v[2])


cdef inline V3 mtv(M9 M, V3 v) noexcept nogil:
    return (M[0] * v[0] + M[3] * v[1] + M[6] * v[2], M[1] * v[0] + M[4] * v[1] + M[7] * v[2],
            M[2] * v[0] + M[5] * v[1] + M[8] * v[2])


cdef inline M9 mm(M9 A, M9 B) noexcept nogil:
    return (A[0] * B[0] + A[1] * B[3] + A[2] * B[6], A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
            A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
            A[3] * B[0] + A[4] * B[3] + A[5] * B[6], A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
            A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
            A[6] * B[0] + A[7] * B[3] + A[8] * B[6], A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
            A[6] * B[2] + A[7] * B[5] + A[8] * B[8])


cdef inline M9 transpose(M9 M) noexcept nogil:
    return (M[0], M[3], M[6], M[1], M[4], M[7], M[2], M[5], M[8])


cdef inline M9 rotation(V3 k, double theta) noexcept nogil:
    """R(k, θ): rotation by θ [rad] about the unit axis k (Rodrigues), row by row."""
    cdef double m[9]
    rotm(k[0], k[1], k[2], theta, m)
    return (m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8])


cdef inline double _max(double a, double b) noexcept nogil:
    return b if b > a else a


cdef inline double _min(double a, double b) noexcept nogil:
    return b if b < a else a


cdef Angle sp1(V3 k, V3 p1, V3 p2) noexcept nogil:
    """Subproblem 1: (status, θ) with R(k, θ)·p₁ = p₂ in the plane normal to k; status DEGENERATE (θ = 0) when p₁
    or p₂ lies on k, else 1 (the least-squares angle when their lengths across k differ)."""
    cdef double cos_part = dot3(p1, p2) - dot3(k, p1) * dot3(k, p2)
    cdef double sin_part = dot3(k, cross3(p1, p2))
    if hypot(cos_part, sin_part) < FLAT:
        return (DEGENERATE, 0.0)
    return (1, atan2(sin_part, cos_part))


cdef (double, double) sp4_range(V3 h, V3 k, V3 p) noexcept nogil:
    """(centre, half-width) of the values hᵀ·R(k, θ)·p takes over θ (subproblem 4's reachable d)."""
    cdef double kp = dot3(k, p)
    return (dot3(h, k) * kp, hypot(dot3(h, p) - dot3(h, k) * kp, dot3(h, cross3(k, p))))


cdef Roots sp4(V3 h, V3 k, V3 p, double d) noexcept nogil:
    """Subproblem 4: (count, θ₁, θ₂) with hᵀ·R(k, θ)·p = d: count 2 (θ₁ = θ₂ at a double root), 0 when |d − c₀|
    exceeds √(a² + b²) by more than TANGENT_SLACK relatively, or DEGENERATE when a = b = 0."""
    cdef double kp = dot3(k, p)
    cdef double a = dot3(h, p) - dot3(h, k) * kp
    cdef double b = dot3(h, cross3(k, p))
    cdef double r = hypot(a, b), x, phi, alpha
    if r < FLAT:
        return (DEGENERATE, 0.0, 0.0)
    x = (d - dot3(h, k) * kp) / r
    if fabs(x) > 1.0:
        if fabs(x) - 1.0 > TANGENT_SLACK:
            return (0, 0.0, 0.0)
        x = 1.0 if x > 0 else -1.0
    phi = atan2(b, a)
    alpha = acos(x)
    return (2, phi + alpha, phi - alpha)


cdef inline Roots _one_if_double(Roots r) noexcept nogil:
    """Subproblem 4's roots with two closer than 2·SINGULAR_WRIST made one (their midpoint): the double root of a
    singular wrist, whose two answers are one continuum."""
    if r[0] == 2 and fabs(wrap(r[1] - r[2])) < 2.0 * SINGULAR_WRIST:
        return (1, r[1] - 0.5 * wrap(r[1] - r[2]), r[2])
    return r


cdef struct Rows:
    # where a class writes its rows: (cap, n) angles, their flags and how many roots each row stands for
    double* out
    unsigned char* free
    long long* hits
    int n
    int cap
    double same  # [rad] a root this close to a written row, joint by joint modulo 2π, is that row
    int dropped  # distinct roots that found no room (the caller then grows the room and solves again)


cdef inline int _write(Rows* rows, int row, double q1, double q2, double q3, double q4, double q5, double q6,
                       bint flag) noexcept nogil:
    """The angles wrapped into (−π, π] (q6 ignored on a 5-joint arm) as row ``row``, or counted towards the row they
    equal (a root the search detects several times is one row); returns the next row. A distinct root with no room
    left is counted in ``rows.dropped``, never lost silently."""
    cdef double r[6]
    cdef int k, j
    r[0], r[1], r[2], r[3], r[4], r[5] = wrap(q1), wrap(q2), wrap(q3), wrap(q4), wrap(q5), wrap(q6)
    for k in range(row):
        if _close(r, rows.out + rows.n * k, rows.n, rows.same):
            rows.hits[k] += 1
            rows.free[k] = rows.free[k] or flag
            return row
    if row >= rows.cap:
        rows.dropped += 1
        return row
    for j in range(rows.n):
        rows.out[rows.n * row + j] = r[j]
    rows.free[row], rows.hits[row] = flag, 1
    return row + 1


cdef (int, double, double, double, double) _planar_pair(V3 ha, V3 hb, V3 pa, V3 pb, V3 v) noexcept nogil:
    """The two (qa, qb) with R(ha, qa)·(pa + R(hb, qb)·pb) = v, ha ∥ hb (a planar elbow): qb by subproblem 3,
    then qa by subproblem 1; (count, qa₁, qb₁, qa₂, qb₂), count 0 when ‖v‖ is out of the elbow's reach."""
    cdef Roots r = sp4(pa, hb, pb, 0.5 * (dot3(v, v) - dot3(pa, pa) - dot3(pb, pb)))
    if r[0] <= 0:
        return (0, 0.0, 0.0, 0.0, 0.0)
    cdef Angle qa1 = sp1(ha, add3(pa, mv(rotation(hb, r[1]), pb)), v)
    cdef Angle qa2 = sp1(ha, add3(pa, mv(rotation(hb, r[2]), pb)), v)
    return (2, qa1[1], r[1], qa2[1], r[2])


cdef (bint, double) _free_sum(V3 h2, V3 h3, V3 c, V3 p23, V3 p34, V3 p45) noexcept nogil:
    """(found, θ₂₃₄) for a wrist in a continuum: the elbow meets ‖δ‖ with δ = c − R(h₂, θ₂₃₄)·p₄₅, so θ₂₃₄ is
    chosen where ‖δ‖² sits mid-way in the range both the elbow and the turn of p₄₅ reach."""
    cdef (double, double) e = sp4_range(p23, h3, p34)
    cdef (double, double) f = sp4_range(c, h2, p45)
    cdef double base_elbow = dot3(p34, p34) + dot3(p23, p23)
    cdef double base_turn = dot3(c, c) + dot3(p45, p45)
    cdef double lo = _max(base_elbow + 2.0 * (e[0] - e[1]), base_turn - 2.0 * (f[0] + f[1]))
    cdef double hi = _min(base_elbow + 2.0 * (e[0] + e[1]), base_turn - 2.0 * (f[0] - f[1]))
    if lo > hi + TANGENT_SLACK * _max(1.0, fabs(hi)):
        return (False, 0.0)
    cdef Roots r = sp4(c, h2, p45, 0.5 * (base_turn - 0.5 * (lo + hi)))
    if r[0] == DEGENERATE:  # p45 along h2: every θ₂₃₄ gives the same δ
        return (True, 0.0)
    return (r[0] > 0, r[1])


cdef (int, double, double, bint) _shoulder(const double* h, const double* o, V3 v) noexcept nogil:
    """The roots of joint 1 (subproblem 4 on the component along h₂) and whether joint 1 is free."""
    cdef V3 h2 = row3(h, 1)
    cdef Roots r = sp4(v, row3(h, 0), h2, dot3(h2, sub3(row3(o, 4), row3(o, 0))))
    if r[0] == DEGENERATE:  # the wrist point on joint 1's axis: every q1 serves
        return (1, 0.0, 0.0, True)
    return (r[0], r[1], r[2], False)


cdef int _elbow(const double* h, const double* o, double q1, M9 R1, M9 R06, V3 v, M9 R_rest, double w0, double w1,
                int nwrist, double spin, Rows* rows, int row, bint flag) noexcept nogil:
    """Rows for one (q1, wrist) pair: θ₂₃₄ from R₁ᵀ·R·R_restᵀ, then θ₃ (two roots) and θ₂; returns the next row.

    The wrist angles (w0,) or (w0, w1) (``nwrist``) go after q1..q4. ``spin`` ≠ 0 marks a wrist in a continuum
    whose last angle turns the tool about h₂ with this sign: θ₂₃₄ is then free, chosen where the elbow reaches,
    and the last wrist angle takes up the difference.
    """
    cdef V3 h2 = row3(h, 1), h3 = row3(h, 2), h4 = row3(h, 3)
    cdef double s3 = 1.0 if dot3(h3, h2) > 0 else -1.0
    cdef double s4 = 1.0 if dot3(h4, h2) > 0 else -1.0
    cdef M9 R234 = mm(mm(transpose(R1), R06), transpose(R_rest))
    cdef V3 x = (1.0, 0.0, 0.0) if fabs(h2[0]) < 0.9 else (0.0, 1.0, 0.0)
    x = sub3(x, scale3(h2, dot3(h2, x)))
    cdef double t234 = sp1(h2, x, mv(R234, x))[1]
    cdef V3 p23 = sub3(row3(o, 2), row3(o, 1)), p34 = sub3(row3(o, 3), row3(o, 2)), p45 = sub3(row3(o, 4), row3(o, 3))
    cdef V3 c = sub3(mtv(R1, v), sub3(row3(o, 1), row3(o, 0)))
    cdef double last = w1 if nwrist == 2 else w0, q2, q3, q4
    cdef (bint, double) chosen
    cdef int i
    if spin != 0.0:
        chosen = _free_sum(h2, h3, c, p23, p34, p45)
        if not chosen[0]:
            return row
        last += spin * (t234 - chosen[1])
        t234 = chosen[1]
        R234 = rotation(h2, t234)
    cdef (int, double, double, double, double) pair = _planar_pair(h2, h3, p23, p34, sub3(c, mv(R234, p45)))
    for i in range(pair[0]):
        q2, q3 = (pair[1], pair[2]) if i == 0 else (pair[3], pair[4])
        q4 = s4 * (t234 - q2 - s3 * q3)
        if nwrist == 2:
            row = _write(rows, row, q1, q2, q3, q4, w0, last, flag)
        else:
            row = _write(rows, row, q1, q2, q3, q4, last, 0.0, flag)
    return row


cdef int parallel_6r(const double* h, const double* o, M9 R0, V3 N0, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every branch of a 6R arm with h₂ ∥ h₃ ∥ h₄ and axes 5 and 6 meeting at o[4] = o[5]; returns the row count."""
    cdef M9 R06 = mm(Rt, transpose(R0)), R1, R5
    cdef V3 v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 5))))
    cdef (int, double, double, bint) s = _shoulder(h, o, v)
    cdef V3 h2 = row3(h, 1), h5 = row3(h, 4), h6 = row3(h, 5), R1h2
    cdef int row = 0, i1, i5
    cdef double q1, q5, t6, spin
    cdef Roots r5
    cdef Angle a6
    for i1 in range(s[0] if s[0] > 0 else 0):
        q1 = s[1] if i1 == 0 else s[2]
        R1 = rotation(row3(h, 0), q1)
        R1h2 = mv(R1, h2)
        r5 = _one_if_double(sp4(h2, h5, h6, dot3(R1h2, mv(R06, h6))))  # a double root: h₆ ∥ h₂, q6 joins θ₂₃₄
        for i5 in range((r5[0] if r5[0] > 0 else 0) if r5[0] != DEGENERATE else 1):
            q5 = (r5[1] if i5 == 0 else r5[2]) if r5[0] != DEGENERATE else 0.0
            R5 = rotation(h5, q5)
            a6 = sp1(h6, mtv(R5, h2), mtv(R06, R1h2))
            t6 = a6[1]
            spin = 0.0
            if r5[0] != 2:  # a wrist in a continuum: q6 = 0 to start, then the elbow's choice of θ₂₃₄ sets it
                t6, spin = 0.0, (1.0 if dot3(mv(R5, h6), h2) > 0 else -1.0)
            row = _elbow(h, o, q1, R1, R06, v, mm(R5, rotation(h6, -t6)), q5, -t6, 2, spin, rows, row,
                         s[3] or a6[0] == DEGENERATE or r5[0] != 2)
    return row


cdef int parallel_5r(const double* h, const double* o, M9 R0, V3 N0, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every branch of a 5R arm with h₂ ∥ h₃ ∥ h₄ (a pose asks six numbers of five joints: the caller keeps the
    rows Pinocchio confirms); returns the row count."""
    cdef M9 R06 = mm(Rt, transpose(R0)), R1
    cdef V3 v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 4))))
    cdef (int, double, double, bint) s = _shoulder(h, o, v)
    cdef V3 h2 = row3(h, 1), h5 = row3(h, 4)
    cdef int row = 0, i1
    cdef double q1
    cdef Angle a5
    for i1 in range(s[0] if s[0] > 0 else 0):
        q1 = s[1] if i1 == 0 else s[2]
        R1 = rotation(row3(h, 0), q1)
        a5 = sp1(h5, h2, mtv(R06, mv(R1, h2)))
        row = _elbow(h, o, q1, R1, R06, v, rotation(h5, -a5[1]), -a5[1], 0.0, 1, 0.0, rows, row,
                     s[3] or a5[0] == DEGENERATE)
    return row


cdef int _spherical_wrist(const double* h, M9 Rw, double q1, double q2, double q3, Rows* rows, int row,
                          bint flag) noexcept nogil:
    """Rows for joints 4–6 turning the rotation Rw = R₄R₅R₆ (after q1, q2, q3); returns the next row. With the
    wrist singular (q5's double root) q4 + q6 is a continuum: q4 = 0 and the row is flagged."""
    cdef V3 h4 = row3(h, 3), h5 = row3(h, 4), h6 = row3(h, 5)
    cdef Roots r5 = _one_if_double(sp4(h4, h5, h6, dot3(h4, mv(Rw, h6))))
    cdef int i5
    cdef double q5
    cdef M9 R5
    cdef Angle a4, a6
    for i5 in range(r5[0] if r5[0] > 0 else 0):
        q5 = r5[1] if i5 == 0 else r5[2]
        R5 = rotation(h5, q5)
        a4 = sp1(h4, mv(R5, h6), mv(Rw, h6))
        a6 = sp1(h6, h5, mtv(mm(rotation(h4, a4[1]), R5), mv(Rw, h5)))
        row = _write(rows, row, q1, q2, q3, a4[1], q5, a6[1], flag or a4[0] == DEGENERATE or r5[0] == 1)
    return row


cdef int spherical_6r(const double* h, const double* o, M9 R0, V3 N0, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every branch of a 6R arm with h₂ ∥ h₃ and axes 4, 5, 6 meeting at o[3] = o[4] = o[5]; returns the row
    count."""
    cdef M9 R06 = mm(Rt, transpose(R0)), R1, R3, Rw
    cdef V3 w0 = row3(o, 3)
    cdef V3 v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, w0)))
    cdef (int, double, double, bint) s = _shoulder(h, o, v)
    cdef V3 h2 = row3(h, 1), h3 = row3(h, 2), c
    cdef V3 p12 = sub3(row3(o, 1), row3(o, 0)), p23 = sub3(row3(o, 2), row3(o, 1)), p3w = sub3(w0, row3(o, 2))
    cdef int row = 0, i1, i3
    cdef double q1, q3
    cdef Roots r3
    cdef Angle a2
    for i1 in range(s[0] if s[0] > 0 else 0):
        q1 = s[1] if i1 == 0 else s[2]
        R1 = rotation(row3(h, 0), q1)
        c = sub3(mtv(R1, v), p12)  # the wrist point seen from axis 2's point, before joint 1
        r3 = sp4(p23, h3, p3w, 0.5 * (dot3(c, c) - dot3(p23, p23) - dot3(p3w, p3w)))
        if r3[0] <= 0:
            continue
        for i3 in range(2):
            q3 = r3[1] if i3 == 0 else r3[2]
            R3 = rotation(h3, q3)
            a2 = sp1(h2, add3(p23, mv(R3, p3w)), c)
            Rw = mm(transpose(mm(mm(R1, rotation(h2, a2[1])), R3)), R06)
            row = _spherical_wrist(h, Rw, q1, a2[1], q3, rows, row, s[3] or a2[0] == DEGENERATE)
    return row


cdef int meeting_6r(const double* h, const double* o, M9 R0, V3 N0, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every branch of a 6R arm with axes 1 and 2 meeting at o[0] = o[1] and axes 4, 5, 6 meeting at
    o[3] = o[4] = o[5]; returns the row count."""
    cdef M9 R06 = mm(Rt, transpose(R0)), R1, R3, Rw
    cdef V3 s = row3(o, 0), w0 = row3(o, 3)
    cdef V3 v = sub3(sub3(pt, mv(R06, sub3(N0, w0))), s)  # the wrist point seen from the shoulder point
    cdef V3 a = sub3(row3(o, 2), s), b = sub3(w0, row3(o, 2)), u
    cdef V3 h1 = row3(h, 0), h2 = row3(h, 1), h3 = row3(h, 2)
    cdef Roots r3 = sp4(a, h3, b, 0.5 * (dot3(v, v) - dot3(a, a) - dot3(b, b))), r1
    cdef int row = 0, i1, i3
    cdef bint free1
    cdef double q1, q3
    cdef Angle a2
    if r3[0] <= 0:
        return row
    for i3 in range(2):
        q3 = r3[1] if i3 == 0 else r3[2]
        R3 = rotation(h3, q3)
        u = add3(a, mv(R3, b))
        r1 = sp4(v, h1, h2, dot3(h2, u))  # joint 2 keeps the component of u along h2
        free1 = r1[0] == DEGENERATE
        for i1 in range((r1[0] if r1[0] > 0 else 0) if not free1 else 1):
            q1 = (r1[1] if i1 == 0 else r1[2]) if not free1 else 0.0
            R1 = rotation(h1, q1)
            a2 = sp1(h2, u, mtv(R1, v))
            Rw = mm(transpose(mm(mm(R1, rotation(h2, a2[1])), R3)), R06)
            row = _spherical_wrist(h, Rw, q1, a2[1], q3, rows, row, free1 or a2[0] == DEGENERATE)
    return row


cdef int _planar_three(const double* h, const double* o, V3 v, double t3, double q1, double q2, double q6,
                       Rows* rows, int row, bint flag) noexcept nogil:
    """Rows for joints 3–5 (parallel) reaching v = R₃(p₃₄ + R₄ p₄₅) with q₃ ± q₄ ± q₅ = t3, after (q1, q2, q6);
    returns the next row."""
    cdef V3 h3 = row3(h, 2), h4 = row3(h, 3)
    cdef double s4 = 1.0 if dot3(h4, h3) > 0 else -1.0
    cdef double s5 = 1.0 if dot3(row3(h, 4), h3) > 0 else -1.0
    cdef V3 p34 = sub3(row3(o, 3), row3(o, 2)), p45 = sub3(row3(o, 4), row3(o, 3))
    cdef (int, double, double, double, double) pair = _planar_pair(h3, h4, p34, p45, v)
    cdef int i
    cdef double q3, q4
    for i in range(pair[0]):
        q3, q4 = (pair[1], pair[2]) if i == 0 else (pair[3], pair[4])
        row = _write(rows, row, q1, q2, q3, q4, s5 * (t3 - q3 - s4 * q4), q6, flag)
    return row


cdef int two_three_6r(const double* h, const double* o, M9 R0, V3 N0, M9 Rt, V3 pt, Rows* rows) noexcept nogil:
    """Every branch of a 6R arm with h₁ ∥ h₂ and h₃ ∥ h₄ ∥ h₅; returns the row count."""
    cdef M9 R06 = mm(Rt, transpose(R0)), R3s, R15
    cdef V3 h1 = row3(h, 0), h3 = row3(h, 2), h6 = row3(h, 5), w, v
    cdef double s2 = 1.0 if dot3(row3(h, 1), h1) > 0 else -1.0, t3, phi
    cdef V3 p12 = sub3(row3(o, 1), row3(o, 0)), p56 = sub3(row3(o, 5), row3(o, 4))
    cdef V3 rest = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 5))))
    cdef Roots r3 = _one_if_double(sp4(h1, h3, h6, dot3(h1, mv(R06, h6)))), r2
    cdef Angle a1, a6
    cdef int row = 0, i3, i2
    for i3 in range(r3[0] if r3[0] > 0 else 0):
        t3 = r3[1] if i3 == 0 else r3[2]
        R3s = rotation(h3, t3)
        a1 = sp1(h1, mv(R3s, h6), mv(R06, h6))
        R15 = mm(rotation(h1, a1[1]), R3s)
        a6 = sp1(h6, h3, mtv(R15, mv(R06, h3)))
        w = mtv(rotation(h1, a1[1]), sub3(rest, mv(R15, p56)))
        r2 = sp4(h3, h1, p12, dot3(h3, w) - dot3(h3, sub3(row3(o, 4), row3(o, 1))))
        for i2 in range(r2[0] if r2[0] > 0 else 0):
            phi = r2[1] if i2 == 0 else r2[2]  # the turn about h1 of joint 1 against the sum θ₁: q₂ = ∓φ
            v = sub3(sub3(w, mv(rotation(h1, phi), p12)), sub3(row3(o, 2), row3(o, 1)))
            row = _planar_three(h, o, v, t3, a1[1] + phi, -s2 * phi, a6[1], rows, row,
                                a1[0] == DEGENERATE or r3[0] == 1)
    return row


include "_search.pxi"
include "_general.pxi"


cdef bint _placed(const double* row, int n, const double* lower, const double* upper, const double* ref,
                  bint use_ref, double slack, double* out) noexcept nogil:
    """Each angle's copy θ + 2πk within [lower, upper] (slack allowed, then clipped), nearest ``ref`` (else nearest
    0), into ``out``; False when a joint has no copy inside."""
    cdef int j
    cdef double aim, x
    for j in range(n):
        aim = ref[j] if use_ref else 0.0
        x = row[j] + TWO_PI * rint((aim - row[j]) / TWO_PI)
        if x < lower[j] - slack:
            x += TWO_PI
        elif x > upper[j] + slack:
            x -= TWO_PI
        if x < lower[j] - slack or x > upper[j] + slack:
            return False
        out[j] = _min(_max(x, lower[j]), upper[j])
    return True


cdef inline bint _close(const double* a, const double* b, int n, double same) noexcept nogil:
    """a and b equal joint by joint to ``same``, angles modulo 2π (the difference reduced by whole turns: no
    trigonometry, which made the merging of a pose's rows cost more than solving them)."""
    cdef int j
    cdef double d
    for j in range(n):
        d = a[j] - b[j]
        if fabs(d - TWO_PI * rint(d / TWO_PI)) > same:
            return False
    return True


cdef struct Arm:
    # an analytic class in the orientation it is solved in
    int kind
    bint mirrored
    int n
    const double* h  # (n, 3) unit axes at q = 0
    const double* o  # (n, 3) points on them [m]
    M9 R0
    V3 N0
    const double* lower
    const double* upper
    double same
    double slack
    const double* general  # the general elimination's packed data (_general.pxi), NULL for the other classes


cdef int _branches(const Arm* arm, M9 Rt, V3 pt, const double* ref, bint use_ref, double* out, long long* found,
                   unsigned char* free) noexcept nogil:
    """Every distinct branch of the pose (Rt, pt) within the limits, in the robot's joint order (see
    :func:`branches`); returns the number of rows written."""
    cdef double raw[RAW_ROWS * 6]
    cdef unsigned char loose[RAW_ROWS]
    cdef long long hits[RAW_ROWS]
    cdef Rows rows
    cdef int m
    rows.out, rows.free, rows.hits, rows.n, rows.cap, rows.same = raw, loose, hits, arm.n, RAW_ROWS, arm.same
    if arm.mirrored:
        pt = scale3(mtv(Rt, pt), -1.0)
        Rt = transpose(Rt)
    m = _placed_rows(arm, Rt, pt, ref, use_ref, out, found, free, &rows)
    if rows.dropped == 0:
        return m
    # more distinct roots than RAW_ROWS (seen: a search along a nearly tangent stretch): solve again with room
    rows.out = <double*> malloc(sizeof(double) * GROWN_ROWS * 6)
    rows.free = <unsigned char*> malloc(GROWN_ROWS)
    rows.hits = <long long*> malloc(sizeof(long long) * GROWN_ROWS)
    if rows.out != NULL and rows.free != NULL and rows.hits != NULL:
        rows.cap = GROWN_ROWS
        m = _placed_rows(arm, Rt, pt, ref, use_ref, out, found, free, &rows)
    release(rows.out)
    release(rows.free)
    release(rows.hits)
    return m


cdef int _placed_rows(const Arm* arm, M9 Rt, V3 pt, const double* ref, bint use_ref, double* out, long long* found,
                      unsigned char* free, Rows* rows) noexcept nogil:
    """The class's roots of (Rt, pt) (already in the solved orientation) written into ``rows``, then merged, turned
    back to the robot's joint order and placed within the limits into ``out``; returns the branches written."""
    cdef double row[6]
    cdef int n = arm.n, count, m = 0, r, j, k
    cdef bint merged
    rows.dropped = 0
    if arm.kind == PARALLEL_6R:
        count = parallel_6r(arm.h, arm.o, arm.R0, arm.N0, Rt, pt, rows)
    elif arm.kind == SPHERICAL_6R:
        count = spherical_6r(arm.h, arm.o, arm.R0, arm.N0, Rt, pt, rows)
    elif arm.kind == MEETING_6R:
        count = meeting_6r(arm.h, arm.o, arm.R0, arm.N0, Rt, pt, rows)
    elif arm.kind == TWO_THREE_6R:
        count = two_three_6r(arm.h, arm.o, arm.R0, arm.N0, Rt, pt, rows)
    elif arm.kind == GENERAL_6R:
        count = general_6r(arm, Rt, pt, rows)
    elif arm.kind >= SEARCH_PAR23_45:
        count = search_6r(arm.h, arm.o, arm.kind, arm.R0, arm.N0, Rt, pt, rows)
    else:
        count = parallel_5r(arm.h, arm.o, arm.R0, arm.N0, Rt, pt, rows)
    for r in range(count):
        for j in range(n):
            row[j] = -rows.out[r * n + n - 1 - j] if arm.mirrored else rows.out[r * n + j]
        merged = False
        for k in range(m):
            if _close(row, out + k * n, n, arm.same):
                found[k] += rows.hits[r]
                free[k] = free[k] or rows.free[r]
                merged = True
                break
        if not merged and m < MAX_ROWS and _placed(row, n, arm.lower, arm.upper, ref, use_ref, arm.slack, out + m * n):
            found[m], free[m] = rows.hits[r], rows.free[r]
            m += 1
    return m


cdef inline M9 _rotation_of(const double[:, :] H) noexcept nogil:
    return (H[0, 0], H[0, 1], H[0, 2], H[1, 0], H[1, 1], H[1, 2], H[2, 0], H[2, 1], H[2, 2])


cdef Arm _arm(int kind, bint mirrored, const double[:, ::1] h, const double[:, ::1] o, const double[:, :] R0,
              const double[:] N0, const double[::1] lower, const double[::1] upper, double same,
              double slack, const double* general=NULL) except *:
    cdef int n = h.shape[0]
    if n not in (5, 6) or h.shape[1] != 3 or o.shape[0] != n or o.shape[1] != 3 or R0.shape[0] != 3 \
            or R0.shape[1] != 3 or N0.shape[0] != 3 or lower.shape[0] != n or upper.shape[0] != n \
            or not (0 <= kind <= SEARCH_MEET23_56 or kind == GENERAL_6R and general != NULL) \
            or (n == 5) != (kind == PARALLEL_5R):
        raise ValueError("an analytic arm: 5 or 6 axes and points (n, 3), R0 (3, 3), N0 (3,), limits (n,), "
                         "and a class code that fits n (the general class's with its prepared data)")
    cdef Arm arm
    arm.kind, arm.mirrored, arm.n, arm.h, arm.o = kind, mirrored, n, &h[0, 0], &o[0, 0]
    arm.R0 = _rotation_of(R0)
    arm.N0 = (N0[0], N0[1], N0[2])
    arm.lower, arm.upper, arm.same, arm.slack, arm.general = &lower[0], &upper[0], same, slack, general
    return arm


def branches(int kind, bint mirrored, const double[:, ::1] h, const double[:, ::1] o, const double[:, :] R0,
             const double[:] N0, const double[:, :] H, const double[::1] lower, const double[::1] upper,
             const double[::1] ref, bint use_ref, double same, double slack, double[:, ::1] out,
             long long[::1] found, unsigned char[::1] free) -> int:
    """Every distinct branch of the pose H (4 × 4, base frame) within the limits, in the robot's joint order.

    Roots closer than ``same`` [rad] joint by joint (modulo 2π) are one branch (``found`` counts them); each angle
    is moved to its copy within [lower − slack, upper + slack] nearest ``ref`` (with ``use_ref``; else nearest 0),
    clipped to the limits. A mirrored class solves H⁻¹ with the chain read from the tool back and turns its rows
    back (q = −q' reversed).

    Args:
        kind: the class's code (PARALLEL_5R 0, PARALLEL_6R 1, SPHERICAL_6R 2, MEETING_6R 3, TWO_THREE_6R 4; the
            search classes of _search.pxi 5 to 10).
        mirrored: the class is solved read from the tool back.
        h, o: (n, 3) unit axes at q = 0 and points on them [m], in the solved orientation.
        R0, N0: the tool's rotation and point [m] at q = 0.
        out: (MAX_ROWS, n) branches written [rad]; found: (MAX_ROWS,) int64; free: (MAX_ROWS,) uint8 (a bool
            array's ``view(np.uint8)``).

    Returns:
        The number of branches written.
    """
    cdef Arm arm = _arm(kind, mirrored, h, o, R0, N0, lower, upper, same, slack)
    if H.shape[0] != 4 or H.shape[1] != 4 or ref.shape[0] != arm.n or out.shape[0] < MAX_ROWS \
            or out.shape[1] != arm.n or found.shape[0] < MAX_ROWS or free.shape[0] < MAX_ROWS:
        raise ValueError("branches: H (4, 4), ref (n,), out (MAX_ROWS, n), found and free (MAX_ROWS,)")
    return _branches(&arm, _rotation_of(H), (H[0, 3], H[1, 3], H[2, 3]), &ref[0], use_ref, &out[0, 0], &found[0],
                     &free[0])


def branches_batch(int kind, bint mirrored, const double[:, ::1] h, const double[:, ::1] o, const double[:, :] R0,
                   const double[:] N0, const double[:, :, :] H, const double[::1] lower, const double[::1] upper,
                   double same, double slack, double[:, :, ::1] out, long long[:, ::1] found,
                   unsigned char[:, ::1] free, long long[::1] count, int threads):
    """:func:`branches` for every pose of the (B, 4, 4) stack H on ``threads`` OpenMP threads (copies nearest 0):
    out (B, MAX_ROWS, n), found and free (B, MAX_ROWS), count (B,) written."""
    cdef Arm arm = _arm(kind, mirrored, h, o, R0, N0, lower, upper, same, slack)
    cdef Py_ssize_t B = H.shape[0], b
    cdef double zero[6]
    cdef int j
    if H.shape[1] != 4 or H.shape[2] != 4 or out.shape[0] != B or out.shape[1] < MAX_ROWS or out.shape[2] != arm.n \
            or found.shape[0] != B or found.shape[1] < MAX_ROWS or free.shape[0] != B or free.shape[1] < MAX_ROWS \
            or count.shape[0] != B:
        raise ValueError("branches_batch: H (B, 4, 4), out (B, MAX_ROWS, n), found and free (B, MAX_ROWS), count (B,)")
    for j in range(6):
        zero[j] = 0.0
    with nogil:
        for b in prange(B, num_threads=max(1, threads), schedule="static"):
            count[b] = _branches(&arm, _rotation_of(H[b]), (H[b, 0, 3], H[b, 1, 3], H[b, 2, 3]), zero, False,
                                 &out[b, 0, 0], &found[b, 0], &free[b, 0])


def search_errors(int kind, const double[:, ::1] h, const double[:, ::1] o, const double[:, :] R0, const double[:] N0,
                  const double[:, :] H, const double[::1] t, double[:, ::1] e, double[:, ::1] margin):
    """The 1-D search's error and margin of each of its WAYS ways at the values t [rad] of its search joint, for the
    pose H (the class solved unmirrored): e and margin (len(t), 4), e NaN where a way has no roots, which is where
    its margin is below 0 (docs/analytic.md)."""
    cdef Search S
    cdef Py_ssize_t k
    if kind < SEARCH_PAR23_45 or kind > SEARCH_MEET23_56 or h.shape[0] != 6 or o.shape[0] != 6 \
            or e.shape[0] != t.shape[0] or e.shape[1] != WAYS or margin.shape[0] != t.shape[0] \
            or margin.shape[1] != WAYS:
        raise ValueError("search_errors: a search class code, h and o (6, 3), e and margin (len(t), 4)")
    _prepare(&S, &h[0, 0], &o[0, 0], kind, _rotation_of(R0), (N0[0], N0[1], N0[2]), _rotation_of(H),
             (H[0, 3], H[1, 3], H[2, 3]))
    for k in range(t.shape[0]):
        _sample(&S, t[k], &e[k, 0], NULL, NULL, &margin[k, 0], -1)


# ---- the prepared closed form: every branch of a pose, judged, in one compiled call ----

cdef enum:
    KEPT = 0  # the judge confirms the root
    NEAR = 1  # short of the tolerances but near them: a warm-started solve may finish it (the caller's)
    DROPPED = 2  # not this pose's root


cdef double NO_AIM[6]  # the reference of a call without one (never read; a C global is zeroed)


cdef class ClosedForm:
    """One robot's closed form with one pair of tolerances, prepared: every branch of a pose, each judged by the
    robot's certified compiled FK, in one compiled call (and a batch of poses on all cores).

    Args:
        judge: the robot's certified compiled FK.
        spec: read once: ``kind``, ``mirrored``, ``h``, ``o``, ``R0``, ``N0`` the class (as :func:`branches`
            takes them; the general class also ``general``, its packed data, kinelab.ik.analytic.general.packed); ``lower``, ``upper`` the joint limits [rad] the roots are placed within, ``same`` [rad] and
            ``slack`` [rad] as :func:`branches`; ``check_lower``, ``check_upper`` the limits an answer must lie within;
            ``tol_pos`` [m], ``tol_rot`` [rad] the tolerances.
    """

    cdef Arm arm
    cdef Judge judge
    cdef list keep
    cdef const double[::1] check_lower, check_upper
    cdef double tol_pos, tol_rot
    cdef readonly int n

    def __init__(self, Judge judge, spec):
        c = [np.ascontiguousarray(getattr(spec, name), dtype=np.float64)
             for name in ("h", "o", "R0", "N0", "lower", "upper", "check_lower", "check_upper")]
        cdef const double[::1] general
        cdef const double* data = NULL
        if spec.kind == GENERAL_6R:
            packed = np.ascontiguousarray(spec.general, dtype=np.float64)
            general = packed
            if general.shape[0] != GENERAL_SIZE:
                raise ValueError(f"ClosedForm: the general class's packed data has {GENERAL_SIZE} numbers")
            c.append(packed)
            data = &general[0]
            ready()
        self.keep = c
        self.arm = _arm(spec.kind, spec.mirrored, c[0], c[1], c[2], c[3], c[4], c[5], spec.same, spec.slack, data)
        self.n = self.arm.n
        self.check_lower, self.check_upper = c[6], c[7]
        if judge.kind.shape[0] != self.n or self.check_lower.shape[0] != self.n or self.check_upper.shape[0] != self.n:
            raise ValueError("ClosedForm: a judge and check limits of the arm's joints")
        self.judge, self.tol_pos, self.tol_rot = judge, spec.tol_pos, spec.tol_rot

    def solve(self, const double[:, :] H, ref):
        """Every branch of the pose H (4 × 4 homogeneous, base frame) within the limits that the judge confirms.

        Args:
            H: oMtarget.
            ref: None, or n angles [rad]: each angle's copy nearest it (else nearest 0).

        Returns:
            (q (k, n) [rad], position errors (k,) [m], rotation errors (k,) [rad], roots merged (k,), one of a
            continuum (k,) bool, roots placed within the limits) in the roots' order; None when a root falls
            short of the tolerances but near them (a warm-started solve may finish it: the caller's general route),
            or H is not a 4 × 4 pose.
        """
        cdef double out[MAX_ROWS * 6]
        cdef double errors[MAX_ROWS * 2]
        cdef long long found[MAX_ROWS]
        cdef unsigned char loose[MAX_ROWS]
        cdef double T[16]
        cdef const double[::1] r
        cdef const double* aim = out  # read only with a reference
        cdef bint use_ref = ref is not None, near = False
        cdef int n = self.n, m = 0, kept, i, j
        if H.shape[0] != 4 or H.shape[1] != 4 or pose_defect_of(H) != 0:
            return None
        if use_ref:
            r = ref
            if r.shape[0] != n:
                raise ValueError("ClosedForm.solve: ref needs one angle per joint")
            aim = &r[0]
        for i in range(4):
            for j in range(4):
                T[4 * i + j] = H[i, j]
        with nogil:
            kept = self._pose(T, aim, use_ref, out, errors, found, loose, &near, &m)
        if near:
            return None
        q = np.empty((kept, n))
        position_error, rotation_error = np.empty(kept), np.empty(kept)
        merged, continuum = np.empty(kept, dtype=np.int64), np.empty(kept, dtype=np.bool_)
        cdef double[:, ::1] qv = q
        cdef double[::1] pv = position_error, rv = rotation_error
        cdef long long[::1] fv = merged
        cdef unsigned char[::1] cv = continuum.view(np.uint8)
        for i in range(kept):
            for j in range(n):
                qv[i, j] = out[i * n + j]
            pv[i], rv[i], fv[i], cv[i] = errors[2 * i], errors[2 * i + 1], found[i], loose[i]
        return q, position_error, rotation_error, merged, continuum, m

    def every(self, target, made):
        """:meth:`solve` of a ``pin.SE3`` target with no reference, its arrays handed to ``made(q, position_error,
        rotation_error, merged, continuum, wall_time, H)`` (the call's wall time [s], the target's 4 × 4 array),
        which builds the caller's result; None where :meth:`solve` gives None or no branch, or roots were merged
        outside a continuum."""
        cdef double t_start = now()
        cdef double out[MAX_ROWS * 6]
        cdef double errors[MAX_ROWS * 2]
        cdef long long found[MAX_ROWS]
        cdef unsigned char loose[MAX_ROWS]
        cdef double T[16]
        cdef bint near = False
        cdef int m = 0, kept, i
        H = target.homogeneous
        if not _row_major(H, T) or pose_defect_row_major(T) != 0:
            return None
        with nogil:
            kept = self._pose(T, out, False, out, errors, found, loose, &near, &m)
        if near or kept == 0:
            return None
        for i in range(kept):
            if found[i] > 1 and not loose[i]:
                return None  # roots merged: perhaps two beside a fold, which the general route splits
        return self._arrays(made, kept, out, errors, found, loose, t_start, H)

    cdef object _arrays(self, object made, int kept, const double* out, const double* errors,
                        const long long* found, const unsigned char* loose, double t_start, object H):
        """The kept rows as arrays, handed to ``made``."""
        cdef cnp.npy_intp rows = kept, i
        cdef cnp.npy_intp dims[2]
        dims[0], dims[1] = kept, self.n
        cdef cnp.ndarray q = cnp.PyArray_EMPTY(2, dims, cnp.NPY_FLOAT64, 0)
        cdef cnp.ndarray dp = cnp.PyArray_EMPTY(1, &rows, cnp.NPY_FLOAT64, 0)
        cdef cnp.ndarray dr = cnp.PyArray_EMPTY(1, &rows, cnp.NPY_FLOAT64, 0)
        cdef cnp.ndarray merged = cnp.PyArray_EMPTY(1, &rows, cnp.NPY_INT64, 0)
        cdef cnp.ndarray continuum = cnp.PyArray_EMPTY(1, &rows, cnp.NPY_BOOL, 0)
        cdef double* qp = <double*> cnp.PyArray_DATA(q)
        cdef double* dpp = <double*> cnp.PyArray_DATA(dp)
        cdef double* drp = <double*> cnp.PyArray_DATA(dr)
        cdef long long* mp = <long long*> cnp.PyArray_DATA(merged)
        cdef unsigned char* cp = <unsigned char*> cnp.PyArray_DATA(continuum)
        for i in range(kept * self.n):
            qp[i] = out[i]
        for i in range(kept):
            dpp[i], drp[i], mp[i], cp[i] = errors[2 * i], errors[2 * i + 1], found[i], loose[i] != 0
        return made(q, dp, dr, merged, continuum, now() - t_start, H)

    def solve_batch(self, const double[:, :, ::1] H, double[:, :, ::1] q, double[:, :, ::1] errors,
                    long long[:, ::1] merged, unsigned char[:, ::1] continuum, long long[::1] count,
                    unsigned char[::1] near, int threads, double deadline=INFINITY):
        """:meth:`solve` for every pose of the (B, 4, 4) stack H (proper poses, checked by the caller; copies
        nearest 0) on ``threads`` OpenMP threads: per pose b the branches the judge confirms in
        q[b, :count[b]] [rad], errors[b, :count[b]] ([m, rad] each), merged and continuum (a bool array's
        ``view(np.uint8)``); rows after count[b] are left as given. near[b] = 1 (and count[b] = 0) where a root
        fell short of the tolerances but near them: the caller solves that pose by the general route; near[b] =
        NOT_STARTED (count 0) for a pose not started before ``deadline`` (the monotonic clock of
        ``time.perf_counter``, [s])."""
        cdef Py_ssize_t B = H.shape[0], b
        cdef int n = self.n
        if H.shape[1] != 4 or H.shape[2] != 4 or q.shape[0] != B or q.shape[1] < MAX_ROWS or q.shape[2] != n \
                or errors.shape[0] != B or errors.shape[1] < MAX_ROWS or errors.shape[2] != 2 \
                or merged.shape[0] != B or merged.shape[1] < MAX_ROWS or continuum.shape[0] != B \
                or continuum.shape[1] < MAX_ROWS or count.shape[0] != B or near.shape[0] != B:
            raise ValueError("ClosedForm.solve_batch: H (B, 4, 4), q (B, MAX_ROWS, n), errors (B, MAX_ROWS, 2), "
                             "merged and continuum (B, MAX_ROWS), count and near (B,)")
        with nogil:
            for b in prange(B, num_threads=max(1, threads), schedule="dynamic", chunksize=8):
                if now() > deadline:
                    count[b], near[b] = 0, NOT_STARTED
                else:
                    count[b] = self._pose_row(&H[b, 0, 0], NO_AIM, &q[b, 0, 0], &errors[b, 0, 0], &merged[b, 0],
                                              &continuum[b, 0], &near[b])

    def nearest_batch(self, const double[:, :, ::1] H, const double[:, ::1] refs, double[:, ::1] q,
                      double[:, ::1] errors, long long[::1] count, unsigned char[::1] near, int threads,
                      double deadline=INFINITY):
        """:meth:`solve` and the pick of ``NearestBranch`` for every pose of the (B, 4, 4) stack H (proper poses,
        checked by the caller) on ``threads`` OpenMP threads: per pose b, with ``refs`` (B, n) [rad], the branch
        nearest refs[b] (each angle's copy nearest it; the first of the nearest by the largest joint difference
        modulo 2π), with ``refs`` of no rows the first branch (copies nearest 0), in q[b] [rad] and its errors in
        errors[b] ([m, rad]); count[b] the branches the judge confirms (0: none, q[b] left as given); near[b] = 1
        (count 0) where a root fell short of the tolerances but near them: the caller's general route; near[b] =
        NOT_STARTED (count 0) for a pose not started before ``deadline`` (``time.perf_counter``'s clock, [s])."""
        cdef Py_ssize_t B = H.shape[0], b
        cdef bint use_ref = refs.shape[0] > 0
        if H.shape[1] != 4 or H.shape[2] != 4 or q.shape[0] != B or q.shape[1] != self.n or errors.shape[0] != B \
                or errors.shape[1] != 2 or count.shape[0] != B or near.shape[0] != B \
                or (use_ref and (refs.shape[0] != B or refs.shape[1] != self.n)):
            raise ValueError("ClosedForm.nearest_batch: H (B, 4, 4), refs (B, n) or (0, n), q (B, n), errors (B, 2), "
                             "count and near (B,)")
        with nogil:
            for b in prange(B, num_threads=max(1, threads), schedule="dynamic", chunksize=8):
                if now() > deadline:
                    count[b], near[b] = 0, NOT_STARTED
                else:
                    count[b] = self._nearest_row(&H[b, 0, 0], &refs[b, 0] if use_ref else NO_AIM, use_ref, &q[b, 0],
                                                 &errors[b, 0], &near[b])

    cdef int _nearest_row(self, const double* T, const double* aim, bint use_ref, double* q, double* errors,
                          unsigned char* near) noexcept nogil:
        """One pose of :meth:`nearest_batch`: how many branches the judge confirms."""
        cdef double out[MAX_ROWS * 6]
        cdef double errs[MAX_ROWS * 2]
        cdef long long found[MAX_ROWS]
        cdef unsigned char loose[MAX_ROWS]
        cdef bint short = False
        cdef int m = 0, kept, k, j, best = 0, n = self.n
        cdef double worst, d, least = INFINITY
        kept = self._pose(T, aim, use_ref, out, errs, found, loose, &short, &m)
        near[0] = short
        if short or kept == 0:
            return 0
        if use_ref:  # as kinelab.core._joints.turn_distances measures, and np.argmin picks: the first nearest
            for k in range(kept):
                worst = 0.0
                for j in range(n):
                    d = fabs(remainder(out[k * n + j] - aim[j], 2.0 * M_PI))
                    if d > worst:
                        worst = d
                if worst < least:
                    least, best = worst, k
        for j in range(n):
            q[j] = out[best * n + j]
        errors[0], errors[1] = errs[2 * best], errs[2 * best + 1]
        return kept

    cdef int _pose_row(self, const double* T, const double* zero, double* q, double* errors, long long* merged,
                       unsigned char* continuum, unsigned char* near) noexcept nogil:
        """One pose of a batch (:meth:`solve_batch`)."""
        cdef bint short = False
        cdef int m = 0, kept
        kept = self._pose(T, zero, False, q, errors, merged, continuum, &short, &m)
        near[0] = short
        return 0 if short else kept

    cdef int _pose(self, const double* T, const double* aim, bint use_ref, double* q, double* errors,
                   long long* merged, unsigned char* continuum, bint* near, int* placed) noexcept nogil:
        """The branches of the pose T (4 × 4, row-major) the judge confirms, compacted into q (MAX_ROWS × n),
        errors (MAX_ROWS × 2), merged and continuum; returns how many. ``near`` set (and the count meaningless)
        when a root fell short of the tolerances but near them; ``placed``: the roots placed within the limits."""
        cdef double out[MAX_ROWS * 6]
        cdef long long found[MAX_ROWS]
        cdef unsigned char loose[MAX_ROWS]
        cdef double p[3]
        cdef double S[9]
        cdef int n = self.n, m, k, i, j, kept = 0
        cdef unsigned char verdict
        cdef M9 Rt = (T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10])
        m = _branches(&self.arm, Rt, (T[3], T[7], T[11]), aim, use_ref, out, found, loose)
        placed[0] = m
        for i in range(3):  # the target's point and rotation, as the verdict reads them
            p[i] = T[4 * i + 3]
            for j in range(3):
                S[3 * i + j] = T[4 * i + j]
        for k in range(m):
            verdict = self._judged(p, S, out + k * n, errors + 2 * kept, errors + 2 * kept + 1)
            if verdict == NEAR:
                near[0] = True
                return kept
            if verdict == KEPT:
                for j in range(n):
                    q[kept * n + j] = out[k * n + j]
                merged[kept], continuum[kept] = found[k], loose[k]
                kept += 1
        return kept

    cdef unsigned char _judged(self, const double* p, const double* S, const double* q, double* dp,
                               double* dr) noexcept nogil:
        """KEPT, NEAR or DROPPED for one root against the target point p and rotation S (3 × 3, row-major); its
        errors written."""
        cdef double T[16]
        cdef int i
        self.judge.pose(q, T)
        pose_errors(T, p, S, -1, dp, dr)
        for i in range(self.n):
            if not self.check_lower[i] <= q[i] <= self.check_upper[i]:
                return DROPPED
        if dp[0] <= self.tol_pos and dr[0] <= self.tol_rot:
            return KEPT
        if dp[0] <= 1e3 * self.tol_pos + 1e-6 and dr[0] <= 1e3 * self.tol_rot + 1e-6:
            return NEAR
        return DROPPED


cdef bint _row_major(object H, double* T):
    """Copy a 4 × 4 float64 array (any strides) into T row by row; False for anything else."""
    if type(H) is not np.ndarray:
        return False
    cdef cnp.ndarray a = H
    if cnp.PyArray_NDIM(a) != 2 or cnp.PyArray_TYPE(a) != cnp.NPY_FLOAT64 or a.shape[0] != 4 or a.shape[1] != 4:
        return False
    cdef char* base = <char*> cnp.PyArray_DATA(a)
    cdef cnp.npy_intp s0 = cnp.PyArray_STRIDES(a)[0], s1 = cnp.PyArray_STRIDES(a)[1]
    cdef int i, j
    for i in range(4):
        for j in range(4):
            T[4 * i + j] = (<double*> (base + i * s0 + j * s1))[0]
    return True

