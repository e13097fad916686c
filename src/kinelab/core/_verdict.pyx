# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The checks a solve makes on its target and on its answer, compiled: arithmetic on Pinocchio's numbers.

Pinocchio computes the tool pose; these functions only compare matrices (a solve in a loop would spend more on a
dozen Python float operations than on the FK itself). Matrices are 4 × 4 homogeneous ones, in any memory order.
"""

from libc.math cimport atan2, fabs, isfinite, sqrt

from kinelab.core._frdm cimport rotation_angle

cdef enum:
    C_NOT_FINITE = 1
    C_NOT_A_ROTATION = 2
    C_NOT_HOMOGENEOUS = 3

NOT_FINITE, NOT_A_ROTATION, NOT_HOMOGENEOUS = C_NOT_FINITE, C_NOT_A_ROTATION, C_NOT_HOMOGENEOUS


cdef int pose_defect_of(const double[:, :] H) noexcept nogil:
    """0, NOT_FINITE or NOT_A_ROTATION (see :func:`pose_defect`)."""
    cdef double T[16]
    cdef int i, j
    for i in range(4):
        for j in range(4):
            T[4 * i + j] = H[i, j]
    return pose_defect_row_major(T)


cdef int pose_defect_row_major(const double* T) noexcept nogil:
    """:func:`pose_defect_of` of a 4 × 4 matrix stored row by row (its first three rows read)."""
    cdef double total = 0.0, gram = 0.0, d, det
    cdef int i, a, b
    for i in range(12):
        total += T[i]
    if not isfinite(total):  # NaN and ±inf poison the sum; so does an overflow of huge finite entries
        for i in range(12):
            if not isfinite(T[i]):
                return C_NOT_FINITE
    for a in range(3):
        for b in range(a, 3):
            d = T[a] * T[b] + T[4 + a] * T[4 + b] + T[8 + a] * T[8 + b] - (1.0 if a == b else 0.0)
            gram = gram if gram >= fabs(d) else fabs(d)
    det = (T[0] * (T[5] * T[10] - T[6] * T[9]) - T[1] * (T[4] * T[10] - T[6] * T[8])
           + T[2] * (T[4] * T[9] - T[5] * T[8]))
    return C_NOT_A_ROTATION if gram > 1e-6 or det < 0.0 else 0


def pose_defect(const double[:, :] H) -> int:
    """0 when the 4 × 4 homogeneous matrix H has finite entries and a rotation block (RᵀR = I to 1e-6, det R > 0);
    else NOT_FINITE or NOT_A_ROTATION."""
    if H.shape[0] != 4 or H.shape[1] != 4:
        raise ValueError("pose_defect: a 4 × 4 matrix expected")
    return pose_defect_of(H)


def first_defect(const double[:, :, :] H) -> tuple:
    """(k, defect) of the first of the (B, 4, 4) homogeneous matrices H that is not a pose — NOT_FINITE, NOT_A_ROTATION
    (see :func:`pose_defect`) or NOT_HOMOGENEOUS (a last row other than (0, 0, 0, 1)) —, else (−1, 0): a batch's
    targets checked in one pass (numpy's stacked checks took 2 ms for 2,000 targets)."""
    if H.shape[1] != 4 or H.shape[2] != 4:
        raise ValueError("first_defect: (B, 4, 4) matrices expected")
    cdef Py_ssize_t b
    cdef int code, j
    for b in range(H.shape[0]):
        code = pose_defect_of(H[b])
        if code == 0:
            for j in range(4):
                if not isfinite(H[b, 3, j]):
                    code = C_NOT_FINITE
                elif H[b, 3, j] != (1.0 if j == 3 else 0.0):
                    code = C_NOT_HOMOGENEOUS if code == 0 else code
        if code != 0:
            return (b, code)
    return (-1, 0)


cdef void pose_errors(const double* T, const double* pstar, const double* Rstar, int axis, double* dp,
                      double* dr) noexcept nogil:
    """dp ← position error [m], dr ← rotation error [rad] of the tool pose T (4 × 4, row-major) against the target
    point pstar and rotation Rstar (3 × 3, row-major): the angle of R*ᵀR, or with ``axis`` = 0, 1, 2 the angle
    between the tool's and the target's x, y or z axes (task "axis"; −1 for the whole rotation)."""
    cdef double d0 = pstar[0] - T[3], d1 = pstar[1] - T[7], d2 = pstar[2] - T[11]
    cdef double u0, u1, u2, v0, v1, v2, c0, c1, c2
    cdef double R[9]
    cdef int i, j
    if axis < 0:
        for i in range(3):
            for j in range(3):
                R[3 * i + j] = T[4 * i + j]
        dr[0] = rotation_angle(R, Rstar)
    else:
        u0, u1, u2 = T[axis], T[4 + axis], T[8 + axis]
        v0, v1, v2 = Rstar[axis], Rstar[3 + axis], Rstar[6 + axis]
        c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        dr[0] = atan2(sqrt(c0 * c0 + c1 * c1 + c2 * c2), u0 * v0 + u1 * v1 + u2 * v2)
    dp[0] = sqrt(d0 * d0 + d1 * d1 + d2 * d2)


cdef tuple verdict_of(const double* T, const double[:, :] H_target, const double[::1] q, const double[::1] lower,
                      const double[::1] upper, int axis):
    """(position error [m], rotation error [rad], q within [lower, upper]) of the tool pose T (4 × 4, row-major)
    against the target H_target (4 × 4, shapes checked by the caller); see :func:`pose_errors`."""
    cdef double p[3]
    cdef double S[9]
    cdef double dp, dr
    cdef int i, j
    cdef bint inside = True
    for i in range(3):
        p[i] = H_target[i, 3]
        for j in range(3):
            S[3 * i + j] = H_target[i, j]
    pose_errors(T, p, S, axis, &dp, &dr)
    for i in range(q.shape[0]):
        inside = inside and lower[i] <= q[i] <= upper[i]
    return dp, dr, inside


def pose_verdict(const double[:, :] H_target, const double[:, :] H_tool, const double[::1] q,
                 const double[::1] lower, const double[::1] upper, int axis) -> tuple:
    """(position error [m], rotation error [rad], q within [lower, upper]) for the homogeneous matrices of the
    target and of the tool (from Pinocchio's FK); see :func:`verdict_of`."""
    if H_target.shape[0] != 4 or H_target.shape[1] != 4 or H_tool.shape[0] != 4 or H_tool.shape[1] != 4 \
            or lower.shape[0] < q.shape[0] or upper.shape[0] < q.shape[0] or axis > 2:
        raise ValueError("pose_verdict: two 4 × 4 matrices, limits for every joint and an axis −1 … 2 expected")
    cdef double T[16]
    cdef int i, j
    for i in range(4):
        for j in range(4):
            T[4 * i + j] = H_tool[i, j]
    return verdict_of(T, H_target, q, lower, upper, axis)


cdef bint take_target(const double[:, :] H, const double[::1] anchor, double radius, double[::1] pstar,
                      double[:, ::1] Rstar) noexcept:
    """True when H (4 × 4) is a proper pose whose point lies within ``radius`` [m] of ``anchor``: its point and
    rotation are then copied into pstar and Rstar (the kernel's target); False, and nothing written, otherwise."""
    cdef int i, j
    if pose_defect_of(H) != 0:
        return False
    cdef double a0 = H[0, 3] - anchor[0], a1 = H[1, 3] - anchor[1], a2 = H[2, 3] - anchor[2]
    if not sqrt(a0 * a0 + a1 * a1 + a2 * a2) <= radius:
        return False
    for i in range(3):
        pstar[i] = H[i, 3]
        for j in range(3):
            Rstar[i, j] = H[i, j]
    return True
