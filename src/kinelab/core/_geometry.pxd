# Geometry written once for every compiled kernel and the judge: the rotation about a unit axis (Rodrigues), its
# inverse (log3), and the wrap of an angle by whole turns.
# Inline here, so each module that cimports it compiles the same arithmetic in place.

from libc.math cimport M_PI, atan2, cos, rint, sin, sqrt


cdef inline void rotm_cs(double x, double y, double z, double c, double s, double* m) noexcept nogil:
    """Rodrigues' rotation about the unit vector (x, y, z) by the angle whose cosine and sine are c and s."""
    cdef double C = 1.0 - c
    m[0] = c + x * x * C
    m[1] = x * y * C - z * s
    m[2] = x * z * C + y * s
    m[3] = y * x * C + z * s
    m[4] = c + y * y * C
    m[5] = y * z * C - x * s
    m[6] = z * x * C - y * s
    m[7] = z * y * C + x * s
    m[8] = c + z * z * C


cdef inline void rotm(double x, double y, double z, double angle, double* m) noexcept nogil:
    """Rodrigues' rotation by ``angle`` [rad] about the unit vector (x, y, z), row by row into m[9]."""
    rotm_cs(x, y, z, cos(angle), sin(angle), m)


cdef inline double wrap(double theta) noexcept nogil:
    """θ [rad] wrapped into (−π, π] by whole turns, as kinelab.geometry.wrap_to_pi does it, to the last bit: exact for
    an angle already inside, and no trigonometry (NumPy's and the C library's differ by an ulp on some processors)."""
    cdef double turn = 2.0 * M_PI
    cdef double t = theta - turn * rint(theta / turn)
    if t <= -M_PI:
        return t + turn
    if t > M_PI:
        return t - turn
    return t


cdef inline void log3(const double* R, double* w) noexcept nogil:
    """Pinocchio's log3: ω with exp3(ω) = R, |ω| ≤ π."""
    cdef double tr = R[0] + R[4] + R[8], c = 0.5 * (tr - 1.0), theta, s, k
    cdef double axis[3]
    cdef int i, big
    if c > 1.0:
        c = 1.0
    elif c < -1.0:
        c = -1.0
    w[0], w[1], w[2] = R[7] - R[5], R[2] - R[6], R[3] - R[1]
    # θ from both its cosine and its sine: acos alone loses half the digits near a half turn
    theta = atan2(0.5 * sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), c)
    if theta < 1e-4:  # θ/(2 sin θ) by its series
        k = 0.5 + theta * theta / 12.0
        w[0], w[1], w[2] = k * w[0], k * w[1], k * w[2]
        return
    if theta < M_PI - 1e-3:
        k = theta / (2.0 * sin(theta))
        w[0], w[1], w[2] = k * w[0], k * w[1], k * w[2]
        return
    # near a half turn: the axis from the symmetric part, its sign from the antisymmetric one
    big = 0
    for i in range(1, 3):
        if R[4 * i] > R[4 * big]:
            big = i
    axis[big] = sqrt(max((R[4 * big] - c) / (1.0 - c), 0.0))
    for i in range(3):
        if i != big:
            axis[i] = (R[3 * big + i] + R[3 * i + big]) / (2.0 * axis[big] * (1.0 - c))
    if axis[0] * w[0] + axis[1] * w[1] + axis[2] * w[2] < 0.0:
        axis[0], axis[1], axis[2] = -axis[0], -axis[1], -axis[2]
    s = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    w[0], w[1], w[2] = theta * axis[0] / s, theta * axis[1] / s, theta * axis[2] / s
