# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The whole-body step, compiled: a tree's forward kinematics, frame and centre-of-mass Jacobians, every task's
error and rate matrix, the QP (DAQP's C interface) and the integration, in one call.

The tree is Pinocchio's model packed into arrays (:mod:`kinelab.wholebody.compiled`): joint j (1 … nj, parents
before children, 0 the world) sits at ``place[j]`` (R row-major, then t) in its parent's frame and turns about, or
slides along, ``axis[j]`` (its own frame); a free-flyer reads q[iq:iq+7] as (x, y, z, qx, qy, qz, qw) and its
velocity as [v; ω] in its own frame; a mimic joint takes ratio · q[iq] + offset and adds ratio times its column to
its leader's. Every formula is the one :mod:`kinelab.wholebody.evaluate` writes with Pinocchio's calls, and kinelab
certifies the two equal on each robot before this path serves it.
"""

import numpy as np

from libc.math cimport INFINITY, acos, asin, atan2, cos, fabs, sin, sqrt, M_PI
from libc.string cimport memcpy, memset

from kinelab.core._blas cimport dgemm, ready
from kinelab.core._geometry cimport log3, rotm

cdef enum:
    REVOLUTE = 0
    PRISMATIC = 1
    CONTINUOUS = 2
    FREEFLYER = 3
    MIMIC_REVOLUTE = 4
    MIMIC_PRISMATIC = 5

cdef enum:
    T_POSE = 0
    T_POSITION = 1
    T_ORIENTATION = 2
    T_AXIS = 3
    T_RELATIVE = 4
    T_COM = 5

cdef enum:
    EQUALITY = 5  # DAQP's sense of an equality row
    ROWS_MAX = 6


# DAQP's C interface (daqp 0.11's api.h and types.h), called through the pointers the installed module exports
ctypedef struct DAQPProblem:
    int n
    int m
    int ms
    double* H
    double* f
    double* A
    double* bupper
    double* blower
    int* sense
    int* break_points
    int nh
    int problem_type

ctypedef struct DAQPSettings:
    double primal_tol
    double dual_tol
    double zero_tol
    double pivot_tol
    double progress_tol
    int cycle_tol
    int iter_limit
    double fval_bound
    double eps_prox
    double eta_prox
    double rho_soft
    double rel_subopt
    double abs_subopt
    double sing_tol
    double refactor_tol
    double time_limit
    double w_soft
    int eq_reduction
    int presolve

ctypedef struct DAQPResult:
    double* x
    double* lam
    double fval
    double soft_slack
    int exitflag
    int iter
    int nodes
    double solve_time
    double setup_time

ctypedef void (*quadprog_t)(DAQPResult*, DAQPProblem*, DAQPSettings*) noexcept nogil
ctypedef void (*defaults_t)(DAQPSettings*) noexcept nogil

cdef quadprog_t _quadprog = NULL
cdef DAQPSettings _settings
cdef double DAQP_BIG = 1e30
cdef double MAX_COORDINATE = 1e6  # [m or rad] kinelab.robot.space.MAX_COORDINATE
cdef int NOT_FINITE = -101  # the step's flag when its answer overflowed (nothing moved)


def set_daqp(size_t quadprog, size_t defaults):
    """Take DAQP's ``daqp_quadprog`` and ``daqp_default_settings`` (their addresses in the installed module)."""
    global _quadprog
    _quadprog = <quadprog_t> quadprog
    (<defaults_t> defaults)(&_settings)
    _settings.presolve = 0  # a continuous QP: nothing for the mixed-integer presolve to do


def daqp_ready():
    """True once :func:`set_daqp` has run."""
    return _quadprog != NULL


# -- small geometry -------------------------------------------------------------------------------
cdef inline void mat_mul(const double* A, const double* B, double* C) noexcept nogil:
    """C = A · B (3 × 3 row-major; C may not alias)."""
    cdef int i, j
    for i in range(3):
        for j in range(3):
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j]


cdef inline void mat_vec(const double* A, const double* x, double* y) noexcept nogil:
    cdef int i
    for i in range(3):
        y[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2]


cdef inline void mat_tvec(const double* A, const double* x, double* y) noexcept nogil:
    """y = Aᵀ x."""
    cdef int i
    for i in range(3):
        y[i] = A[i] * x[0] + A[3 + i] * x[1] + A[6 + i] * x[2]


cdef inline void compose(const double* M1, const double* M2, double* out) noexcept nogil:
    """out = M1 · M2 for poses stored as R (9, row-major) then t (3)."""
    cdef double v[3]
    mat_mul(M1, M2, out)
    mat_vec(M1, &M2[9], v)
    out[9], out[10], out[11] = M1[9] + v[0], M1[10] + v[1], M1[11] + v[2]


cdef inline void cross(const double* a, const double* b, double* c) noexcept nogil:
    c[0] = a[1] * b[2] - a[2] * b[1]
    c[1] = a[2] * b[0] - a[0] * b[2]
    c[2] = a[0] * b[1] - a[1] * b[0]


cdef inline double norm3(const double* a) noexcept nogil:
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


cdef void jlog3(const double* w, double* J) noexcept nogil:
    """Pinocchio's Jlog3 at the rotation exp3(ω): I + ½[ω]× + a[ω]×², a = 1/θ² − (1 + cos θ)/(2θ sin θ)."""
    cdef double t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], theta = sqrt(t2), a
    cdef double W[9]
    cdef double W2[9]
    if theta < 1e-4:
        a = 1.0 / 12.0 + t2 / 720.0
    else:
        a = 1.0 / t2 - (1.0 + cos(theta)) / (2.0 * theta * sin(theta))
    W[0], W[1], W[2] = 0.0, -w[2], w[1]
    W[3], W[4], W[5] = w[2], 0.0, -w[0]
    W[6], W[7], W[8] = -w[1], w[0], 0.0
    mat_mul(W, W, W2)
    cdef int i
    for i in range(9):
        J[i] = 0.5 * W[i] + a * W2[i]
    J[0] += 1.0
    J[4] += 1.0
    J[8] += 1.0


cdef void quat_to_matrix(double x, double y, double z, double qw, double* R) noexcept nogil:
    """The rotation of the unit quaternion (x, y, z, w) (Pinocchio's free-flyer order)."""
    R[0] = 1.0 - 2.0 * (y * y + z * z)
    R[1] = 2.0 * (x * y - z * qw)
    R[2] = 2.0 * (x * z + y * qw)
    R[3] = 2.0 * (x * y + z * qw)
    R[4] = 1.0 - 2.0 * (x * x + z * z)
    R[5] = 2.0 * (y * z - x * qw)
    R[6] = 2.0 * (x * z - y * qw)
    R[7] = 2.0 * (y * z + x * qw)
    R[8] = 1.0 - 2.0 * (x * x + y * y)


cdef void matrix_to_quat(const double* R, double* q) noexcept nogil:
    """(x, y, z, w) of a rotation (Shepperd's method), w ≥ 0."""
    cdef double tr = R[0] + R[4] + R[8], s
    if tr > 0.0:
        s = 2.0 * sqrt(tr + 1.0)
        q[3], q[0], q[1], q[2] = 0.25 * s, (R[7] - R[5]) / s, (R[2] - R[6]) / s, (R[3] - R[1]) / s
    elif R[0] > R[4] and R[0] > R[8]:
        s = 2.0 * sqrt(1.0 + R[0] - R[4] - R[8])
        q[3], q[0], q[1], q[2] = (R[7] - R[5]) / s, 0.25 * s, (R[1] + R[3]) / s, (R[2] + R[6]) / s
    elif R[4] > R[8]:
        s = 2.0 * sqrt(1.0 + R[4] - R[0] - R[8])
        q[3], q[0], q[1], q[2] = (R[2] - R[6]) / s, (R[1] + R[3]) / s, 0.25 * s, (R[5] + R[7]) / s
    else:
        s = 2.0 * sqrt(1.0 + R[8] - R[0] - R[4])
        q[3], q[0], q[1], q[2] = (R[3] - R[1]) / s, (R[2] + R[6]) / s, (R[5] + R[7]) / s, 0.25 * s
    if q[3] < 0.0:
        q[0], q[1], q[2], q[3] = -q[0], -q[1], -q[2], -q[3]
    s = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])  # unit, whatever rounding did
    q[0], q[1], q[2], q[3] = q[0] / s, q[1] / s, q[2] / s, q[3] / s


cdef void exp6(const double* v, double* M) noexcept nogil:
    """exp of the twist [v; ω] (6) as a pose: R = exp3(ω), t = V(ω) v."""
    cdef double t2 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5], theta = sqrt(t2), a, b, c
    cdef double W[9]
    cdef double W2[9]
    cdef double V[9]
    cdef int i
    W[0], W[1], W[2] = 0.0, -v[5], v[4]
    W[3], W[4], W[5] = v[5], 0.0, -v[3]
    W[6], W[7], W[8] = -v[4], v[3], 0.0
    mat_mul(W, W, W2)
    if theta < 1e-4:
        a, b, c = 1.0 - t2 / 6.0, 0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0
    else:
        a, b, c = sin(theta) / theta, (1.0 - cos(theta)) / t2, (theta - sin(theta)) / (t2 * theta)
    for i in range(9):
        M[i] = a * W[i] + b * W2[i]
        V[i] = b * W[i] + c * W2[i]
    M[0] += 1.0
    M[4] += 1.0
    M[8] += 1.0
    V[0] += 1.0
    V[4] += 1.0
    V[8] += 1.0
    mat_vec(V, v, &M[9])


# -- the tree -------------------------------------------------------------------------------------
cdef class Tree:
    """A Pinocchio model packed for the compiled step (see the module's docstring)."""

    cdef public int nj, nq, nv
    cdef int[::1] parent, kind, iq, iv, vjoint
    cdef double[::1] ratio, offset, mass, qlo, qhi
    cdef double[:, ::1] place, axis, lever
    cdef double[:, ::1] oM  # (nj + 1, 12) world placement of each joint after its motion
    cdef double[:, ::1] sub  # (nj + 1, 4) subtree mass and Σ m·c (world)
    cdef double total_mass

    def __init__(self, int[::1] parent, int[::1] kind, int[::1] iq, int[::1] iv, double[::1] ratio,
                 double[::1] offset, double[:, ::1] place, double[:, ::1] axis, double[::1] mass,
                 double[:, ::1] lever, int nq, int nv, double[::1] qlo, double[::1] qhi):
        cdef int j
        self.qlo, self.qhi = qlo, qhi
        self.nj = parent.shape[0] - 1
        self.parent, self.kind, self.iq, self.iv = parent, kind, iq, iv
        self.ratio, self.offset, self.place, self.axis = ratio, offset, place, axis
        self.mass, self.lever, self.nq, self.nv = mass, lever, nq, nv
        self.oM = np.zeros((self.nj + 1, 12))
        self.sub = np.zeros((self.nj + 1, 4))
        self.oM[0, 0] = self.oM[0, 4] = self.oM[0, 8] = 1.0
        self.total_mass = float(np.sum(mass))
        self.vjoint = np.zeros(nv, dtype=np.intc)  # the joint of each velocity (0: a free-flyer's, or none)
        for j in range(1, self.nj + 1):
            if kind[j] in (REVOLUTE, PRISMATIC, CONTINUOUS):
                self.vjoint[iv[j]] = j

    cdef int check(self, const double* q) noexcept nogil:
        """0 when q is nq finite numbers within MAX_COORDINATE with unit quaternions and (cos, sin) pairs (1e-6),
        else 1."""
        cdef int j, i
        cdef double s
        for i in range(self.nq):
            if not (fabs(q[i]) <= MAX_COORDINATE):  # NaN, ±inf, or beyond what a rate of it holds
                return 1
        for j in range(1, self.nj + 1):
            i = self.iq[j]
            if self.kind[j] == FREEFLYER:
                s = q[i + 3] * q[i + 3] + q[i + 4] * q[i + 4] + q[i + 5] * q[i + 5] + q[i + 6] * q[i + 6]
                if fabs(sqrt(s) - 1.0) > 1e-6:
                    return 1
            elif self.kind[j] == CONTINUOUS:
                if fabs(sqrt(q[i] * q[i] + q[i + 1] * q[i + 1]) - 1.0) > 1e-6:
                    return 1
        return 0

    cdef void bounds(self, const double* q, double dt, const double* vmax, bint position, const double* amax,
                     const double* v_prev, double slack, double* lo, double* hi, unsigned char* returning) noexcept nogil:
        """The bounds on v that keep q ⊕ v·dt within the position limits and |v| within vmax (and, with amax,
        |v − v_prev| ≤ amax·dt); a joint outside its limits only comes back, at most at its velocity limit
        (``returning``): :func:`kinelab.wholebody.limits.bounds`, compiled."""
        cdef int j, i, v
        cdef double pl, pu, a_lo, a_hi
        for v in range(self.nv):
            lo[v], hi[v], returning[v] = -vmax[v], vmax[v], 0
        if position:
            for j in range(1, self.nj + 1):
                if self.kind[j] != REVOLUTE and self.kind[j] != PRISMATIC:
                    continue
                i, v = self.iq[j], self.iv[j]
                pl, pu = (self.qlo[i] - q[i]) / dt, (self.qhi[i] - q[i]) / dt
                if pl > slack / dt:
                    lo[v], hi[v], returning[v] = min(pl, vmax[v]), min(pu, vmax[v]), 1
                elif pu < -slack / dt:
                    lo[v], hi[v], returning[v] = max(pl, -vmax[v]), max(pu, -vmax[v]), 1
                else:
                    lo[v], hi[v] = max(pl, -vmax[v]), min(pu, vmax[v])
                    if amax != NULL and amax[v] < INFINITY:  # no faster than it can still stop before the limit
                        hi[v] = min(hi[v], _braking(pu * dt, amax[v], dt))
                        lo[v] = max(lo[v], -_braking(-pl * dt, amax[v], dt))
        if amax != NULL and v_prev != NULL:
            for v in range(self.nv):  # the acceleration yields where it cannot keep within the others
                a_lo, a_hi = v_prev[v] - amax[v] * dt, v_prev[v] + amax[v] * dt
                if a_hi < lo[v]:
                    hi[v] = lo[v]
                elif a_lo > hi[v]:
                    lo[v] = hi[v]
                else:
                    lo[v], hi[v] = max(lo[v], a_lo), min(hi[v], a_hi)

    cdef void forward(self, const double* q) noexcept nogil:
        """Every joint's world placement at q."""
        cdef int j, k
        cdef double value, M[12], L[12]
        for j in range(1, self.nj + 1):
            k = self.kind[j]
            memset(M, 0, 12 * sizeof(double))
            if k == FREEFLYER:
                quat_to_matrix(q[self.iq[j] + 3], q[self.iq[j] + 4], q[self.iq[j] + 5], q[self.iq[j] + 6], M)
                M[9], M[10], M[11] = q[self.iq[j]], q[self.iq[j] + 1], q[self.iq[j] + 2]
            else:
                value = q[self.iq[j]]
                if k == CONTINUOUS:
                    value = atan2_(q[self.iq[j] + 1], q[self.iq[j]])
                elif k == MIMIC_REVOLUTE or k == MIMIC_PRISMATIC:
                    value = self.ratio[j] * value + self.offset[j]
                if k == PRISMATIC or k == MIMIC_PRISMATIC:
                    M[0] = M[4] = M[8] = 1.0
                    M[9], M[10], M[11] = self.axis[j, 0] * value, self.axis[j, 1] * value, self.axis[j, 2] * value
                else:
                    rotm(self.axis[j, 0], self.axis[j, 1], self.axis[j, 2], value, M)
            compose(&self.place[j, 0], M, L)
            compose(&self.oM[self.parent[j], 0], L, &self.oM[j, 0])

    cdef void frame(self, int joint, const double* fplace, double* out) noexcept nogil:
        """A frame's world placement (after :meth:`forward`)."""
        compose(&self.oM[joint, 0], fplace, out)

    cdef void jacobian(self, int joint, const double* p, double* J) noexcept nogil:
        """The 6 × nv Jacobian, world axes, of the point p (world) moving with ``joint`` (rows [linear; angular],
        row-major): Pinocchio's LOCAL_WORLD_ALIGNED Jacobian of a frame at p."""
        cdef int j = joint, k, a, c, nv = self.nv
        cdef double w[3], lin[3], d[3], r
        memset(J, 0, 6 * nv * sizeof(double))
        while j != 0:
            k = self.kind[j]
            d[0], d[1], d[2] = p[0] - self.oM[j, 9], p[1] - self.oM[j, 10], p[2] - self.oM[j, 11]
            if k == FREEFLYER:
                for a in range(3):
                    c = self.iv[j] + a
                    w[0], w[1], w[2] = self.oM[j, a], self.oM[j, 3 + a], self.oM[j, 6 + a]
                    J[c], J[nv + c], J[2 * nv + c] = w[0], w[1], w[2]
                    cross(w, d, lin)
                    c = self.iv[j] + 3 + a
                    J[c], J[nv + c], J[2 * nv + c] = lin[0], lin[1], lin[2]
                    J[3 * nv + c], J[4 * nv + c], J[5 * nv + c] = w[0], w[1], w[2]
            else:
                mat_vec(&self.oM[j, 0], &self.axis[j, 0], w)
                r = self.ratio[j] if k == MIMIC_REVOLUTE or k == MIMIC_PRISMATIC else 1.0
                c = self.iv[j]
                if k == PRISMATIC or k == MIMIC_PRISMATIC:
                    J[c] += r * w[0]
                    J[nv + c] += r * w[1]
                    J[2 * nv + c] += r * w[2]
                else:
                    cross(w, d, lin)
                    J[c] += r * lin[0]
                    J[nv + c] += r * lin[1]
                    J[2 * nv + c] += r * lin[2]
                    J[3 * nv + c] += r * w[0]
                    J[4 * nv + c] += r * w[1]
                    J[5 * nv + c] += r * w[2]
            j = self.parent[j]

    cdef void com(self, double* c, double* Jc) noexcept nogil:
        """The centre of mass (world) and its 3 × nv Jacobian (after :meth:`forward`)."""
        cdef int j, k, a, col, nv = self.nv
        cdef double body[3], w[3], d[3], lin[3], m, r
        memset(&self.sub[0, 0], 0, (self.nj + 1) * 4 * sizeof(double))
        for j in range(self.nj, 0, -1):
            m = self.mass[j]
            mat_vec(&self.oM[j, 0], &self.lever[j, 0], body)
            self.sub[j, 0] += m
            for a in range(3):
                self.sub[j, 1 + a] += m * (body[a] + self.oM[j, 9 + a])
            k = self.parent[j]
            for a in range(4):
                self.sub[k, a] += self.sub[j, a]
        for a in range(3):
            c[a] = self.sub[0, 1 + a] / self.total_mass
        memset(Jc, 0, 3 * nv * sizeof(double))
        for j in range(1, self.nj + 1):
            k = self.kind[j]
            m = self.sub[j, 0] / self.total_mass
            for a in range(3):  # Σ m (c − o) over the subtree, over the total mass
                d[a] = (self.sub[j, 1 + a] - self.sub[j, 0] * self.oM[j, 9 + a]) / self.total_mass
            if k == FREEFLYER:
                for a in range(3):
                    w[0], w[1], w[2] = self.oM[j, a], self.oM[j, 3 + a], self.oM[j, 6 + a]
                    col = self.iv[j] + a
                    Jc[col], Jc[nv + col], Jc[2 * nv + col] = m * w[0], m * w[1], m * w[2]
                    cross(w, d, lin)
                    col = self.iv[j] + 3 + a
                    Jc[col], Jc[nv + col], Jc[2 * nv + col] = lin[0], lin[1], lin[2]
                continue
            mat_vec(&self.oM[j, 0], &self.axis[j, 0], w)
            r = self.ratio[j] if k == MIMIC_REVOLUTE or k == MIMIC_PRISMATIC else 1.0
            col = self.iv[j]
            if k == PRISMATIC or k == MIMIC_PRISMATIC:
                lin[0], lin[1], lin[2] = m * w[0], m * w[1], m * w[2]
            else:
                cross(w, d, lin)
            Jc[col] += r * lin[0]
            Jc[nv + col] += r * lin[1]
            Jc[2 * nv + col] += r * lin[2]

    cdef void integrate(self, const double* q, const double* v, double dt, double* out) noexcept nogil:
        """out = q ⊕ v·dt (Pinocchio's integrate for these joints)."""
        cdef int j, k, i, a
        cdef double angle, M[12], T[12], P[12], tw[6]
        memcpy(out, q, self.nq * sizeof(double))
        for j in range(1, self.nj + 1):
            k = self.kind[j]
            i = self.iq[j]
            if k == REVOLUTE or k == PRISMATIC:
                out[i] = q[i] + v[self.iv[j]] * dt
            elif k == CONTINUOUS:
                angle = atan2_(q[i + 1], q[i]) + v[self.iv[j]] * dt
                out[i], out[i + 1] = cos(angle), sin(angle)
            elif k == FREEFLYER:
                quat_to_matrix(q[i + 3], q[i + 4], q[i + 5], q[i + 6], M)
                M[9], M[10], M[11] = q[i], q[i + 1], q[i + 2]
                for a in range(6):
                    tw[a] = v[self.iv[j] + a] * dt
                exp6(tw, T)
                compose(M, T, P)
                out[i], out[i + 1], out[i + 2] = P[9], P[10], P[11]
                matrix_to_quat(P, &out[i + 3])

    def forward_placements(self, double[::1] q):
        """(nj + 1, 12) every joint's world placement at q (R row-major, t): for the certificate."""
        self.forward(&q[0])
        return np.asarray(self.oM).copy()

    def frame_jacobian(self, double[::1] q, int joint, double[::1] fplace):
        """(pose (12,), 6 × nv Jacobian) of a frame at q: for the certificate."""
        cdef double out[12]
        J = np.zeros((6, self.nv))
        cdef double[:, ::1] Jv = J
        self.forward(&q[0])
        self.frame(joint, &fplace[0], out)
        self.jacobian(joint, &out[9], &Jv[0, 0])
        return np.array([out[i] for i in range(12)]), J

    def center_of_mass(self, double[::1] q):
        """(c (3,), its 3 × nv Jacobian) at q: for the certificate."""
        Jc = np.zeros((3, self.nv))
        c = np.zeros(3)
        cdef double[:, ::1] Jv = Jc
        cdef double[::1] cv = c
        self.forward(&q[0])
        self.com(&cv[0], &Jv[0, 0])
        return c, Jc

    def integrated(self, double[::1] q, double[::1] v, double dt):
        """q ⊕ v·dt: for the certificate."""
        out = np.zeros(self.nq)
        cdef double[::1] o = out
        self.integrate(&q[0], &v[0], dt, &o[0])
        return out


cdef inline double atan2_(double y, double x) noexcept nogil:
    return atan2(y, x)


# -- the step -------------------------------------------------------------------------------------
cdef class Step:
    """One robot's step problem: its tree, its tasks packed (targets set per call), its buffers."""

    cdef Tree tree
    cdef public int ntasks, m1, m2, neq
    cdef int[::1] kind, joint, root, axis, priority, rows
    cdef double[:, ::1] place, root_place, target
    cdef double[::1] wp, wo, gain
    cdef double[::1] post_ref, post_w, damping1, damping2
    cdef double post_gain
    cdef int post_priority
    cdef bint level2
    cdef int[::1] cq, cv, lq, lv, slot, cslot
    cdef int post_slot
    cdef double[::1] cratio, coffset
    # buffers
    cdef double[:, ::1] A1, A2, Jf, Jr, Jc, H, Aeq
    cdef double[::1] b1, b2, w1, w2, f, lower, upper, bl, bu, x, x1, lam, c
    cdef int[::1] sense, warm

    def __init__(self, Tree tree, problem):
        """The step of ``problem`` (:class:`kinelab.wholebody.compiled.StepProblem`: the tasks' blocks, the
        posture, the dampings and the couplings, as named arrays) on ``tree``."""
        cdef int t, n
        cdef int[::1] kind = problem.kind
        cdef int[::1] axis = problem.axis
        cdef int[::1] priority = problem.priority
        ready()  # BLAS from SciPy, once per process
        self.slot, self.post_slot, self.cslot = problem.slot, problem.post_slot, problem.cslot
        self.tree, self.ntasks = tree, kind.shape[0]
        self.kind, self.joint, self.root, self.axis, self.priority = kind, problem.joint, problem.root, axis, priority
        self.place, self.root_place = problem.place, problem.root_place
        self.wp, self.wo, self.gain = problem.wp, problem.wo, problem.gain
        self.post_ref, self.post_w = problem.post_ref, problem.post_w
        self.post_gain, self.post_priority = problem.post_gain, problem.post_priority
        self.damping1, self.damping2 = problem.damping1, problem.damping2
        self.cq, self.cv, self.lq, self.lv = problem.cq, problem.cv, problem.lq, problem.lv
        self.cratio, self.coffset = problem.cratio, problem.coffset
        self.target = np.zeros((self.ntasks, 12))
        self.rows = np.zeros(self.ntasks, dtype=np.intc)
        self.m1 = self.m2 = 0
        for t in range(self.ntasks):
            n = _task_rows(kind[t], axis[t])
            self.rows[t] = n
            if priority[t] == 1:
                self.m1 += n
            else:
                self.m2 += n
        n = tree.nv
        self.neq = self.cq.shape[0]
        self.level2 = self.m2 > 0 or self.post_priority == 2 or np.any(problem.damping2)
        self.A1 = np.zeros((max(self.m1, 1), n))
        self.A2 = np.zeros((max(self.m2, 1), n))
        self.b1, self.w1 = np.zeros(max(self.m1, 1)), np.zeros(max(self.m1, 1))
        self.b2, self.w2 = np.zeros(max(self.m2, 1)), np.zeros(max(self.m2, 1))
        self.Jf, self.Jr, self.Jc = np.zeros((6, n)), np.zeros((6, n)), np.zeros((3, n))
        self.H, self.f = np.zeros((n, n)), np.zeros(n)
        self.Aeq = np.zeros((self.neq + self.m1 + 1, n))
        self.lower, self.upper = np.zeros(n), np.zeros(n)
        self.bl, self.bu = np.zeros(n + self.neq + self.m1 + 1), np.zeros(n + self.neq + self.m1 + 1)
        self.x, self.x1, self.lam = np.zeros(n), np.zeros(n), np.zeros(n + self.neq + self.m1 + 1)
        self.sense = np.zeros(n + self.neq + self.m1 + 1, dtype=np.intc)
        self.warm = np.zeros(n, dtype=np.intc)
        self.c = np.zeros(3)

    def set_target(self, int t, const double[::1] target):
        """Task t's target: a pose (12: R row-major, t) or a centre of mass (3, in the last three)."""
        memcpy(&self.target[t, 0], &target[0], target.shape[0] * sizeof(double))

    def set_pose(self, int t, const double[:, ::1] H):
        """Task t's target pose from its 4 × 4 homogeneous matrix."""
        cdef int i
        for i in range(3):
            self.target[t, 3 * i], self.target[t, 3 * i + 1], self.target[t, 3 * i + 2] = H[i, 0], H[i, 1], H[i, 2]
            self.target[t, 9 + i] = H[i, 3]

    def set_point(self, int t, const double[::1] p):
        """Task t's target point (a centre of mass) [m]."""
        self.target[t, 9], self.target[t, 10], self.target[t, 11] = p[0], p[1], p[2]

    def step(self, const double[::1] q, double dt, const double[::1] vmax, bint position, const double[::1] amax,
             const double[::1] v_prev, double damping, double[::1] q_out, double[::1] v_out, double[:, ::1] errors,
             unsigned char[::1] returning):
        """One step from q: v (v_out), q ⊕ v·dt (q_out), each task's (position, rotation) error before it in its slot
        (errors), the joints brought back into their limits (returning). ``amax`` and ``v_prev``: empty, or nv
        numbers each. Returns (DAQP's exit flag: 1 or 2 solved; −100: q is not a configuration, nothing done;
        −101: the answer overflowed, nothing moved; DAQP's iterations)."""
        cdef int flag, iters = 0, nv = self.tree.nv
        cdef const double* a = &amax[0] if amax.shape[0] == nv else NULL
        cdef const double* vp = &v_prev[0] if v_prev.shape[0] == nv else NULL
        with nogil:
            flag = self._one(&q[0], dt, &vmax[0], position, a, vp, damping, &q_out[0], &v_out[0], &errors[0, 0],
                             &returning[0], &iters)
        return flag, iters

    def step_many(self, const double[:, ::1] Q, double dt, const double[:, :, ::1] T, const double[::1] vmax,
                  bint position, const double[::1] amax, const double[:, ::1] V_prev, double damping,
                  double[:, ::1] Q_out, double[:, ::1] V_out, int[::1] flags, int[::1] iters, int[:, ::1] warm,
                  double[:, ::1] errors, unsigned char[::1] returning):
        """Worlds w = 0..N−1 one after the other, the GIL released throughout: from Q[w] toward the targets T[w]
        (ntasks × 12, as :meth:`set_target` takes them), with world w's own warm start (warm[w], nv; kept for its
        next call), into Q_out[w], V_out[w], flags[w] and iters[w] (:meth:`step`'s). ``V_prev``: (N, nv) or empty;
        ``errors`` (tasks × 2) and ``returning`` (nv): scratch."""
        cdef Py_ssize_t w, n = Q.shape[0]
        cdef int nv = self.tree.nv, it
        cdef const double* a = &amax[0] if amax.shape[0] == nv else NULL
        cdef bint has_vp = V_prev.shape[0] == n and n > 0
        with nogil:
            for w in range(n):
                if self.ntasks > 0:
                    memcpy(&self.target[0, 0], &T[w, 0, 0], self.ntasks * 12 * sizeof(double))
                memcpy(&self.warm[0], &warm[w, 0], nv * sizeof(int))
                it = 0
                flags[w] = self._one(&Q[w, 0], dt, &vmax[0], position, a, &V_prev[w, 0] if has_vp else NULL,
                                     damping, &Q_out[w, 0], &V_out[w, 0], &errors[0, 0], &returning[0], &it)
                iters[w] = it
                memcpy(&warm[w, 0], &self.warm[0], nv * sizeof(int))

    cdef int _one(self, const double* q, double dt, const double* vmax, bint position, const double* a,
                  const double* vp, double damping, double* q_out, double* v_out, double* errors,
                  unsigned char* returning, int* iters) noexcept nogil:
        """:meth:`step`'s work on raw buffers (its flag)."""
        cdef int flag, level, nv = self.tree.nv
        if self.tree.check(q):
            return -100
        self.tree.bounds(q, dt, vmax, position, a, vp, 1e-9, &self.lower[0], &self.upper[0], returning)
        self.tree.forward(q)
        if self._any_com():
            self.tree.com(&self.c[0], &self.Jc[0, 0])
        self._rows(q, dt, errors)
        self._other_errors(q, errors)
        flag = self._solve(1, &self.lower[0], &self.upper[0], damping, q, dt, iters)
        if (flag == 1 or flag == 2) and self.level2:
            memcpy(&self.x1[0], &self.x[0], nv * sizeof(double))
            level = self._solve(2, &self.lower[0], &self.upper[0], damping, q, dt, iters)
            if not (level == 1 or level == 2):
                memcpy(&self.x[0], &self.x1[0], nv * sizeof(double))
        if flag == 1 or flag == 2:
            memcpy(v_out, &self.x[0], nv * sizeof(double))
            self.tree.integrate(q, &self.x[0], dt, q_out)
            if not (_finite(v_out, nv) and _finite(q_out, self.tree.nq)):
                flag = NOT_FINITE
        if not (flag == 1 or flag == 2):
            memset(v_out, 0, nv * sizeof(double))
            memcpy(q_out, q, self.tree.nq * sizeof(double))
        return flag

    cdef void _other_errors(self, const double* q, double* errors) noexcept nogil:
        """The posture's error (its largest joint gap) and each coupling's, into their slots."""
        cdef int j, r
        cdef double worst = 0.0, gap
        if self.post_slot >= 0:
            for j in range(self.tree.nv):
                if self.post_w[j] != 0.0:
                    gap = fabs(_posture_error(self, q, j))
                    if gap > worst:
                        worst = gap
            errors[2 * self.post_slot], errors[2 * self.post_slot + 1] = worst, 0.0
        for r in range(self.neq):
            errors[2 * self.cslot[r]] = fabs(q[self.cq[r]] - self.cratio[r] * q[self.lq[r]] - self.coffset[r])
            errors[2 * self.cslot[r] + 1] = 0.0

    cdef bint _any_com(self) noexcept nogil:
        cdef int t
        for t in range(self.ntasks):
            if self.kind[t] == T_COM:
                return True
        return False

    cdef void _rows(self, const double* q, double dt, double* errors) noexcept nogil:
        """Each task's rows into its level's A, b, w, and its errors."""
        cdef int t, r1 = 0, r2 = 0, n, i, k
        cdef double* A
        cdef double* b
        cdef double* w
        cdef int nv = self.tree.nv
        for t in range(self.ntasks):
            n = self.rows[t]
            if self.priority[t] == 1:
                A, b, w = &self.A1[r1, 0], &self.b1[r1], &self.w1[r1]
                r1 += n
            else:
                A, b, w = &self.A2[r2, 0], &self.b2[r2], &self.w2[r2]
                r2 += n
            self._task(t, A, b, w, &errors[2 * self.slot[t]])
            for i in range(n):
                b[i] = -self.gain[t] * b[i] / dt  # b held e until here

    cdef void _task(self, int t, double* A, double* e, double* w, double* err) noexcept nogil:
        """Task t's rows A (n × nv), error e (n), weights w (n) and its (position, rotation) error."""
        cdef int k = self.kind[t], nv = self.tree.nv, i, j, row
        cdef double F[12], Rr[12], ER[9], tmp[9], JL[9], wv[3], gap[3], a[3], Rt[9]
        cdef double* T = &self.target[t, 0]
        cdef double* Jf = &self.Jf[0, 0]
        cdef double* Jr = &self.Jr[0, 0]
        if k == T_COM:
            row = 0
            for i in range(3):
                if self.axis[t] & (1 << i):
                    e[row] = self.c[i] - T[9 + i]
                    w[row] = self.wp[t]
                    memcpy(&A[row * nv], &self.Jc[i, 0], nv * sizeof(double))
                    row += 1
            err[0], err[1] = _norm(e, row), 0.0
            return
        self.tree.frame(self.joint[t], &self.place[t, 0], F)
        self.tree.jacobian(self.joint[t], &F[9], Jf)
        if k == T_RELATIVE:
            _relative(self, t, F, A, e, w, err)
            return
        for i in range(3):
            gap[i] = F[9 + i] - T[9 + i]
        err[0] = norm3(gap) if k != T_ORIENTATION else 0.0
        if k == T_POSITION:
            memcpy(A, Jf, 3 * nv * sizeof(double))
            e[0], e[1], e[2] = gap[0], gap[1], gap[2]
            w[0] = w[1] = w[2] = self.wp[t]
            err[1] = 0.0
            return
        if k == T_AXIS:
            memcpy(A, Jf, 3 * nv * sizeof(double))
            j = self.axis[t]
            a[0], a[1], a[2] = F[j], F[3 + j], F[6 + j]
            for i in range(3):
                e[i], e[3 + i] = gap[i], a[i] - T[3 * i + j]
                w[i], w[3 + i] = self.wp[t], self.wo[t]
            _skew_rows(a, Jf, &A[3 * nv], nv)  # −[a]× J_angular
            err[1] = 2.0 * _asin_half(_norm(&e[3], 3))
            return
        # pose, orientation: ER = Rfᵀ R*, e = log3(ER), rows −Jlog3(ERᵀ) Rfᵀ J_angular
        _transpose_mul(F, T, ER)
        log3(ER, wv)
        err[1] = norm3(wv)
        for i in range(3):
            a[i] = -wv[i]
        jlog3(a, JL)
        _transpose(F, Rt)
        mat_mul(JL, Rt, tmp)
        row = 0
        if k == T_POSE:
            memcpy(A, Jf, 3 * nv * sizeof(double))
            for i in range(3):
                e[i], w[i] = gap[i], self.wp[t]
            row = 3
        for i in range(3):
            for j in range(nv):
                A[(row + i) * nv + j] = -(tmp[3 * i] * Jf[3 * nv + j] + tmp[3 * i + 1] * Jf[4 * nv + j]
                                          + tmp[3 * i + 2] * Jf[5 * nv + j])
            e[row + i], w[row + i] = wv[i], self.wo[t]

    cdef int _solve(self, int level, const double* lower, const double* upper, double damping, const double* q,
                    double dt, int* iters) noexcept nogil:
        """The level's QP into self.x: H = Aᵀ W A + posture + λI, f = −Aᵀ W b − posture's pull; bounds, the
        couplings and (level 2) the first level's rates as equalities."""
        cdef int nv = self.tree.nv, m = self.m1 if level == 1 else self.m2, i, j, r, neq = 0
        cdef double* A = &self.A1[0, 0] if level == 1 else &self.A2[0, 0]
        cdef double* b = &self.b1[0] if level == 1 else &self.b2[0]
        cdef double* w = &self.w1[0] if level == 1 else &self.w2[0]
        cdef double alpha = 1.0, beta = 0.0, s
        cdef char tr = b'T', nt = b'N'
        cdef DAQPProblem problem
        cdef DAQPResult result
        memset(&self.H[0, 0], 0, nv * nv * sizeof(double))
        memset(&self.f[0], 0, nv * sizeof(double))
        for r in range(m):  # scale rows by √w: H = (√W A)ᵀ(√W A), f = −(√W A)ᵀ(√W b)
            s = sqrt(w[r])
            for j in range(nv):
                A[r * nv + j] *= s
            b[r] *= s
            for j in range(nv):
                self.f[j] -= A[r * nv + j] * b[r]
        if m > 0:
            dgemm(&nt, &tr, &nv, &nv, &m, &alpha, A, &nv, A, &nv, &beta, &self.H[0, 0], &nv)
        for j in range(nv):
            self.H[j, j] += damping + (self.damping1[j] if level == 1 else self.damping2[j])
        if self.post_priority == level:
            for j in range(nv):
                if self.post_w[j] != 0.0:
                    self.H[j, j] += self.post_w[j]
                    self.f[j] += self.post_w[j] * self.post_gain * _posture_error(self, q, j) / dt
        for j in range(nv):  # the bounds active at the last answer start DAQP's working set (a warm start)
            self.bl[j], self.bu[j] = max(lower[j], -DAQP_BIG), min(upper[j], DAQP_BIG)
            self.sense[j] = self.warm[j] if level == 1 else 0
        for r in range(self.neq):
            memset(&self.Aeq[r, 0], 0, nv * sizeof(double))
            self.Aeq[r, self.cv[r]] = 1.0
            self.Aeq[r, self.lv[r]] = -self.cratio[r]
            s = -(q[self.cq[r]] - self.cratio[r] * q[self.lq[r]] - self.coffset[r]) / dt
            self.bl[nv + r] = self.bu[nv + r] = s
            self.sense[nv + r] = EQUALITY
        neq = self.neq
        if level == 2 and self.m1 > 0:  # the first level's rates held at its answer (A1 is √W-scaled already)
            for r in range(self.m1):
                memcpy(&self.Aeq[neq + r, 0], &self.A1[r, 0], nv * sizeof(double))
                s = _dot(&self.A1[r, 0], &self.x1[0], nv)
                self.bl[nv + neq + r] = self.bu[nv + neq + r] = s
                self.sense[nv + neq + r] = EQUALITY
            neq += self.m1
        problem.n, problem.m, problem.ms = nv, nv + neq, nv
        problem.H, problem.f = &self.H[0, 0], &self.f[0]
        problem.A = &self.Aeq[0, 0]
        problem.bupper, problem.blower, problem.sense = &self.bu[0], &self.bl[0], &self.sense[0]
        problem.break_points, problem.nh, problem.problem_type = NULL, 0, 0
        result.x, result.lam = &self.x[0], &self.lam[0]
        _quadprog(&result, &problem, &_settings)
        iters[0] += result.iter
        if level == 1:
            for j in range(nv):  # λ > 0: the upper bound active, λ < 0: the lower one (DAQP's ACTIVE, LOWER bits)
                self.warm[j] = 0 if not (result.exitflag == 1 or result.exitflag == 2) or self.lam[j] == 0.0 \
                    else (1 if self.lam[j] > 0.0 else 3)
        for j in range(nv):  # its bounds hold to its tolerance: exactly here
            self.x[j] = min(max(self.x[j], lower[j]), upper[j])
        return result.exitflag


cdef inline double _braking(double distance, double amax, double dt) noexcept nogil:
    """:func:`kinelab.wholebody.limits.braking`, for one joint with a finite amax."""
    cdef double ad = amax * dt
    return -ad + sqrt(ad * ad + 2.0 * amax * max(distance, 0.0))


cdef inline bint _finite(const double* x, int n) noexcept nogil:
    cdef int i
    for i in range(n):
        if not (x[i] - x[i] == 0.0):  # NaN or ±inf
            return False
    return True


cdef inline int _task_rows(int kind, int axis) noexcept nogil:
    if kind == T_POSE or kind == T_AXIS or kind == T_RELATIVE:
        return 6
    if kind == T_COM:
        return (axis & 1) + ((axis >> 1) & 1) + ((axis >> 2) & 1)
    return 3


cdef inline double _dot(const double* a, const double* b, int n) noexcept nogil:
    cdef double s = 0.0
    cdef int i
    for i in range(n):
        s += a[i] * b[i]
    return s


cdef inline double _norm(const double* e, int n) noexcept nogil:
    cdef double s = 0.0
    cdef int i
    for i in range(n):
        s += e[i] * e[i]
    return sqrt(s)


cdef inline double _asin_half(double x) noexcept nogil:
    return asin(min(1.0, 0.5 * x))


cdef inline void _transpose(const double* M, double* T) noexcept nogil:
    cdef int i, j
    for i in range(3):
        for j in range(3):
            T[3 * i + j] = M[3 * j + i]


cdef inline void _transpose_mul(const double* A, const double* B, double* C) noexcept nogil:
    """C = Aᵀ B (3 × 3 parts of two poses)."""
    cdef int i, j
    for i in range(3):
        for j in range(3):
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j]


cdef inline void _skew_rows(const double* a, const double* J, double* out, int nv) noexcept nogil:
    """out (3 × nv) = −[a]× J[3:6] (the axis error's rows)."""
    cdef int j
    for j in range(nv):
        out[j] = -(-a[2] * J[4 * nv + j] + a[1] * J[5 * nv + j])
        out[nv + j] = -(a[2] * J[3 * nv + j] - a[0] * J[5 * nv + j])
        out[2 * nv + j] = -(-a[1] * J[3 * nv + j] + a[0] * J[4 * nv + j])


cdef double _posture_error(Step s, const double* q, int v_index) noexcept nogil:
    """q ⊖ q_ref at velocity index v_index, for a 1-DoF or continuous joint (the free-flyer's are not pulled)."""
    cdef int j = s.tree.vjoint[v_index], i
    if j == 0:
        return 0.0
    i = s.tree.iq[j]
    if s.tree.kind[j] == CONTINUOUS:
        return _wrap(atan2_(q[i + 1], q[i]) - atan2_(s.post_ref[i + 1], s.post_ref[i]))
    return q[i] - s.post_ref[i]


cdef inline double _wrap(double x) noexcept nogil:
    while x > M_PI:
        x -= 2.0 * M_PI
    while x <= -M_PI:
        x += 2.0 * M_PI
    return x


cdef void _relative(Step s, int t, const double* F, double* A, double* e, double* w, double* err) noexcept nogil:
    """A relative frame task's rows: the frame's pose in the root frame's axes (see evaluate.relative_rows)."""
    cdef int nv = s.tree.nv, i, j
    cdef double Rp[12], gap[3], rel[3], ER[9], M1[9], wv[3], a[3], JL[9], Rt[9], P[9], d
    cdef double* T = &s.target[t, 0]
    cdef double* Jf = &s.Jf[0, 0]
    cdef double* Jr = &s.Jr[0, 0]
    s.tree.frame(s.root[t], &s.root_place[t, 0], Rp)
    s.tree.jacobian(s.root[t], &Rp[9], Jr)
    for i in range(3):
        gap[i] = F[9 + i] - Rp[9 + i]
    mat_tvec(Rp, gap, rel)
    for i in range(3):
        e[i] = rel[i] - T[9 + i]
        w[i], w[3 + i] = s.wp[t], s.wo[t]
    for j in range(nv):  # Rrᵀ (Jf_lin − Jr_lin + [gap]× Jr_ang)
        a[0] = Jf[j] - Jr[j] + (gap[1] * Jr[5 * nv + j] - gap[2] * Jr[4 * nv + j])
        a[1] = Jf[nv + j] - Jr[nv + j] + (gap[2] * Jr[3 * nv + j] - gap[0] * Jr[5 * nv + j])
        a[2] = Jf[2 * nv + j] - Jr[2 * nv + j] + (gap[0] * Jr[4 * nv + j] - gap[1] * Jr[3 * nv + j])
        mat_tvec(Rp, a, rel)
        A[j], A[nv + j], A[2 * nv + j] = rel[0], rel[1], rel[2]
    _transpose_mul(F, Rp, M1)  # Rfᵀ Rr
    mat_mul(M1, T, ER)  # Rfᵀ Rr R*
    log3(ER, wv)
    for i in range(3):
        a[i] = -wv[i]
        e[3 + i] = wv[i]
    jlog3(a, JL)
    _transpose(F, Rt)
    mat_mul(JL, Rt, P)
    for i in range(3):
        for j in range(nv):
            d = 0.0
            d += P[3 * i] * (Jf[3 * nv + j] - Jr[3 * nv + j])
            d += P[3 * i + 1] * (Jf[4 * nv + j] - Jr[4 * nv + j])
            d += P[3 * i + 2] * (Jf[5 * nv + j] - Jr[5 * nv + j])
            A[(3 + i) * nv + j] = -d
    err[0], err[1] = _norm(e, 3), norm3(wv)
