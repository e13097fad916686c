# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The serial chain's forward kinematics, compiled when kinelab is installed (Cython, no JIT).

A chain is its joints in series: joint i sits at ``placement_R[i]``, ``placement_t[i]`` in joint i−1's frame
(i = 0: the base frame) and turns about, or slides along, ``axis[i]`` (a unit vector in its own frame); the tool
sits at ``tool_R``, ``tool_t`` in the last joint's frame. Units: m, rad. ``kind[i]`` is 1 for a prismatic joint,
anything else for a revolute or continuous one (a continuous joint's q is its angle). The same composition as
Pinocchio's ``forwardKinematics`` + ``updateFramePlacement`` on a serial model: kinelab certifies the two equal
on each robot (:mod:`kinelab.robot.certificate`).
"""

from libc.math cimport cos, sin

from kinelab.core._geometry cimport rotm
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


cdef void fk_chain(int n, const double* placement_R, const double* placement_t, const double* axis,
                   const long long* kind, const double* tool_R, const double* tool_t, const double* q,
                   double* out) noexcept nogil:
    """:func:`fk_row` on the arrays' data (n joints: placement_R n × 3 × 3, placement_t and axis n × 3, row-major)."""
    cdef double R[3][3]
    cdef double t[3]
    cdef int i, j
    for i in range(3):
        t[i] = 0.0
        for j in range(3):
            R[i][j] = 1.0 if i == j else 0.0
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
