# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The serial chain's forward kinematics, compiled when kinelab is installed (Cython, no JIT).

A chain is its joints in series: joint i sits at ``placement_R[i]``, ``placement_t[i]`` in joint i−1's frame
(i = 0: the base frame) and turns about, or slides along, ``axis[i]`` (a unit vector in its own frame); the tool
sits at ``tool_R``, ``tool_t`` in the last joint's frame. Units: m, rad. ``kind[i]`` is 1 for a prismatic joint,
anything else for a revolute or continuous one (a continuous joint's q is its angle). The same composition as
Pinocchio's ``forwardKinematics`` + ``updateFramePlacement`` on a serial model: kinelab certifies the two equal
on each robot (:mod:`kinelab.robot.certificate`).
"""

import numpy as np

from libc.math cimport cos, fabs, isfinite, sin, sqrt
from libc.stdlib cimport free, malloc

from kinelab.core._geometry cimport log3, rotm
from kinelab.core._verdict cimport pose_errors, verdict_of

cdef int PRISMATIC = 1


cdef inline bint _identity(const double* M) noexcept nogil:
    return M[0] == 1.0 and M[4] == 1.0 and M[8] == 1.0 and M[1] == 0.0 and M[2] == 0.0 and M[3] == 0.0 \
        and M[5] == 0.0 and M[6] == 0.0 and M[7] == 0.0


cdef inline void _compose(double[3][3] R, double[3] t, const double* dR, const double* dt) noexcept nogil:
    """(R, t) ← (R, t) · (dR, dt) (dR 3 × 3 row-major). An identity dR (most joint origins) leaves R as the product
    would: R·I gives R's own values (up to the sign of a zero)."""
    cdef double out[3][3]
    cdef double v[3]
    cdef int i, j
    for i in range(3):
        v[i] = t[i] + R[i][0] * dt[0] + R[i][1] * dt[1] + R[i][2] * dt[2]
    for i in range(3):
        t[i] = v[i]
    if _identity(dR):
        return
    for i in range(3):
        for j in range(3):
            out[i][j] = R[i][0] * dR[j] + R[i][1] * dR[3 + j] + R[i][2] * dR[6 + j]
    for i in range(3):
        for j in range(3):
            R[i][j] = out[i][j]


cdef inline int _coordinate_axis(const double* a) noexcept nogil:
    """0, 1 or 2 when a is ±x, ±y or ±z exactly (most URDF joint axes), else −1."""
    if a[1] == 0.0 and a[2] == 0.0 and (a[0] == 1.0 or a[0] == -1.0):
        return 0
    if a[0] == 0.0 and a[2] == 0.0 and (a[1] == 1.0 or a[1] == -1.0):
        return 1
    if a[0] == 0.0 and a[1] == 0.0 and (a[2] == 1.0 or a[2] == -1.0):
        return 2
    return -1


cdef inline void _turn_about(double[3][3] R, int k, double sign, double angle) noexcept nogil:
    """R ← R · Rot(sign·e_k, angle): the product with Rodrigues' matrix of a coordinate axis, its zero terms left
    out. Each entry is the general product's value (up to the sign of a zero): the matrix's entries are c, ±s and
    c + (1 − c) exactly as :func:`rotm` makes them, and a sum of two products does not depend on its order."""
    cdef double c = cos(angle), s = sign * sin(angle)
    cdef double diagonal = c + (1.0 - c)
    cdef int i = (k + 1) % 3, j = (k + 2) % 3, r
    cdef double ri, rj
    for r in range(3):
        ri, rj = R[r][i], R[r][j]
        R[r][i] = ri * c + rj * s
        R[r][j] = ri * -s + rj * c
        R[r][k] = R[r][k] * diagonal


cdef inline void _turn(double[3][3] R, const double* a, double angle) noexcept nogil:
    """R ← R · Rot(a, angle) (Rodrigues)."""
    cdef double M[3][3]
    cdef double out[3][3]
    cdef int i, j
    cdef int k = _coordinate_axis(a)
    if k >= 0:
        _turn_about(R, k, a[k], angle)
        return
    rotm(a[0], a[1], a[2], angle, &M[0][0])
    for i in range(3):
        for j in range(3):
            out[i][j] = R[i][0] * M[0][j] + R[i][1] * M[1][j] + R[i][2] * M[2][j]
    for i in range(3):
        for j in range(3):
            R[i][j] = out[i][j]


cdef void fk_row(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t,
                 const double[:, ::1] axis, const long long[::1] kind, const double[:, ::1] tool_R,
                 const double[::1] tool_t, const double* q, double* out) noexcept nogil:
    """oMtool at q (one value per joint of ``kind``) into out (4 × 4, row-major)."""
    cdef int n = kind.shape[0]
    if n == 0:
        fk_chain(n, NULL, NULL, NULL, NULL, &tool_R[0, 0], &tool_t[0], q, out)
    else:
        fk_chain(n, &placement_R[0, 0, 0], &placement_t[0, 0], &axis[0, 0], &kind[0], &tool_R[0, 0], &tool_t[0], q,
                 out)


cdef inline void _base_pose(double[3][3] R, double[3] t) noexcept nogil:
    """(R, t) ← the base frame's own pose (identity, origin): where a chain's composition starts."""
    cdef int i, j
    for i in range(3):
        t[i] = 0.0
        for j in range(3):
            R[i][j] = 1.0 if i == j else 0.0


cdef void fk_chain(int n, const double* placement_R, const double* placement_t, const double* axis,
                   const long long* kind, const double* tool_R, const double* tool_t, const double* q,
                   double* out) noexcept nogil:
    """:func:`fk_row` on the arrays' data (n joints: placement_R n × 3 × 3, placement_t and axis n × 3, row-major)."""
    cdef double R[3][3]
    cdef double t[3]
    cdef int i, j
    _base_pose(R, t)
    for i in range(n):
        _compose(R, t, placement_R + 9 * i, placement_t + 3 * i)
        if kind[i] == PRISMATIC:
            for j in range(3):
                t[j] += (R[j][0] * axis[3 * i] + R[j][1] * axis[3 * i + 1] + R[j][2] * axis[3 * i + 2]) * q[i]
        else:
            _turn(R, axis + 3 * i, q[i])
    _compose(R, t, tool_R, tool_t)
    for i in range(3):
        for j in range(3):
            out[4 * i + j] = R[i][j]
        out[4 * i + 3] = t[i]
        out[12 + i] = 0.0
    out[15] = 1.0


def fk_batch(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t, const double[:, ::1] axis,
             const long long[::1] kind, const double[:, ::1] tool_R, const double[::1] tool_t,
             const double[:, ::1] Q, double[:, :, ::1] out):
    """oMtool of every row of Q into out: (B, n) joint values [rad or m] → (B, 4, 4) homogeneous matrices.

    Shapes are the caller's to get right (:mod:`kinelab.core` checks them): placement_R (n, 3, 3),
    placement_t (n, 3), axis (n, 3), kind (n,) int64, tool_R (3, 3), tool_t (3,), Q (B, n), out (B, 4, 4).
    """
    cdef Py_ssize_t b
    with nogil:
        for b in range(Q.shape[0]):
            fk_row(placement_R, placement_t, axis, kind, tool_R, tool_t, &Q[b, 0], &out[b, 0, 0])



cdef void jacobian_chain(int n, const double* placement_R, const double* placement_t, const double* axis,
                         const long long* kind, const double* tool_R, const double* tool_t, const double* q,
                         double* J) noexcept nogil:
    """The tool Jacobian at q with the base's axes at the tool origin (Pinocchio's LOCAL_WORLD_ALIGNED) into J
    (6 × n, row-major, rows [v; ω]): a revolute joint's column is [e × (p − o); e], a prismatic one's [e; 0], with e
    its axis and o its origin in the base frame and p the tool's origin."""
    cdef double R[3][3]
    cdef double t[3]
    cdef double e[3]
    cdef int i, j
    _base_pose(R, t)
    for i in range(n):
        _compose(R, t, placement_R + 9 * i, placement_t + 3 * i)
        for j in range(3):
            e[j] = R[j][0] * axis[3 * i] + R[j][1] * axis[3 * i + 1] + R[j][2] * axis[3 * i + 2]
            J[(3 + j) * n + i] = e[j]  # the origin, until the tool's is known; e kept in the angular rows
            J[j * n + i] = t[j]
        if kind[i] == PRISMATIC:
            for j in range(3):
                t[j] += e[j] * q[i]
        else:
            _turn(R, axis + 3 * i, q[i])
    _compose(R, t, tool_R, tool_t)
    for i in range(n):
        for j in range(3):
            e[j] = J[(3 + j) * n + i]
        if kind[i] == PRISMATIC:
            for j in range(3):
                J[j * n + i] = e[j]
                J[(3 + j) * n + i] = 0.0
            continue
        _column(e, t, J, n, i)


cdef inline void _column(const double* e, const double* p, double* J, int n, int i) noexcept nogil:
    """A revolute joint's linear rows: e × (p − o), o read from (and replaced in) the linear rows of column i."""
    cdef double d0 = p[0] - J[i], d1 = p[1] - J[n + i], d2 = p[2] - J[2 * n + i]
    J[i] = e[1] * d2 - e[2] * d1
    J[n + i] = e[2] * d0 - e[0] * d2
    J[2 * n + i] = e[0] * d1 - e[1] * d0


def jacobian_batch(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t, const double[:, ::1] axis,
                   const long long[::1] kind, const double[:, ::1] tool_R, const double[::1] tool_t,
                   const double[:, ::1] Q, double[:, :, ::1] out):
    """The tool Jacobian of every row of Q, base axes at the tool origin (LOCAL_WORLD_ALIGNED), rows [v; ω]:
    (B, n) joint values [rad or m] → out (B, 6, n). Shapes as :func:`fk_batch` takes them (the caller's to check);
    n ≥ 1."""
    cdef Py_ssize_t b
    cdef int n = kind.shape[0]
    if n == 0 or Q.shape[1] != n or out.shape[0] < Q.shape[0] or out.shape[1] != 6 or out.shape[2] != n:
        raise ValueError("jacobian_batch: (B, n) joint values with n ≥ 1 and a (B, 6, n) output")
    with nogil:
        for b in range(Q.shape[0]):
            jacobian_chain(n, &placement_R[0, 0, 0], &placement_t[0, 0], &axis[0, 0], &kind[0], &tool_R[0, 0],
                           &tool_t[0], &Q[b, 0], &out[b, 0, 0])


cdef bint _finite_row(const double* x, int n) noexcept nogil:
    cdef int i
    for i in range(n):
        if not isfinite(x[i]):
            return False
    return True


cdef void _factor_normal(const double* Jr, int m, int n, double* L, double* inv) noexcept nogil:
    """L (m × m, lower) with L Lᵀ = Jr Jrᵀ + 1e-12 I (Cholesky; Jr m × n row-major, m ≤ 6), and inv[i] = 1 / L[i, i]."""
    cdef int i, j, c
    cdef double acc
    for i in range(m):
        for j in range(i + 1):
            acc = 1e-12 if i == j else 0.0
            for c in range(n):
                acc += Jr[i * n + c] * Jr[j * n + c]
            for c in range(j):
                acc -= L[i * m + c] * L[j * m + c]
            if i == j:
                L[i * m + i] = sqrt(acc)
                inv[i] = 1.0 / L[i * m + i]
            else:
                L[i * m + j] = acc * inv[j]


cdef void _least_norm(const double* Jr, const double* L, const double* inv, int m, int n, const double* v,
                      double* x) noexcept nogil:
    """x = Jrᵀ (L Lᵀ)⁻¹ v: the least-norm joint step for the task motion v (m values) into x (n)."""
    cdef double y[6]
    cdef int i, c
    cdef double acc
    for i in range(m):
        acc = v[i]
        for c in range(i):
            acc -= L[i * m + c] * y[c]
        y[i] = acc * inv[i]
    for i in range(m - 1, -1, -1):
        acc = y[i]
        for c in range(i + 1, m):
            acc -= L[c * m + i] * y[c]
        y[i] = acc * inv[i]
    for c in range(n):
        acc = 0.0
        for i in range(m):
            acc += Jr[i * n + c] * y[i]
        x[c] = acc


cdef void _drift_row(const double* Jr, int m, int n, const double* dx, const double* dq, double* L, double* x,
                     double* drift, double* own) noexcept nogil:
    """One sample of :func:`null_drift`: own = max |J⁺dx|, drift = dq − J⁺J dq (J⁺v = Jᵀ(JJᵀ + 1e-12 I)⁻¹v)."""
    cdef double v[6]
    cdef double inv[6]
    cdef int i, c
    _factor_normal(Jr, m, n, L, inv)
    _least_norm(Jr, L, inv, m, n, dx, x)
    own[0] = 0.0
    for c in range(n):
        if fabs(x[c]) > own[0]:
            own[0] = fabs(x[c])
    for i in range(m):
        v[i] = 0.0
        for c in range(n):
            v[i] += Jr[i * n + c] * dq[c]
    _least_norm(Jr, L, inv, m, n, v, x)
    for c in range(n):
        drift[c] = dq[c] - x[c]


def null_drift(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t, const double[:, ::1] axis,
               const long long[::1] kind, const double[:, ::1] tool_R, const double[::1] tool_t,
               const double[:, ::1] prev, const double[:, ::1] Q, const double[:, ::1] dx, const long long[::1] rows,
               double[:, ::1] drift, double[::1] own):
    """Each sample's motion along the task's null space, for the self-motion check of a tracked path.

    With J the task's ``rows`` of the tool Jacobian (base axes at the tool origin) at ``prev[k]`` and
    J⁺v = Jᵀ(JJᵀ + 1e-12 I)⁻¹v: own[k] = max |J⁺ dx[k]| (the least-norm joint step the target's motion dx[k] asks
    for [rad or m]) and drift[k] = dq − J⁺J dq with dq = Q[k] − prev[k] (a non-finite entry of dq taken as 0). A row
    of prev that is not finite gets drift 0 and own 0. Shapes: prev and Q (K, n), dx (K, 6) [m, rad], rows (m,)
    of 0…5 (m ≤ 6), drift (K, n), own (K,).
    """
    cdef int n = kind.shape[0], m = rows.shape[0], i, c
    cdef Py_ssize_t k, K = prev.shape[0]
    if n == 0 or m == 0 or m > 6 or prev.shape[1] != n or Q.shape[0] != K or Q.shape[1] != n or dx.shape[0] != K \
            or dx.shape[1] != 6 or drift.shape[0] != K or drift.shape[1] != n or own.shape[0] != K:
        raise ValueError("null_drift: prev and Q (K, n), dx (K, 6), 1 to 6 rows, drift (K, n) and own (K,)")
    for i in range(m):
        if not 0 <= rows[i] < 6:
            raise ValueError("null_drift: rows are 0 … 5")
    cdef double* J = <double*> malloc(6 * n * sizeof(double))
    cdef double* Jr = <double*> malloc(6 * n * sizeof(double))
    cdef double* dq = <double*> malloc(2 * n * sizeof(double))
    cdef double L[36]
    cdef double v[6]
    if J == NULL or Jr == NULL or dq == NULL:
        free(J)
        free(Jr)
        free(dq)
        raise MemoryError("null_drift")
    with nogil:
        for k in range(K):
            if not _finite_row(&prev[k, 0], n):
                own[k] = 0.0
                for c in range(n):
                    drift[k, c] = 0.0
                continue
            jacobian_chain(n, &placement_R[0, 0, 0], &placement_t[0, 0], &axis[0, 0], &kind[0], &tool_R[0, 0],
                           &tool_t[0], &prev[k, 0], J)
            for i in range(m):
                v[i] = dx[k, rows[i]]
                for c in range(n):
                    Jr[i * n + c] = J[rows[i] * n + c]
            for c in range(n):
                dq[c] = Q[k, c] - prev[k, c]
                if not isfinite(dq[c]):
                    dq[c] = 0.0
            _drift_row(Jr, m, n, v, dq, L, dq + n, &drift[k, 0], &own[k])
    free(J)
    free(Jr)
    free(dq)


def running_events(const double[:, ::1] drift, double bar, long long[::1] sample, double[::1] moved):
    """Where a running total of the rows of ``drift`` (K, n) [rad or m], reset after each event, first has an entry
    larger than ``bar`` in magnitude: the samples into ``sample`` and that largest entry into ``moved``, as many as
    they hold. Returns the number of events written."""
    cdef Py_ssize_t K = drift.shape[0], k
    cdef int n = drift.shape[1], c, count = 0, room = min(sample.shape[0], moved.shape[0])
    cdef double top
    total = np.zeros(n)
    cdef double[::1] t = total
    with nogil:
        for k in range(K):
            top = 0.0
            for c in range(n):
                t[c] += drift[k, c]
                top = max(top, fabs(t[c]))
            if top > bar and count < room:
                sample[count], moved[count] = k, top
                count += 1
                for c in range(n):
                    t[c] = 0.0
    return count


def rotation_steps(const double[:, :, ::1] R, double[:, :] out):
    """The rotation from each of the K rotations (K, 3, 3) to the next as a base-frame rotation vector [rad]:
    out[k] = R[k − 1] log3(R[k − 1]ᵀ R[k]) for k ≥ 1, out[0] = 0 (out (K, 3))."""
    cdef Py_ssize_t k, K = R.shape[0]
    cdef double D[9]
    cdef double w[3]
    cdef int i, j
    if R.shape[1] != 3 or R.shape[2] != 3 or out.shape[0] < K or out.shape[1] != 3:
        raise ValueError("rotation_steps: (K, 3, 3) rotations and a (K, 3) output")
    with nogil:
        if K:
            out[0, 0] = out[0, 1] = out[0, 2] = 0.0
        for k in range(1, K):
            for i in range(3):
                for j in range(3):
                    D[3 * i + j] = R[k - 1, 0, i] * R[k, 0, j] + R[k - 1, 1, i] * R[k, 1, j] \
                        + R[k - 1, 2, i] * R[k, 2, j]
            log3(D, w)
            for i in range(3):
                out[k, i] = R[k - 1, i, 0] * w[0] + R[k - 1, i, 1] * w[1] + R[k - 1, i, 2] * w[2]


cdef class Judge:
    """The verdict on one answer by the compiled chain FK (the judge a robot's certificate names): the arrays as
    :func:`fk_batch` takes them, held once.

    Args:
        placement_R, placement_t, axis, kind, tool_R, tool_t: the chain (see :func:`fk_batch`).
    """

    def __init__(self, const double[:, :, ::1] placement_R, const double[:, ::1] placement_t,
                 const double[:, ::1] axis, const long long[::1] kind, const double[:, ::1] tool_R,
                 const double[::1] tool_t):
        cdef Py_ssize_t n = kind.shape[0]
        if placement_R.shape[0] != n or placement_t.shape[0] != n or axis.shape[0] != n or tool_R.shape[0] != 3 \
                or tool_R.shape[1] != 3 or tool_t.shape[0] != 3:
            raise ValueError("Judge: a chain of n joints (placements, axes, kinds) and a tool placement")
        self.placement_R, self.placement_t, self.axis, self.kind = placement_R, placement_t, axis, kind
        self.tool_R, self.tool_t = tool_R, tool_t
        self.n = <int> n
        if n:
            self.pR, self.pt, self.pa, self.pk = &placement_R[0, 0, 0], &placement_t[0, 0], &axis[0, 0], &kind[0]
        self.tR, self.tt = &tool_R[0, 0], &tool_t[0]

    def verdict(self, const double[:, :] H_target, const double[::1] q, const double[::1] lower,
                const double[::1] upper, int rot_axis) -> tuple:
        """(position error [m], rotation error [rad], q within [lower, upper]) of the answer q against the target
        (4 × 4, base frame): the angle of R*ᵀR, or with ``rot_axis`` = 0, 1, 2 the angle between that tool axis
        and the target's (task "axis"; −1 for the whole rotation)."""
        cdef Py_ssize_t n = self.kind.shape[0]
        if q.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n or H_target.shape[0] != 4 \
                or H_target.shape[1] != 4 or rot_axis > 2:
            raise ValueError("verdict: a 4 × 4 target, q and limits of one value per joint, an axis −1 … 2")
        cdef double T[16]
        self.pose(&q[0] if n else NULL, T)
        return verdict_of(T, H_target, q, lower, upper, rot_axis)

    def verdicts(self, const double[:, :] H_target, const double[:, ::1] Q, const double[::1] lower,
                 const double[::1] upper, double[::1] position_error, double[::1] rotation_error,
                 unsigned char[::1] within):
        """The verdict on every row of Q (m × n answers) against one target (4 × 4, base frame), in one pass:
        position error [m], rotation error [rad] (the angle of R*ᵀR) and within [lower, upper] written per row."""
        cdef Py_ssize_t n = self.kind.shape[0], m = Q.shape[0], k
        if Q.shape[1] != n or lower.shape[0] != n or upper.shape[0] != n or H_target.shape[0] != 4 \
                or H_target.shape[1] != 4 or position_error.shape[0] < m or rotation_error.shape[0] < m \
                or within.shape[0] < m:
            raise ValueError("verdicts: a 4 × 4 target, (m, n) answers, limits of one value per joint, m outputs")
        cdef double T[16]
        cdef double p[3]
        cdef double S[9]
        cdef int i, j
        cdef bint inside
        for i in range(3):
            p[i] = H_target[i, 3]
            for j in range(3):
                S[3 * i + j] = H_target[i, j]
        for k in range(m):
            self.pose(&Q[k, 0], T)
            pose_errors(T, p, S, -1, &position_error[k], &rotation_error[k])
            inside = True
            for i in range(n):
                inside = inside and lower[i] <= Q[k, i] <= upper[i]
            within[k] = inside

    cdef void pose(self, const double* q, double* T) noexcept nogil:
        """oMtool at q (n values) into T (4 × 4, row-major)."""
        fk_chain(self.n, self.pR, self.pt, self.pa, self.pk, self.tR, self.tt, q, T)
