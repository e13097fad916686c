# Geometry written once for every compiled kernel and the judge: the rotation about a unit axis (Rodrigues), and
# the wrap of an angle by whole turns.
# Inline here, so each module that cimports it compiles the same arithmetic in place.

from libc.math cimport M_PI, cos, rint, sin


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
