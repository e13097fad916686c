# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The collision model's first test, compiled: the joint frames at q from the model's placements and axes, each
object's sphere centre carried by its joint, and the pairs whose spheres are not farther apart than the margin.

A plane obstacle's test is the sphere's height above it. The frames follow Pinocchio's model (a joint's frame is
its parent's, times its placement, times its motion); the test is conservative by construction and is held
against Pinocchio's exact test in the tests.
"""

from libc.math cimport sqrt
from libc.stdlib cimport free, malloc

from kinelab.core._geometry cimport rotm

cdef double PLANE = -1.0  # radius marker of a plane obstacle
cdef int PRISMATIC = 1


cdef inline void _rot(const double* k, double angle, double* out) noexcept nogil:
    rotm(k[0], k[1], k[2], angle, out)


cdef void _frames(const double* q, const long long* parents, int J, const double* place_R, const double* place_t,
                  const double* axis, const long long* kind, const long long* q_index, double* R,
                  double* t) noexcept nogil:
    """Every joint's frame in the base frame at q: R (J, 3, 3), t (J, 3) written (joint 0: identity)."""
    cdef double local[9]
    cdef double motion[9]
    cdef double lt[3]
    cdef const double* P
    cdef double v
    cdef int j, p, a, b
    for a in range(9):
        R[a] = 1.0 if a % 4 == 0 else 0.0
    t[0] = t[1] = t[2] = 0.0
    for j in range(1, J):
        p = parents[j]
        v = q[q_index[j]]
        P = place_R + 9 * j
        lt[0], lt[1], lt[2] = place_t[3 * j], place_t[3 * j + 1], place_t[3 * j + 2]
        if kind[j] == PRISMATIC:
            for a in range(3):
                lt[a] += (P[3 * a] * axis[3 * j] + P[3 * a + 1] * axis[3 * j + 1] + P[3 * a + 2] * axis[3 * j + 2]) * v
            for a in range(9):
                local[a] = P[a]
        else:
            _rot(axis + 3 * j, v, motion)
            for a in range(3):
                for b in range(3):
                    local[3 * a + b] = P[3 * a] * motion[b] + P[3 * a + 1] * motion[3 + b] + P[3 * a + 2] * motion[6 + b]
        for a in range(3):
            t[3 * j + a] = t[3 * p + a] + R[9 * p + 3 * a] * lt[0] + R[9 * p + 3 * a + 1] * lt[1] \
                + R[9 * p + 3 * a + 2] * lt[2]
            for b in range(3):
                R[9 * j + 3 * a + b] = R[9 * p + 3 * a] * local[b] + R[9 * p + 3 * a + 1] * local[3 + b] \
                    + R[9 * p + 3 * a + 2] * local[6 + b]


def candidates(const double[::1] q, const long long[::1] parents, const double[:, :, ::1] place_R,
               const double[:, ::1] place_t, const double[:, ::1] axis, const long long[::1] kind,
               const long long[::1] q_index, const long long[::1] joints, const double[:, ::1] centres,
               const double[::1] radii, const double[:, ::1] normals, const long long[:, ::1] pairs, double margin,
               long long[::1] out) -> int:
    """The indices of the pairs whose spheres the test cannot separate, written into ``out``; returns their count.

    Args:
        q: kinelab's configuration [rad or m].
        parents, place_R, place_t, axis, kind, q_index: per model joint (index 0 the universe) its parent, its
            placement in the parent's frame, its axis, kind (1 prismatic) and the index of its value in q.
        joints, centres, radii, normals: per object its joint, its sphere's centre in that joint's frame [m], radius
            [m] (PLANE −1 for a plane) and a plane's unit normal.
        pairs: (P, 2) object indices; margin [m]; out: (P,) written.
    """
    cdef int J = parents.shape[0], G = joints.shape[0], P = pairs.shape[0], g, a, b, j, k, count = 0, i
    if J < 1 or place_R.shape[0] != J or place_t.shape[0] != J or axis.shape[0] != J or kind.shape[0] != J \
            or q_index.shape[0] != J or centres.shape[0] != G or radii.shape[0] != G or normals.shape[0] != G \
            or out.shape[0] < P or (P and pairs.shape[1] != 2):
        raise ValueError("candidates: inconsistent shapes")
    for i in range(1, J):
        if not 0 <= parents[i] < i or not 0 <= q_index[i] < q.shape[0]:
            raise ValueError("candidates: a parent after its child, or a joint value outside q")
    for g in range(G):
        if not 0 <= joints[g] < J:
            raise ValueError("candidates: an object on an unknown joint")
    for k in range(P):
        if not (0 <= pairs[k, 0] < G and 0 <= pairs[k, 1] < G):
            raise ValueError("candidates: a pair of unknown objects")
    cdef double* block = <double*> malloc(sizeof(double) * (12 * J + 3 * G))
    if block == NULL:
        raise MemoryError("candidates")
    cdef double* R = block
    cdef double* t = block + 9 * J
    cdef double* world = block + 12 * J
    cdef double dx, dy, dz, gap
    with nogil:
        _frames(&q[0], &parents[0], J, &place_R[0, 0, 0], &place_t[0, 0], &axis[0, 0], &kind[0], &q_index[0], R, t)
        for g in range(G):
            j = joints[g]
            for a in range(3):
                world[3 * g + a] = t[3 * j + a] + R[9 * j + 3 * a] * centres[g, 0] + R[9 * j + 3 * a + 1] * centres[g, 1] \
                    + R[9 * j + 3 * a + 2] * centres[g, 2]
        for k in range(P):
            a, b = pairs[k, 0], pairs[k, 1]
            dx, dy, dz = world[3 * a] - world[3 * b], world[3 * a + 1] - world[3 * b + 1], world[3 * a + 2] - world[3 * b + 2]
            if radii[b] == PLANE:
                gap = dx * normals[b, 0] + dy * normals[b, 1] + dz * normals[b, 2] - radii[a]
            else:
                gap = sqrt(dx * dx + dy * dy + dz * dz) - radii[a] - radii[b]
            if gap <= margin:
                out[count] = k
                count += 1
    free(block)
    return count
