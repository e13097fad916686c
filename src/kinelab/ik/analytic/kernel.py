"""All the branches of one pose, compiled, for the arms of the three classes of docs/analytic.md.

The chain is written as a product of exponentials at q = 0, everything in the base frame: unit axes h_i,
points o_i on them, the tool's rotation R0 and point N0. With R = R_target·R0ᵀ and v the target point less
what the last joints carry, the parallel triple leaves joint 1 one scalar equation (subproblem 4), the wrist
angles follow from the orientation (subproblems 4 and 1), the sum θ₂ + θ₃ + θ₄ from the rotation left over
(subproblem 1), and the planar elbow from a distance (subproblem 3) and an angle (subproblem 1).

Rows are written into ``out`` (angles in (−π, π], one row per root combination; coincident roots are
written twice and merged by the caller); ``free`` marks rows where a subproblem was degenerate and its
angle was set to 0 (a continuum of answers: a wrist or shoulder singularity).

A spherical wrist (axes 4, 5, 6 meeting at w) with h₂ ∥ h₃ is solved the classical way: the target fixes
the wrist point, which joints 1–3 alone move (joint 1 from its component along h₂, subproblem 4; joint 3
from its distance to axis 2's point, subproblem 3; joint 2 by subproblem 1); the rotation left for the wrist
gives joint 5 (subproblem 4), then joints 4 and 6 (subproblem 1 each). With axes 1 and 2 meeting at s
instead, the wrist point's distance from s fixes joint 3 (subproblem 3) and the turn of joints 1 and 2 onto
it is subproblem 2 (here subproblem 4 for joint 1, then subproblem 1 for joint 2).

With h₁ ∥ h₂ and h₃ ∥ h₄ ∥ h₅ (a turning platform carrying a planar arm, the youBot's heading and arm), the
rotation is R(h₁, θ₁)·R(h₃, θ₃)·R(h₆, q₆) with θ₁ = q₁ ± q₂ and θ₃ = q₃ ± q₄ ± q₅: θ₃ by subproblem 4, θ₁
and q₆ by subproblem 1; the point then fixes q₂ through the component along h₃ that the planar joints keep
(subproblem 4), and the planar elbow gives q₄ (subproblem 3) and q₃ (subproblem 1).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from kinelab.geometry import TWO_PI
from kinelab.ik.analytic.subproblems import (
    DEGENERATE,
    TANGENT_SLACK,
    add3,
    dot3,
    mm,
    mtv,
    mv,
    rotation,
    row3,
    scale3,
    sp1,
    sp4,
    sp4_range,
    sub3,
    transpose,
    wrap,
)

MAX_ROWS = 8
PARALLEL_5R, PARALLEL_6R, SPHERICAL_6R, MEETING_6R, TWO_THREE_6R = 0, 1, 2, 3, 4  # kernel codes (ArmClass.kind)
SINGULAR_WRIST = 1e-6  # [rad] q5's two roots closer than twice this are the singular wrist's double root


@njit(cache=True, inline="always")
def mat9(M):
    """A 3 × 3 array as a 9-tuple, row by row."""
    return (M[0, 0], M[0, 1], M[0, 2], M[1, 0], M[1, 1], M[1, 2], M[2, 0], M[2, 1], M[2, 2])


@njit(cache=True, inline="always")
def _one_if_double(n, a, b):
    """Subproblem 4's (count, θ₁, θ₂) with two roots closer than 2·SINGULAR_WRIST made one (their midpoint): the
    double root of a singular wrist, whose two answers are one continuum."""
    if n == 2 and abs(wrap(a - b)) < 2.0 * SINGULAR_WRIST:
        return 1, a - 0.5 * wrap(a - b), b
    return n, a, b


@njit(cache=True)
def _elbow(h, o, q1, R1, R06, v, R_rest, wrist, spin, out, free, row, flag):
    """Rows for one (q1, wrist) pair: θ₂₃₄ from R₁ᵀ·R·R_restᵀ, then θ₃ (two roots) and θ₂; returns the next row.

    ``wrist`` holds the wrist angles (q5,) or (q5, q6) that go after q1..q4. ``spin`` ≠ 0 marks a wrist in a
    continuum whose last angle turns the tool about h₂ with this sign: θ₂₃₄ is then free, chosen where the
    elbow reaches (:func:`_free_sum`), and the last wrist angle takes up the difference.
    """
    h2, h3, h4 = row3(h, 1), row3(h, 2), row3(h, 3)
    s3 = 1.0 if dot3(h3, h2) > 0 else -1.0
    s4 = 1.0 if dot3(h4, h2) > 0 else -1.0
    R234 = mm(mm(transpose(R1), R06), transpose(R_rest))
    x = (1.0, 0.0, 0.0) if abs(h2[0]) < 0.9 else (0.0, 1.0, 0.0)
    x = sub3(x, scale3(h2, dot3(h2, x)))
    _, t234 = sp1(h2, x, mv(R234, x))
    p23, p34, p45 = sub3(row3(o, 2), row3(o, 1)), sub3(row3(o, 3), row3(o, 2)), sub3(row3(o, 4), row3(o, 3))
    c = sub3(mtv(R1, v), sub3(row3(o, 1), row3(o, 0)))
    last = wrist[len(wrist) - 1]
    if spin != 0.0:
        ok, chosen = _free_sum(h2, h3, c, p23, p34, p45)
        if not ok:
            return row
        last += spin * (t234 - chosen)
        t234 = chosen
        R234 = rotation(h2, t234)
    n, q2a, q3a, q2b, q3b = _planar_pair(h2, h3, p23, p34, sub3(c, mv(R234, p45)))
    for i in range(n):
        q2, q3 = (q2a, q3a) if i == 0 else (q2b, q3b)
        q4 = s4 * (t234 - q2 - s3 * q3)
        out[row, 0], out[row, 1], out[row, 2], out[row, 3] = wrap(q1), wrap(q2), wrap(q3), wrap(q4)
        out[row, 4] = wrap(wrist[0])
        if len(wrist) == 2:
            out[row, 5] = wrap(last)
        else:
            out[row, 4] = wrap(last)
        free[row] = flag
        row += 1
    return row


@njit(cache=True)
def _planar_pair(ha, hb, pa, pb, v):
    """The two (qa, qb) with R(ha, qa)·(pa + R(hb, qb)·pb) = v, ha ∥ hb (a planar elbow): qb by subproblem 3,
    then qa by subproblem 1; (count, qa₁, qb₁, qa₂, qb₂), count 0 when ‖v‖ is out of the elbow's reach."""
    n, a, b = sp4(pa, hb, pb, 0.5 * (dot3(v, v) - dot3(pa, pa) - dot3(pb, pb)))
    if n <= 0:
        return 0, 0.0, 0.0, 0.0, 0.0
    _, qa1 = sp1(ha, add3(pa, mv(rotation(hb, a), pb)), v)
    _, qa2 = sp1(ha, add3(pa, mv(rotation(hb, b), pb)), v)
    return 2, qa1, a, qa2, b


@njit(cache=True)
def _free_sum(h2, h3, c, p23, p34, p45):
    """(found, θ₂₃₄) for a wrist in a continuum: the elbow meets ‖δ‖ with δ = c − R(h₂, θ₂₃₄)·p₄₅, so θ₂₃₄ is
    chosen where ‖δ‖² sits mid-way in the range both the elbow and the turn of p₄₅ reach (one of the continuum)."""
    e0, er = sp4_range(p23, h3, p34)
    f0, fr = sp4_range(c, h2, p45)
    base_elbow = dot3(p34, p34) + dot3(p23, p23)
    base_turn = dot3(c, c) + dot3(p45, p45)
    lo = max(base_elbow + 2.0 * (e0 - er), base_turn - 2.0 * (f0 + fr))
    hi = min(base_elbow + 2.0 * (e0 + er), base_turn - 2.0 * (f0 - fr))
    if lo > hi + TANGENT_SLACK * max(1.0, abs(hi)):
        return False, 0.0
    n, a, _ = sp4(c, h2, p45, 0.5 * (base_turn - 0.5 * (lo + hi)))
    if n == DEGENERATE:  # p45 along h2: every θ₂₃₄ gives the same δ
        return True, 0.0
    return n > 0, a


@njit(cache=True)
def _shoulder(h, o, v):
    """The roots of joint 1 (subproblem 4 on the component along h₂) and whether joint 1 is free."""
    h2 = row3(h, 1)
    n1, a1, b1 = sp4(v, row3(h, 0), h2, dot3(h2, sub3(row3(o, 4), row3(o, 0))))
    if n1 == DEGENERATE:  # the wrist point on joint 1's axis: every q1 serves
        return 1, 0.0, 0.0, True
    return n1, a1, b1, False


@njit(cache=True)
def parallel_6r(h, o, R0, N0, Rt, pt, out, free):
    """Every branch of a 6R arm with h₂ ∥ h₃ ∥ h₄ and axes 5 and 6 meeting at o[4] = o[5]; returns the row count.

    Args:
        h: (6, 3) unit axes at q = 0, base frame.
        o: (6, 3) points on them [m] (o[4] = o[5] the wrist point).
        R0: the tool's rotation at q = 0 (9-tuple, row by row).
        N0: the tool's point at q = 0 [m] (3-tuple).
        Rt: the target's rotation (9-tuple, base frame).
        pt: the target's point [m] (3-tuple).
        out: (MAX_ROWS, 6) rows written [rad].
        free: (MAX_ROWS,) flags written (one of a continuum).
    """
    R06 = mm(Rt, transpose(R0))
    v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 5))))
    n1, a1, b1, free1 = _shoulder(h, o, v)
    h2, h5, h6 = row3(h, 1), row3(h, 4), row3(h, 5)
    row = 0
    for i1 in range(max(n1, 0)):
        q1 = a1 if i1 == 0 else b1
        R1 = rotation(row3(h, 0), q1)
        R1h2 = mv(R1, h2)
        n5, a5, b5 = sp4(h2, h5, h6, dot3(R1h2, mv(R06, h6)))
        n5, a5, b5 = _one_if_double(n5, a5, b5)  # a double root: h₆ ∥ h₂, q6 joins θ₂₃₄
        for i5 in range(max(n5, 0) if n5 != DEGENERATE else 1):
            q5 = (a5 if i5 == 0 else b5) if n5 != DEGENERATE else 0.0
            R5 = rotation(h5, q5)
            m6, t6 = sp1(h6, mtv(R5, h2), mtv(R06, R1h2))
            spin = 0.0
            if n5 != 2:  # a wrist in a continuum: q6 = 0 to start, then the elbow's choice of θ₂₃₄ sets it
                t6, spin = 0.0, (1.0 if dot3(mv(R5, h6), h2) > 0 else -1.0)
            row = _elbow(h, o, q1, R1, R06, v, mm(R5, rotation(h6, -t6)), (q5, -t6), spin, out, free, row,
                         free1 or m6 == DEGENERATE or n5 != 2)
    return row


@njit(cache=True)
def parallel_5r(h, o, R0, N0, Rt, pt, out, free):
    """Every branch of a 5R arm with h₂ ∥ h₃ ∥ h₄ (a pose asks six numbers of five joints: the caller keeps the
    rows Pinocchio confirms); returns the row count. Arguments as :func:`parallel_6r`, (5, 3) axes and points."""
    R06 = mm(Rt, transpose(R0))
    v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 4))))
    n1, a1, b1, free1 = _shoulder(h, o, v)
    h2, h5 = row3(h, 1), row3(h, 4)
    row = 0
    for i1 in range(max(n1, 0)):
        q1 = a1 if i1 == 0 else b1
        R1 = rotation(row3(h, 0), q1)
        m5, t5 = sp1(h5, h2, mtv(R06, mv(R1, h2)))
        row = _elbow(h, o, q1, R1, R06, v, rotation(h5, -t5), (-t5,), 0.0, out, free, row,
                     free1 or m5 == DEGENERATE)
    return row


@njit(cache=True)
def spherical_6r(h, o, R0, N0, Rt, pt, out, free):
    """Every branch of a 6R arm with h₂ ∥ h₃ and axes 4, 5, 6 meeting at o[3] = o[4] = o[5]; returns the row
    count. Arguments as :func:`parallel_6r`."""
    R06 = mm(Rt, transpose(R0))
    w0 = row3(o, 3)
    v = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, w0)))
    n1, a1, b1, free1 = _shoulder(h, o, v)
    h2, h3 = row3(h, 1), row3(h, 2)
    p12, p23, p3w = sub3(row3(o, 1), row3(o, 0)), sub3(row3(o, 2), row3(o, 1)), sub3(w0, row3(o, 2))
    row = 0
    for i1 in range(max(n1, 0)):
        q1 = a1 if i1 == 0 else b1
        R1 = rotation(row3(h, 0), q1)
        c = sub3(mtv(R1, v), p12)  # the wrist point seen from axis 2's point, before joint 1
        n3, a3, b3 = sp4(p23, h3, p3w, 0.5 * (dot3(c, c) - dot3(p23, p23) - dot3(p3w, p3w)))
        if n3 <= 0:
            continue
        for i3 in range(2):
            q3 = a3 if i3 == 0 else b3
            R3 = rotation(h3, q3)
            m2, q2 = sp1(h2, add3(p23, mv(R3, p3w)), c)
            Rw = mm(transpose(mm(mm(R1, rotation(h2, q2)), R3)), R06)
            row = _spherical_wrist(h, Rw, q1, q2, q3, out, free, row, free1 or m2 == DEGENERATE)
    return row


@njit(cache=True)
def meeting_6r(h, o, R0, N0, Rt, pt, out, free):
    """Every branch of a 6R arm with axes 1 and 2 meeting at o[0] = o[1] and axes 4, 5, 6 meeting at
    o[3] = o[4] = o[5]; returns the row count. Arguments as :func:`parallel_6r`."""
    R06 = mm(Rt, transpose(R0))
    s, w0 = row3(o, 0), row3(o, 3)
    v = sub3(sub3(pt, mv(R06, sub3(N0, w0))), s)  # the wrist point seen from the shoulder point
    a, b = sub3(row3(o, 2), s), sub3(w0, row3(o, 2))
    h1, h2, h3 = row3(h, 0), row3(h, 1), row3(h, 2)
    n3, a3, b3 = sp4(a, h3, b, 0.5 * (dot3(v, v) - dot3(a, a) - dot3(b, b)))
    row = 0
    if n3 <= 0:
        return row
    for i3 in range(2):
        q3 = a3 if i3 == 0 else b3
        R3 = rotation(h3, q3)
        u = add3(a, mv(R3, b))
        n1, a1, b1 = sp4(v, h1, h2, dot3(h2, u))  # joint 2 keeps the component of u along h2
        free1 = n1 == DEGENERATE
        for i1 in range(max(n1, 0) if not free1 else 1):
            q1 = (a1 if i1 == 0 else b1) if not free1 else 0.0
            R1 = rotation(h1, q1)
            m2, q2 = sp1(h2, u, mtv(R1, v))
            Rw = mm(transpose(mm(mm(R1, rotation(h2, q2)), R3)), R06)
            row = _spherical_wrist(h, Rw, q1, q2, q3, out, free, row, free1 or m2 == DEGENERATE)
    return row


@njit(cache=True)
def two_three_6r(h, o, R0, N0, Rt, pt, out, free):
    """Every branch of a 6R arm with h₁ ∥ h₂ and h₃ ∥ h₄ ∥ h₅; returns the row count. Arguments as
    :func:`parallel_6r`."""
    R06 = mm(Rt, transpose(R0))
    h1, h3, h6 = row3(h, 0), row3(h, 2), row3(h, 5)
    s2 = 1.0 if dot3(row3(h, 1), h1) > 0 else -1.0
    p12, p56 = sub3(row3(o, 1), row3(o, 0)), sub3(row3(o, 5), row3(o, 4))
    rest = sub3(sub3(pt, row3(o, 0)), mv(R06, sub3(N0, row3(o, 5))))
    n3, a3, b3 = sp4(h1, h3, h6, dot3(h1, mv(R06, h6)))
    n3, a3, b3 = _one_if_double(n3, a3, b3)
    row = 0
    for i3 in range(max(n3, 0)):
        t3 = a3 if i3 == 0 else b3
        R3s = rotation(h3, t3)
        m1, t1 = sp1(h1, mv(R3s, h6), mv(R06, h6))
        R15 = mm(rotation(h1, t1), R3s)
        _, q6 = sp1(h6, h3, mtv(R15, mv(R06, h3)))
        w = mtv(rotation(h1, t1), sub3(rest, mv(R15, p56)))
        n2, a2, b2 = sp4(h3, h1, p12, dot3(h3, w) - dot3(h3, sub3(row3(o, 4), row3(o, 1))))
        for i2 in range(max(n2, 0)):
            phi = a2 if i2 == 0 else b2  # the turn about h1 of joint 1 against the sum θ₁: q₂ = ∓φ
            v = sub3(sub3(w, mv(rotation(h1, phi), p12)), sub3(row3(o, 2), row3(o, 1)))
            row = _planar_three(h, o, v, t3, (t1 + phi, -s2 * phi, q6), out, free, row,
                                m1 == DEGENERATE or n3 == 1)
    return row


@njit(cache=True)
def _planar_three(h, o, v, t3, outer, out, free, row, flag):
    """Rows for joints 3–5 (parallel) reaching v = R₃(p₃₄ + R₄ p₄₅) with q₃ ± q₄ ± q₅ = t3, after (q1, q2, q6) in
    ``outer``; returns the next row."""
    h3, h4 = row3(h, 2), row3(h, 3)
    s4 = 1.0 if dot3(h4, h3) > 0 else -1.0
    s5 = 1.0 if dot3(row3(h, 4), h3) > 0 else -1.0
    p34, p45 = sub3(row3(o, 3), row3(o, 2)), sub3(row3(o, 4), row3(o, 3))
    n, q3a, q4a, q3b, q4b = _planar_pair(h3, h4, p34, p45, v)
    for i in range(n):
        q3, q4 = (q3a, q4a) if i == 0 else (q3b, q4b)
        q5 = s5 * (t3 - q3 - s4 * q4)
        out[row, 0], out[row, 1], out[row, 2] = wrap(outer[0]), wrap(outer[1]), wrap(q3)
        out[row, 3], out[row, 4], out[row, 5] = wrap(q4), wrap(q5), wrap(outer[2])
        free[row] = flag
        row += 1
    return row


@njit(cache=True)
def _spherical_wrist(h, Rw, q1, q2, q3, out, free, row, flag):
    """Rows for joints 4–6 turning the rotation Rw = R₄R₅R₆ (after q1, q2, q3); returns the next row. With the
    wrist singular (h₆ turned onto h₄: q5's double root) q4 + q6 is a continuum: q4 = 0 and the row is flagged."""
    h4, h5, h6 = row3(h, 3), row3(h, 4), row3(h, 5)
    n5, a5, b5 = sp4(h4, h5, h6, dot3(h4, mv(Rw, h6)))
    n5, a5, b5 = _one_if_double(n5, a5, b5)
    for i5 in range(max(n5, 0)):
        q5 = a5 if i5 == 0 else b5
        R5 = rotation(h5, q5)
        m4, q4 = sp1(h4, mv(R5, h6), mv(Rw, h6))
        _, q6 = sp1(h6, h5, mtv(mm(rotation(h4, q4), R5), mv(Rw, h5)))
        out[row, 0], out[row, 1], out[row, 2] = wrap(q1), wrap(q2), wrap(q3)
        out[row, 3], out[row, 4], out[row, 5] = wrap(q4), wrap(q5), wrap(q6)
        free[row] = flag or m4 == DEGENERATE or n5 == 1
        row += 1
    return row


@njit(cache=True)
def _placed(row, lower, upper, ref, use_ref, slack, out):
    """Each angle's copy θ + 2πk within [lower, upper] (slack allowed, then clipped), nearest ``ref`` (else
    nearest 0, the copy in (−π, π] when it is inside), into ``out``; False when a joint has no copy inside."""
    for j in range(row.shape[0]):
        aim = ref[j] if use_ref else 0.0
        x = row[j] + TWO_PI * np.round((aim - row[j]) / TWO_PI)
        if x < lower[j] - slack:
            x += TWO_PI
        elif x > upper[j] + slack:
            x -= TWO_PI
        if x < lower[j] - slack or x > upper[j] + slack:
            return False
        out[j] = min(max(x, lower[j]), upper[j])
    return True


@njit(cache=True)
def branches(kind, mirrored, h, o, R0, N0, H, lower, upper, ref, use_ref, same, slack, out, found, free):
    """Every distinct branch of the pose H (4 × 4, base frame) within the limits, in the robot's joint order.

    Roots closer than ``same`` [rad] joint by joint (modulo 2π) are one branch (``found`` counts them); each
    angle is moved to its copy within the limits nearest ``ref`` (:func:`_placed`). A mirrored class solves
    H⁻¹ with the chain read from the tool back and turns its rows back (q = −q' reversed).

    Returns:
        The number of branches written into ``out`` (rows), ``found`` and ``free`` (one of a continuum).
    """
    n = h.shape[0]
    Rt, pt = mat9(H), (H[0, 3], H[1, 3], H[2, 3])
    if mirrored:
        pt = scale3(mtv(Rt, pt), -1.0)
        Rt = transpose(Rt)
    R0t, N0t = mat9(R0), (N0[0], N0[1], N0[2])
    raw, loose = np.empty((MAX_ROWS, n)), np.zeros(MAX_ROWS, dtype=np.bool_)
    if kind == PARALLEL_6R:
        count = parallel_6r(h, o, R0t, N0t, Rt, pt, raw, loose)
    elif kind == SPHERICAL_6R:
        count = spherical_6r(h, o, R0t, N0t, Rt, pt, raw, loose)
    elif kind == MEETING_6R:
        count = meeting_6r(h, o, R0t, N0t, Rt, pt, raw, loose)
    elif kind == TWO_THREE_6R:
        count = two_three_6r(h, o, R0t, N0t, Rt, pt, raw, loose)
    else:
        count = parallel_5r(h, o, R0t, N0t, Rt, pt, raw, loose)
    m = 0
    row = np.empty(n)
    for r in range(count):
        for j in range(n):
            row[j] = -raw[r, n - 1 - j] if mirrored else raw[r, j]
        merged = False
        for k in range(m):
            if _close(row, out[k], same):
                found[k] += 1
                free[k] = free[k] or loose[r]
                merged = True
                break
        if not merged and _placed(row, lower, upper, ref, use_ref, slack, out[m]):
            found[m], free[m] = 1, loose[r]
            m += 1
    return m


@njit(cache=True, inline="always")
def _close(a, b, same):
    """a and b equal joint by joint to ``same``, angles modulo 2π."""
    for j in range(a.shape[0]):  # noqa: SIM110 (numba compiles loops, not all() over a generator)
        if abs(wrap(a[j] - b[j])) > same:
            return False
    return True


@njit(cache=True, parallel=True)
def branches_batch(kind, mirrored, h, o, R0, N0, H, lower, upper, same, slack, out, found, free, count):
    """:func:`branches` for every pose of the (B, 4, 4) stack H, in threads (copies nearest 0).

    Args:
        kind: the class's kernel code (PARALLEL_5R, PARALLEL_6R, SPHERICAL_6R, MEETING_6R or TWO_THREE_6R).
        mirrored: the class is solved read from the tool back.
        h: (n, 3) unit axes at q = 0 in the solved orientation.
        o: (n, 3) points on them [m].
        R0: the tool's rotation at q = 0.
        N0: the tool's point at q = 0 [m].
        H: (B, 4, 4) target poses, base frame.
        lower: (n,) joint limits [rad].
        upper: (n,) joint limits [rad].
        same: roots closer than this [rad] are one branch.
        slack: a root this close outside a limit is the limit [rad].
        out: (B, MAX_ROWS, n) branches written.
        found: (B, MAX_ROWS) roots merged into each.
        free: (B, MAX_ROWS) one of a continuum.
        count: (B,) branches per pose.
    """
    n = h.shape[0]
    zero = np.zeros(n)
    for b in prange(H.shape[0]):
        count[b] = branches(kind, mirrored, h, o, R0, N0, H[b], lower, upper, zero, False, same, slack, out[b],
                            found[b], free[b])
