# Included by _analytic.pyx (it shares the subproblems, the vector types and the row writer).
#
# Every branch of a 6R arm outside the closed-form classes, by a 1-D search (after Elias & Wen's IK-Geo):
# two consecutive wrist axes meet (4 and 5 at p, or 5 and 6 at p) and the first three joints place a point in
# closed form (h₂ ∥ h₃, axes 1 and 2 meeting, or axes 2 and 3 meeting). The joint left over (6 when axes 4 and
# 5 meet, 4 when axes 5 and 6 do) is the search variable t. At each t the meeting point's target follows, joints
# 1–3 place it (up to 4 ways, each a branch of the search), and the two meeting joints must turn the rotation
# left over, Rrem = R_a·R_b, which two joints can do only when the error
#
#     e(t) = h_aᵀ·Rrem·h_b − h_aᵀ·h_b
#
# vanishes. Each branch's e is sampled at SAMPLES points of the turn; a sign change between samples is refined
# by regula falsi (Illinois) to rounding; a local minimum of |e| that keeps its sign is searched (golden section)
# for a pair of close roots or a double root; where a branch ends between two samples (its subproblem loses its
# roots) the end is found by bisection and the error there compared with the last sample, since the branch
# folds back into its partner. Every root then gives its six angles in closed form.

cdef enum:
    SEARCH_PAR23_45 = 5  # h₂ ∥ h₃; axes 4, 5 meeting; t = q6
    SEARCH_MEET12_45 = 6  # axes 1, 2 meeting; axes 4, 5 meeting; t = q6
    SEARCH_MEET23_45 = 7  # axes 2, 3 meeting; axes 4, 5 meeting; t = q6
    SEARCH_PAR23_56 = 8  # h₂ ∥ h₃; axes 5, 6 meeting; t = q4
    SEARCH_MEET12_56 = 9
    SEARCH_MEET23_56 = 10
    SAMPLES = 400  # samples of t over one turn
    WAYS = 4  # branches of the search (2 roots × 2 roots)
    PIECES = 12  # pieces of a stretch between a sample and a way's end

cdef double REFINE_TOL = 1e-15  # [rad] a root's bracket is narrowed to this
cdef double TURN = 0.03  # [rad] a span whose shoulder joints turn more than this between samples is halved
cdef double END_ROOT = 1e-8  # an error this small where a way ends is a root there (the pose met to about as much)
cdef double DOUBLE_ROOT = 1e-10  # a dip of |e| to this is a double root (its pose is met to about as much)
cdef int MAX_DEPTH = 8  # halvings at most (a span of 2π/SAMPLES/256)


cdef struct Search:
    const double* h
    const double* o
    int shoulder  # 0: h₂ ∥ h₃, 1: axes 1, 2 meeting, 2: axes 2, 3 meeting
    bint last_pair  # axes 5 and 6 meet (t = q4); else axes 4 and 5 (t = q6)
    M9 R06  # R_target·R0ᵀ = R₁⋯R₆
    V3 shift  # p_target − R06·N0: the point E(x) = R06·x + shift is where x (at q = 0) goes


cdef void _prepare(Search* S, const double* h, const double* o, int kind, M9 R0, V3 N0, M9 Rt,
                   V3 pt) noexcept nogil:
    """S for the arm (axes h, points o, class ``kind``, tool R0, N0 at q = 0) and the pose (Rt, pt)."""
    S.h, S.o = h, o
    S.shoulder = (kind - SEARCH_PAR23_45) % 3
    S.last_pair = kind >= SEARCH_PAR23_56
    S.R06 = mm(Rt, transpose(R0))
    S.shift = sub3(pt, mv(S.R06, N0))


cdef inline V3 _moved(const Search* S, V3 x) noexcept nogil:
    return add3(mv(S.R06, x), S.shift)


ctypedef (double, double, double) Reach  # (margin, θ₁, θ₂)


cdef Reach sp4_reach(V3 h, V3 k, V3 p, double d) noexcept nogil:
    """Subproblem 4 with its margin: (1 − |x|, θ₁, θ₂), x the cosine of the roots' half-gap, so the margin is
    negative when there is no root (the angles are then those of the reachable d nearest to d); −1 when
    hᵀ·R(k, θ)·p does not depend on θ."""
    cdef double kp = dot3(k, p)
    cdef double a = dot3(h, p) - dot3(h, k) * kp
    cdef double b = dot3(h, cross3(k, p))
    cdef double r = hypot(a, b), x, phi, alpha
    if r < FLAT:
        return (-1.0, 0.0, 0.0)
    x = (d - dot3(h, k) * kp) / r
    phi = atan2(b, a)
    alpha = acos(_min(1.0, _max(-1.0, x)))
    return (1.0 - fabs(x), phi + alpha, phi - alpha)


cdef void _place(const Search* S, V3 P, V3 pw, double* q123, double* margin, int only) noexcept nogil:
    """Joints 1–3 moving the point P (at q = 0) to pw: WAYS triples (q1, q2, q3) into q123 (3 per way), with each
    way's margin (the smaller of its two subproblems': negative when it has no root, its q1 then NaN); only way
    ``only`` when it is not −1."""
    cdef const double* h = S.h
    cdef const double* o = S.o
    cdef V3 h1 = row3(h, 0), h2 = row3(h, 1), h3 = row3(h, 2), o1 = row3(o, 0), o2 = row3(o, 1), o3 = row3(o, 2)
    cdef V3 v = sub3(pw, o1), c, a, b, u
    cdef Reach first, second
    cdef int i, j, w
    cdef double x, y
    if S.shoulder == 0:  # h₂ ∥ h₃: q1 keeps P's component along h₂, q3 from the distance to axis 2, q2 turns
        first = sp4_reach(v, h1, h2, dot3(h2, sub3(P, o1)))
        a, b = sub3(o3, o2), sub3(P, o3)
    elif S.shoulder == 1:  # axes 1, 2 meeting at o1: q3 from the distance to o1, then q1 and q2
        a, b = sub3(o3, o1), sub3(P, o3)
        first = sp4_reach(a, h3, b, 0.5 * (dot3(v, v) - dot3(a, a) - dot3(b, b)))
    else:  # axes 2, 3 meeting at o2: q1 from the distance to o2 (subproblem 3 turns v by −q1), then q3 and q2
        c, b = sub3(o2, o1), sub3(P, o2)
        first = sp4_reach(c, h1, v, 0.5 * (dot3(v, v) + dot3(c, c) - dot3(b, b)))
    for i in range(2):
        if only >= 0 and i != only // 2:
            continue
        x = first[1] if i == 0 else first[2]
        if S.shoulder == 0:
            c = sub3(mtv(rotation(h1, x), v), sub3(o2, o1))
            second = sp4_reach(a, h3, b, 0.5 * (dot3(c, c) - dot3(a, a) - dot3(b, b)))
        elif S.shoulder == 1:
            u = add3(a, mv(rotation(h3, x), b))
            second = sp4_reach(v, h1, h2, dot3(h2, u))
        else:
            x = -x
            u = sub3(mtv(rotation(h1, x), v), c)
            second = sp4_reach(h2, h3, b, dot3(h2, u))
        for j in range(2):
            w = 2 * i + j
            if only >= 0 and w != only:
                continue
            y = second[1] if j == 0 else second[2]
            margin[w] = _min(first[0], second[0])
            if margin[w] < -TANGENT_SLACK:
                q123[3 * w] = NAN
            elif S.shoulder == 0:
                q123[3 * w], q123[3 * w + 1], q123[3 * w + 2] = x, sp1(h2, add3(a, mv(rotation(h3, y), b)), c)[1], y
            elif S.shoulder == 1:
                q123[3 * w], q123[3 * w + 1], q123[3 * w + 2] = y, sp1(h2, u, mtv(rotation(h1, y), v))[1], x
            else:
                q123[3 * w], q123[3 * w + 1], q123[3 * w + 2] = x, sp1(h2, mv(rotation(h3, y), b), u)[1], y


cdef inline V3 turn(V3 k, double theta, V3 v) noexcept nogil:
    """R(k, θ)·v (Rodrigues), k a unit axis."""
    cdef double c = cos(theta), s = sin(theta)
    return add3(add3(scale3(v, c), scale3(cross3(k, v), s)), scale3(k, dot3(k, v) * (1.0 - c)))


cdef void _sample(const Search* S, double t, double* e, double* q, double* q123, double* margin,
                  int only) noexcept nogil:
    """The error of each way at t into e[WAYS] (NaN: the way has no root there), of way ``only`` alone when it is
    not −1; when q is not NULL the six angles into q (6 per way), when q123 is not NULL joints 1–3 into q123 (3
    per way), when margin is not NULL the margins (:func:`_place`).

    The error h_aᵀ·Rrem·h_b − h_aᵀ·h_b is computed as (R₁R₂R₃·h_a')ᵀ·(R06·h_b') with vectors alone: h_a' = h₄,
    h_b' = R₆(t)ᵀ·h₅ for axes 4 and 5 meeting; h_a' = R₄(t)·h₅, h_b' = h₆ for axes 5 and 6."""
    cdef const double* h = S.h
    cdef const double* o = S.o
    cdef int a = 4 if S.last_pair else 3, w
    cdef V3 ha = row3(h, a), hb = row3(h, a + 1), P, pw, left, right
    cdef M9 Rrem, Ra
    cdef double placed[3 * WAYS]
    cdef double reach[WAYS]
    cdef double* q123_ = q123 if q123 != NULL else placed
    cdef double* margin_ = margin if margin != NULL else reach
    cdef double qa, qb, base = dot3(ha, hb)
    if S.last_pair:  # t = q4 turns the meeting point of axes 5 and 6 about axis 4
        P = add3(row3(o, 3), turn(row3(h, 3), t, sub3(row3(o, 4), row3(o, 3))))
        pw = _moved(S, row3(o, 4))
        left, right = turn(row3(h, 3), t, ha), mv(S.R06, hb)
    else:  # t = q6: the meeting point of axes 4 and 5 must be where E·R₆(t)⁻¹ puts it
        P = row3(o, 3)
        pw = _moved(S, add3(row3(o, 5), turn(row3(h, 5), -t, sub3(P, row3(o, 5)))))
        left, right = ha, mv(S.R06, turn(row3(h, 5), -t, hb))
    _place(S, P, pw, q123_, margin_, only)
    for w in range(WAYS):
        e[w] = NAN
        if (only >= 0 and w != only) or q123_[3 * w] != q123_[3 * w]:
            continue
        e[w] = dot3(turn(row3(h, 0), q123_[3 * w], turn(row3(h, 1), q123_[3 * w + 1],
                                                        turn(row3(h, 2), q123_[3 * w + 2], left))), right) - base
        if q == NULL:
            continue
        if S.last_pair:  # Rrem = (R₁R₂R₃R₄)ᵀ·R06 = R₅R₆
            Rrem = mm(transpose(mm(mm(mm(rotation(row3(h, 0), q123_[3 * w]), rotation(row3(h, 1), q123_[3 * w + 1])),
                                      rotation(row3(h, 2), q123_[3 * w + 2])), rotation(row3(h, 3), t))), S.R06)
        else:  # Rrem = (R₁R₂R₃)ᵀ·R06·R₆ᵀ = R₄R₅
            Rrem = mm(transpose(mm(mm(rotation(row3(h, 0), q123_[3 * w]), rotation(row3(h, 1), q123_[3 * w + 1])),
                                   rotation(row3(h, 2), q123_[3 * w + 2]))),
                      mm(S.R06, transpose(rotation(row3(h, 5), t))))
        qa = sp1(ha, hb, mv(Rrem, hb))[1]
        Ra = rotation(ha, qa)
        qb = sp1(hb, ha, mtv(Ra, mv(Rrem, ha)))[1]
        q[6 * w], q[6 * w + 1], q[6 * w + 2] = q123_[3 * w], q123_[3 * w + 1], q123_[3 * w + 2]
        if S.last_pair:
            q[6 * w + 3], q[6 * w + 4], q[6 * w + 5] = t, qa, qb
        else:
            q[6 * w + 3], q[6 * w + 4], q[6 * w + 5] = qa, qb, t


cdef double _way(const Search* S, double t, int w) noexcept nogil:
    cdef double e[WAYS]
    _sample(S, t, e, NULL, NULL, NULL, w)
    return e[w]


cdef double _refine(const Search* S, int w, double a, double ea, double b, double eb) noexcept nogil:
    """The root of way w in [a, b] (ea, eb of opposite signs) by regula falsi, Illinois-modified, to REFINE_TOL;
    NaN when the way loses its roots inside."""
    cdef int side = 0, it
    cdef double c, ec
    for it in range(200):
        if fabs(b - a) <= REFINE_TOL * _max(1.0, fabs(a)):
            break
        c = b - eb * (b - a) / (eb - ea)
        if not (c > _min(a, b) and c < _max(a, b)):
            c = 0.5 * (a + b)
        ec = _way(S, c, w)
        if ec != ec:
            return NAN
        if ec == 0.0:
            return c
        if (ec > 0) == (eb > 0):
            b, eb = c, ec
            if side == 1:
                ea *= 0.5
            side = 1
        else:
            a, ea = c, ec
            if side == -1:
                eb *= 0.5
            side = -1
    return b if fabs(eb) < fabs(ea) else a


cdef int _root(const Search* S, double t, int w, Rows* rows, int row) noexcept nogil:
    """The row of way w at the root t (none when t is NaN); returns the next row."""
    cdef double e[WAYS]
    cdef double q[6 * WAYS]
    if t != t:
        return row
    _sample(S, t, e, q, NULL, NULL, w)
    if e[w] != e[w]:
        return row
    return _write(rows, row, q[6 * w], q[6 * w + 1], q[6 * w + 2], q[6 * w + 3], q[6 * w + 4], q[6 * w + 5], False)


cdef int _edge(const Search* S, int w, double last, double e_last, double outside, double inner, double e_inner,
               Rows* rows, int row) noexcept nogil:
    """Where way w ends between the sample ``last`` (error e_last) and ``outside`` (no roots there): the end by
    bisection, then the stretch from the sample to the end searched piece by piece (near an end a way turns
    steeply, and can cross 0 several times), and the dip of |e| towards 0 and back between ``last`` and the sample
    ``inner`` on its other side (error e_inner, NaN if it has none) when |e| falls towards the end; returns the
    next row. (The way folds back into its partner at the end, whose own call finds the roots on its side.)"""
    cdef int it
    cdef double mid, e_mid, inside = last, end = last, e_end = e_last
    for it in range(40):  # to 2⁻⁴⁰ of a sample step
        mid = 0.5 * (inside + outside)
        e_mid = _way(S, mid, w)
        if e_mid == e_mid:
            inside, end, e_end = mid, mid, e_mid
        else:
            outside = mid
    if end == last:
        return row
    if fabs(e_end) <= END_ROOT:  # a root at the end itself: the fold is a double root of a subproblem
        row = _root(S, end, w, rows, row)
    row = _stretch(S, w, last, e_last, end, e_end, rows, row)
    if e_inner == e_inner and not _opposite(e_inner, e_last) and e_last != 0.0 and fabs(e_last) < fabs(e_inner):
        row = _dip(S, w, _min(last, inner), _max(last, inner), 1.0 if e_last > 0 else -1.0, rows, row)
    return row


cdef int _stretch(const Search* S, int w, double a, double ea, double b, double eb, Rows* rows,
                  int row) noexcept nogil:
    """The roots of way w from a sample a to the way's end b (errors ea, eb), searched over PIECES pieces that
    shrink towards the end as the square of their distance (there e turns like the square root of it): each sign
    change refined, each dip of |e| between pieces searched; returns the next row."""
    cdef double f[PIECES + 1]
    cdef double t[PIECES + 1]
    cdef double sign
    cdef int i
    for i in range(PIECES + 1):
        t[i] = b + (a - b) * ((PIECES - i) / <double> PIECES) ** 2
    f[0], f[PIECES], t[0], t[PIECES] = ea, eb, a, b
    for i in range(1, PIECES):
        f[i] = _way(S, t[i], w)
    for i in range(PIECES):
        if f[i] != f[i] or f[i + 1] != f[i + 1]:
            continue
        if f[i] == 0.0 and i > 0:
            row = _root(S, t[i], w, rows, row)
        elif _opposite(f[i], f[i + 1]):
            row = _root(S, _refine(S, w, t[i], f[i], t[i + 1], f[i + 1]), w, rows, row)
            # a close pair of roots can sit beside a steep crossing, in a neighbouring piece that keeps its sign
            if i > 0 and f[i - 1] == f[i - 1] and f[i - 1] != 0.0 and not _opposite(f[i - 1], f[i]):
                row = _dip(S, w, _min(t[i - 1], t[i]), _max(t[i - 1], t[i]), 1.0 if f[i] > 0 else -1.0, rows, row)
            if i + 2 <= PIECES and f[i + 2] == f[i + 2] and f[i + 2] != 0.0 and not _opposite(f[i + 1], f[i + 2]):
                row = _dip(S, w, _min(t[i + 1], t[i + 2]), _max(t[i + 1], t[i + 2]), 1.0 if f[i + 1] > 0 else -1.0,
                           rows, row)
        elif f[i] != 0.0 and f[i + 1] != 0.0:  # a dip: |e| least at a piece's end, or falling to either end
            sign = 1.0 if f[i] > 0 else -1.0
            if i > 0 and f[i - 1] == f[i - 1] and not _opposite(f[i - 1], f[i]) and fabs(f[i]) < fabs(f[i - 1]) \
                    and fabs(f[i]) <= fabs(f[i + 1]):
                row = _dip(S, w, _min(t[i - 1], t[i + 1]), _max(t[i - 1], t[i + 1]), sign, rows, row)
            elif (i == 0 and fabs(f[0]) < fabs(f[1])) or (i == PIECES - 1 and fabs(f[PIECES]) < fabs(f[i])):
                row = _dip(S, w, _min(t[i], t[i + 1]), _max(t[i], t[i + 1]), sign, rows, row)
    return row


cdef inline bint _opposite(double a, double b) noexcept nogil:
    return (a > 0 and b < 0) or (a < 0 and b > 0)


cdef inline double _turn(const double* qa, const double* qb) noexcept nogil:
    """The largest change of joints 1–3 between two points of a way [rad]."""
    return _max(fabs(wrap(qa[0] - qb[0])), _max(fabs(wrap(qa[1] - qb[1])), fabs(wrap(qa[2] - qb[2]))))


cdef int _span(const Search* S, int w, double ta, double ea, const double* qa, double tb, double eb, const double* qb,
               int depth, Rows* rows, int row) noexcept nogil:
    """The roots of way w between ta and tb, both with roots (errors ea, eb; joints 1–3 qa, qb): where the way's
    joints turn by more than TURN the span is halved (a near-singular shoulder sweeps them fast, and a dip can hide
    between samples), up to MAX_DEPTH times; returns the next row."""
    cdef double e[WAYS]
    cdef double q123[3 * WAYS]
    cdef double tm = 0.5 * (ta + tb), em
    if depth < MAX_DEPTH and _turn(qa, qb) > TURN:
        _sample(S, tm, e, NULL, q123, NULL, w)
        em = e[w]
        if em != em:  # the way breaks inside: an end on each side
            row = _edge(S, w, ta, ea, tm, NAN, NAN, rows, row)
            return _edge(S, w, tb, eb, tm, NAN, NAN, rows, row)
        row = _span(S, w, ta, ea, qa, tm, em, &q123[3 * w], depth + 1, rows, row)
        row = _span(S, w, tm, em, &q123[3 * w], tb, eb, qb, depth + 1, rows, row)
        if not _opposite(ea, em) and not _opposite(em, eb) and fabs(em) < fabs(ea) and fabs(em) < fabs(eb):
            row = _dip(S, w, ta, tb, 1.0 if em > 0 else -1.0, rows, row)
        elif _opposite(ea, em) != _opposite(em, eb) and em != 0.0:
            # one half crosses 0 (steeply, as a fast sweep does), the other keeps its sign: a close pair of roots
            # (or a double root) can sit beside the crossing in the other half, searched as a dip
            if _opposite(ea, em) and eb != 0.0:
                row = _dip(S, w, tm, tb, 1.0 if em > 0 else -1.0, rows, row)
            elif _opposite(em, eb) and ea != 0.0:
                row = _dip(S, w, ta, tm, 1.0 if em > 0 else -1.0, rows, row)
        return row
    if ea == 0.0:
        return _root(S, ta, w, rows, row)
    if _opposite(ea, eb):
        return _root(S, _refine(S, w, ta, ea, tb, eb), w, rows, row)
    return row


cdef double _value(const Search* S, double t, int w, double sign, bint of_margin) noexcept nogil:
    """sign·e of way w at t, or (``of_margin``) minus its margin."""
    cdef double e[WAYS]
    cdef double margin[WAYS]
    _sample(S, t, e, NULL, NULL, margin, w)
    return -margin[w] if of_margin else sign * e[w]


cdef double _golden(const Search* S, int w, double a, double b, double sign, bint of_margin) noexcept nogil:
    """The t in [a, b] where :func:`_value` of way w is least (golden section, 30 steps: 5e-7 of the interval)."""
    cdef double g = 0.6180339887498949, c = b - g * (b - a), d = a + g * (b - a)
    cdef double fc = _value(S, c, w, sign, of_margin), fd = _value(S, d, w, sign, of_margin)
    cdef int it
    for it in range(30):
        if not (fc == fc and fd == fd):
            break
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = _value(S, c, w, sign, of_margin)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = _value(S, d, w, sign, of_margin)
    return 0.5 * (a + b)


cdef int _island(const Search* S, int w, double a, double b, Rows* rows, int row) noexcept nogil:
    """Way w between a and b, without roots at either, where its margin may peak in between: when the peak
    reaches 0 the way exists on a stretch shorter than a sample step, searched from the peak to each of its
    ends; returns the next row."""
    cdef double peak = _golden(S, w, a, b, 1.0, True), e
    if _value(S, peak, w, 1.0, True) > TANGENT_SLACK:
        return row
    e = _way(S, peak, w)
    if e != e:
        return row
    if e == 0.0:
        return _root(S, peak, w, rows, row)
    row = _edge(S, w, peak, e, a, NAN, NAN, rows, row)
    return _edge(S, w, peak, e, b, NAN, NAN, rows, row)


cdef int _dip(const Search* S, int w, double a, double b, double sign, Rows* rows, int row) noexcept nogil:
    """A local minimum of |e| of way w between samples a and b that keeps the sign ``sign``: two close roots
    when sign·e dips below 0 inside, one double root when it touches 0; returns the next row."""
    cdef double m = _golden(S, w, a, b, sign, False), em = _way(S, m, w), ea, eb
    if em != em:
        return row
    if sign * em > 0:  # the dip keeps its sign: a double root only where it touches 0 to rounding
        return _root(S, m, w, rows, row) if sign * em <= DOUBLE_ROOT else row
    if em == 0.0:
        return _root(S, m, w, rows, row)
    # sign·e dips below 0: two roots, one on each side of the dip, however close (never one answer between them)
    ea, eb = _way(S, a, w), _way(S, b, w)
    row = _root(S, _refine(S, w, a, ea, m, em), w, rows, row)
    return _root(S, _refine(S, w, m, em, b, eb), w, rows, row)


cdef int search_6r(const double* h, const double* o, int kind, M9 R0, V3 N0, M9 Rt, V3 pt,
                   Rows* rows) noexcept nogil:
    """Every branch of a 6R arm of a search class (``kind`` SEARCH_*) by the 1-D search; returns the row count."""
    cdef Search S
    cdef double e[(SAMPLES + 2) * WAYS]
    cdef double m[(SAMPLES + 2) * WAYS]
    cdef double q[(SAMPLES + 2) * WAYS * 3]
    cdef double step = TWO_PI / SAMPLES, t0 = -M_PI
    cdef int k, w, j, row = 0
    _prepare(&S, h, o, kind, R0, N0, Rt, pt)
    for k in range(SAMPLES):
        _sample(&S, t0 + k * step, e + k * WAYS, NULL, q + k * WAYS * 3, m + k * WAYS, -1)
    for j in range(2 * WAYS):  # the turn closes: samples SAMPLES and SAMPLES + 1 are samples 0 and 1
        e[SAMPLES * WAYS + j], m[SAMPLES * WAYS + j] = e[j], m[j]
    for j in range(6 * WAYS):
        q[SAMPLES * WAYS * 3 + j] = q[j]
    for k in range(SAMPLES):
        for w in range(WAYS):
            row = _interval(&S, w, k, t0 + k * step, step, e, m, q, rows, row)
    return row


cdef inline bint _suspect(double gz, double ga, double gb, double gc) noexcept nogil:
    """Whether g, positive at both ends of an interval (ga, gb), may reach 0 inside it: the line through either end
    and its outer neighbour (gz before a, gc after b; NaN when unknown) crosses 0 before the other end."""
    return (gz == gz and 2.0 * ga - gz <= 0.0) or (gc == gc and 2.0 * gb - gc <= 0.0)


cdef int _interval(const Search* S, int w, int k, double ta, double step, const double* e, const double* m,
                   const double* q, Rows* rows, int row) noexcept nogil:
    """The roots of way w between samples k and k + 1 (at ta and ta + step; e, m, q: every sample's errors,
    margins and joints 1–3, samples SAMPLES and SAMPLES + 1 repeating 0 and 1); returns the next row.

    Beyond sign changes and ends, two patterns are searched: a dip of |e| towards 0 (a local minimum among the
    samples, or a slope that would reach 0 inside were it kept) and an island (the margin of a way without roots at
    either sample rising towards 0 the same way)."""
    cdef double tb = ta + step
    cdef int a = k * WAYS + w, b = (k + 1) * WAYS + w, c = (k + 2) * WAYS + w
    cdef int z = ((k + SAMPLES - 1) % SAMPLES) * WAYS + w
    cdef double ea = e[a], eb = e[b], ec = e[c], ez = e[z], sign
    if ea != ea and eb != eb:
        if m[a] >= m[z] and m[a] > m[b]:  # the margin peaks at sample k
            return _island(S, w, ta - step, tb, rows, row)
        if _suspect(-m[z], -m[a], -m[b], -m[c]):
            return _island(S, w, ta, tb, rows, row)
        return row
    if ea != ea:
        return _edge(S, w, tb, eb, ta, tb + step, ec, rows, row)
    if eb != eb:
        return _edge(S, w, ta, ea, tb, ta - step, ez, rows, row)
    row = _span(S, w, ta, ea, q + a * 3, tb, eb, q + b * 3, 0, rows, row)
    if _opposite(ea, eb) or ea == 0.0 or eb == 0.0:
        return row
    sign = 1.0 if ea > 0 else -1.0
    if _suspect(sign * ez, sign * ea, sign * eb, sign * ec):
        return _dip(S, w, ta, tb, sign, rows, row)
    if ec == ec and not _opposite(eb, ec) and fabs(eb) < fabs(ea) and fabs(eb) <= fabs(ec):
        row = _dip(S, w, ta, tb + step, sign, rows, row)
    return row
