# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""FABRIK (Aristidou & Lasenby, 2011) as a benchmark reference, compiled like kinelab's own kernels so that a
comparison is of methods, not of languages (see :mod:`kinelab.report.bench.fabrik` for the method as run here).
"""

from libc.math cimport atan2, ceil, cos, sin, sqrt, M_PI
from libc.stdlib cimport free, malloc

from kinelab.core._frdm cimport CONTINUOUS, PRISMATIC, Chain, Packed, chain_fk

from kinelab.core._frdm import pack_chain

cdef double PROGRESS = 1e-3  # a stall: PATIENCE iterations without gaining this share of the best error
cdef int PATIENCE = 10
cdef double SAME_POINT = 1e-9  # [m] a key point nearer a joint's axis than this does not move when the joint turns


cdef inline double dot3(const double* a, const double* b) noexcept nogil:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


cdef void forward_reach(const double* points, const double* axes, int m, const double* target,
                        double* reached) noexcept nogil:
    """``reached`` ← the forward pass: the last point on ``target``, each earlier one (joint k's origin) on the way
    back towards its old position, at its old distance from the next and with its old offset along joint k's axis
    (the next point turns about that axis: the offset is invariant). m + 1 points."""
    cdef double seg[3]
    cdef double d[3]
    cdef double axial, radial, dist, dd
    cdef const double* e
    cdef int k, a
    for a in range(3):
        reached[3 * m + a] = target[a]
    for k in range(m - 1, -1, -1):
        e = axes + 3 * k
        for a in range(3):
            seg[a] = points[3 * (k + 1) + a] - points[3 * k + a]
            d[a] = points[3 * k + a] - reached[3 * (k + 1) + a]
        axial = dot3(seg, e)
        radial = dot3(seg, seg) - axial * axial
        radial = sqrt(radial if radial > 0.0 else 0.0)
        dd = dot3(d, e)
        for a in range(3):
            d[a] = d[a] - e[a] * dd
        dist = sqrt(dot3(d, d))
        for a in range(3):
            reached[3 * k + a] = reached[3 * (k + 1) + a] - axial * e[a]
            if dist > SAME_POINT:
                reached[3 * k + a] += d[a] * (radial / dist)


cdef double _turn(int k, int n, const double* e, const double* o, const double* p, const double* reached,
                  long long kind) noexcept nogil:
    """Joint k's displacement (about or along its axis e[k] through o[k]) that brings the key points downstream of
    it (origins o[k+1:], tool point p) nearest, in least squares, to where the forward pass put them."""
    cdef double sin_part = 0.0, cos_part = 0.0, slide = 0.0, ev, ed
    cdef double v[3]
    cdef double d[3]
    cdef double c[3]
    cdef const double* current
    cdef const double* ek = e + 3 * k
    cdef int j, a
    for j in range(k + 1, n + 1):
        current = o + 3 * j if j < n else p
        if kind == PRISMATIC:
            for a in range(3):
                d[a] = reached[3 * j + a] - current[a]
            slide += dot3(ek, d)
            continue
        for a in range(3):
            v[a] = current[a] - o[3 * k + a]
            d[a] = reached[3 * j + a] - o[3 * k + a]
        ev, ed = dot3(ek, v), dot3(ek, d)
        for a in range(3):
            v[a] = v[a] - ek[a] * ev
            d[a] = d[a] - ek[a] * ed
        c[0], c[1], c[2] = v[1] * d[2] - v[2] * d[1], v[2] * d[0] - v[0] * d[2], v[0] * d[1] - v[1] * d[0]
        sin_part += dot3(ek, c)
        cos_part += dot3(v, d)
    if kind == PRISMATIC:
        return slide / (n - k)
    if sin_part * sin_part + cos_part * cos_part < SAME_POINT * SAME_POINT * SAME_POINT * SAME_POINT:
        return 0.0  # every downstream point lies on the axis: turning the joint moves none of them
    return atan2(sin_part, cos_part)


cdef double _clip(double value, long long kind, double lower, double upper) noexcept nogil:
    cdef double shifted
    if kind == CONTINUOUS:
        return atan2(sin(value), cos(value))
    if kind != PRISMATIC and (value < lower or value > upper):
        shifted = value + 2.0 * M_PI * ceil((lower - value) / (2.0 * M_PI))
        if shifted <= upper:
            return shifted
    value = lower if lower > value else value
    return upper if upper < value else value


cdef double _distance(const double* p, const double* target) noexcept nogil:
    cdef double d0 = p[0] - target[0], d1 = p[1] - target[1], d2 = p[2] - target[2]
    return sqrt(d0 * d0 + d1 * d1 + d2 * d2)


cdef int _attempt(const Chain* ch, const double* lower, const double* upper, const double* target, double* q,
                  double tol, int max_iterations, double* work, double* error_out) noexcept nogil:
    cdef int n = ch.n, it = 0, since = 0, k, iterations = 0
    cdef double* e = work
    cdef double* o = work + 3 * n
    cdef double* points = work + 6 * n
    cdef double* reached = points + 3 * (n + 1)
    cdef double* q_best = reached + 3 * (n + 1)
    cdef double p[3]
    cdef double R[9]
    cdef double error, best
    chain_fk(ch, q, e, o, p, R)
    error = best = _distance(p, target)
    for k in range(n):
        q_best[k] = q[k]
    if error <= tol:
        error_out[0] = error
        return 0
    for it in range(max_iterations):
        iterations = it + 1
        for k in range(3 * n):
            points[k] = o[k]
        points[3 * n], points[3 * n + 1], points[3 * n + 2] = p[0], p[1], p[2]
        forward_reach(points, e, n, target, reached)
        for k in range(n):
            q[k] = _clip(q[k] + _turn(k, n, e, o, p, reached, ch.kind[k]), ch.kind[k], lower[k], upper[k])
            chain_fk(ch, q, e, o, p, R)
        error = _distance(p, target)
        if error <= tol:
            error_out[0] = error
            return iterations
        if error < best * (1.0 - PROGRESS):
            best, since = error, 0
            for k in range(n):
                q_best[k] = q[k]
        else:
            since += 1
            if since == PATIENCE:
                break
    if error > best:
        for k in range(n):
            q[k] = q_best[k]
    error_out[0] = best if best < error else error
    return iterations


def attempt(chain, const double[::1] lower, const double[::1] upper, const double[::1] target, double[::1] q,
            double tol, int max_iterations):
    """FABRIK from q (changed in place) towards the tool point ``target`` [m]; returns (iterations, error [m])."""
    cdef Packed packed = pack_chain(chain)
    cdef int n = packed.n, iterations
    cdef double error = 0.0
    if q.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n or target.shape[0] != 3 or n == 0:
        raise ValueError("attempt: q and the limits one value per joint, a 3-vector target")
    cdef double* work = <double*> malloc(sizeof(double) * (6 * n + 6 * (n + 1) + n))
    if work == NULL:
        raise MemoryError("attempt")
    with nogil:
        iterations = _attempt(&packed.ch, &lower[0], &upper[0], &target[0], &q[0], tol, max_iterations, work, &error)
    free(work)
    return iterations, error
