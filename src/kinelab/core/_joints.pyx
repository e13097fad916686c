# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""A joint vector's usual check and its Pinocchio form, compiled: ``robot.fk``, ``robot.jacobian_*`` and every check
of a configuration pay these on each call, and from Python they cost more than Pinocchio's FK itself."""

cimport numpy as cnp
from libc.math cimport M_PI, cos, fabs, isfinite, remainder, sin

cnp.import_array()


cdef bint is_plain(object q, Py_ssize_t n):
    if not cnp.PyArray_Check(q):
        return False
    cdef cnp.ndarray a = <cnp.ndarray> q
    if cnp.PyArray_TYPE(a) != cnp.NPY_FLOAT64 or cnp.PyArray_NDIM(a) != 1 or cnp.PyArray_DIM(a, 0) != n:
        return False
    cdef char* data = <char*> cnp.PyArray_DATA(a)
    cdef Py_ssize_t stride = cnp.PyArray_STRIDE(a, 0), i
    cdef double total = 0.0
    for i in range(n):
        total += (<double*> (data + i * stride))[0]
    return isfinite(total)  # NaN and ±inf poison the sum (an overflow too: the caller's slow path decides)


def plain_q(object q, Py_ssize_t n):
    """True when ``q`` is an ndarray of n float64 numbers (any stride), every one finite: the usual configuration,
    which needs neither conversion nor copy."""
    return bool(is_plain(q, n))


cdef class PinForm:
    """Pinocchio's q of kinelab's for one robot: joint k of Pinocchio's order is q[position[k]], or its (cos, sin)
    when ``continuous[k]`` (a continuous joint is two numbers in Pinocchio's q)."""

    cdef cnp.intp_t[::1] position
    cdef unsigned char[::1] continuous
    cdef cnp.npy_intp nq
    cdef bint identity

    def __init__(self, cnp.intp_t[::1] position, unsigned char[::1] continuous, Py_ssize_t nq):
        self.position, self.continuous, self.nq = position, continuous, nq
        self.identity = nq == position.shape[0]
        for k in range(position.shape[0]):
            self.identity = self.identity and position[k] == k and not continuous[k]

    def usual(self, object q):
        """Pinocchio's q of a plain ``q`` (n finite float64 numbers, see :func:`plain_q`): q itself when the two
        orders coincide, else a new array; None for anything else (the caller's check names what is wrong)."""
        if not is_plain(q, self.position.shape[0]):
            return None
        return q if self.identity else self.of(q)

    def of(self, cnp.ndarray q):
        """Pinocchio's q (a new array of nq numbers) of ``q``: n float64 numbers, any stride."""
        cdef char* data = <char*> cnp.PyArray_DATA(q)
        cdef Py_ssize_t stride = cnp.PyArray_STRIDE(q, 0), k, j = 0
        cdef cnp.ndarray out = cnp.PyArray_EMPTY(1, &self.nq, cnp.NPY_FLOAT64, 0)
        cdef double* o = <double*> cnp.PyArray_DATA(out)
        cdef double x
        for k in range(self.position.shape[0]):
            x = (<double*> (data + self.position[k] * stride))[0]
            if self.continuous[k]:
                o[j] = cos(x)
                o[j + 1] = sin(x)
                j += 2
            else:
                o[j] = x
                j += 1
        return out


def turn_distances(const double[:, :] q, const double[:] ref):
    """How far each row of q (k × n angles [rad]) is from ``ref`` (n angles): the largest joint difference, each taken
    modulo 2π into [−π, π]; a new array of k numbers [rad]."""
    cdef cnp.npy_intp k = q.shape[0]
    cdef cnp.ndarray out = cnp.PyArray_EMPTY(1, &k, cnp.NPY_FLOAT64, 0)
    cdef double* o = <double*> cnp.PyArray_DATA(out)
    cdef Py_ssize_t i, j
    cdef double worst, d
    if q.shape[1] != ref.shape[0]:
        raise ValueError(f"turn_distances: rows of {q.shape[1]} angles against a reference of {ref.shape[0]}")
    for i in range(k):
        worst = 0.0
        for j in range(q.shape[1]):
            d = fabs(remainder(q[i, j] - ref[j], 2.0 * M_PI))
            if d > worst:
                worst = d
        o[i] = worst
    return out
