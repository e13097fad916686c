# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The biquaternion control laws of paper 001 (docs/methods.md §2.4–2.5) and the solver's default preset,
compiled: law (9), Euler with h·k = 1 and a joint-step cap, the Cauchy problem q̇ = A⁻¹U integrated on the
shared chain FK, with seeded restarts.

M is the error biquaternion M* = N̄∘Λ as 8 numbers (real w, x, y, z, dual w, x, y, z) with m^0 ≥ 0; a control
U = ω + s v (end-link axes) is written into ``twist`` in Pinocchio's order [v; ω]. The Python integrators
(:mod:`kinelab.ik.biquat.integrators`) are the reference and call the same laws through the functions at the
end. The linear algebra is BLAS and LAPACK's, called as NumPy calls them.
"""

from libc.math cimport ceil, cos, exp, fabs, isfinite, log, sin, sqrt, atan2, NAN, M_PI
from libc.stdlib cimport free, malloc

from kinelab.core._blas cimport ddot, dgemm, dgemv, dgesdd, dgesv, dgetrf, ready
from kinelab.core._frdm cimport CONTINUOUS, PRISMATIC, Chain, Packed, chain_fk, now, random_configuration

from kinelab.core._frdm import pack_chain

cdef double TWO_PI = 2.0 * M_PI


cdef void quat_wxyz(const double* R, double* q) noexcept nogil:
    """Unit quaternion (w, x, y, z) of a row-major rotation matrix, w ≥ 0 (Shepperd)."""
    cdef double t = R[0] + R[4] + R[8], s, norm
    cdef int one = 1, four = 4, i
    if t > 0.0:
        s = sqrt(t + 1.0) * 2.0
        q[0], q[1], q[2], q[3] = 0.25 * s, (R[7] - R[5]) / s, (R[2] - R[6]) / s, (R[3] - R[1]) / s
    elif R[0] > R[4] and R[0] > R[8]:
        s = sqrt(1.0 + R[0] - R[4] - R[8]) * 2.0
        q[0], q[1], q[2], q[3] = (R[7] - R[5]) / s, 0.25 * s, (R[1] + R[3]) / s, (R[2] + R[6]) / s
    elif R[4] > R[8]:
        s = sqrt(1.0 + R[4] - R[0] - R[8]) * 2.0
        q[0], q[1], q[2], q[3] = (R[2] - R[6]) / s, (R[1] + R[3]) / s, 0.25 * s, (R[5] + R[7]) / s
    else:
        s = sqrt(1.0 + R[8] - R[0] - R[4]) * 2.0
        q[0], q[1], q[2], q[3] = (R[3] - R[1]) / s, (R[2] + R[6]) / s, (R[5] + R[7]) / s, 0.25 * s
    if q[0] < 0.0:
        for i in range(4):
            q[i] = -q[i]
    norm = sqrt(ddot(&four, q, &one, q, &one))
    for i in range(4):
        q[i] = q[i] / norm


cdef void error_biquaternion(const double* p, const double* R, const double* pstar, const double* Rstar,
                             double* out) noexcept nogil:
    """M* = N̄∘Λ (8 numbers, m^0 ≥ 0): the tool's pose (p [m], R) in the target frame (p*, R*)."""
    cdef double Rrel[9]
    cdef double d[3]
    cdef double t[3]
    cdef double one = 1.0, zero = 0.0, tx, ty, tz
    cdef int three = 3, inc = 1
    cdef char tr = b't', nt = b'n'
    dgemm(&nt, &tr, &three, &three, &three, &one, <double*> R, &three, <double*> Rstar, &three, &zero, Rrel, &three)
    d[0], d[1], d[2] = p[0] - pstar[0], p[1] - pstar[1], p[2] - pstar[2]
    dgemv(&nt, &three, &three, &one, <double*> Rstar, &three, d, &inc, &zero, t, &inc)
    quat_wxyz(Rrel, out)
    tx, ty, tz = 0.5 * t[0], 0.5 * t[1], 0.5 * t[2]
    out[4] = -tx * out[1] - ty * out[2] - tz * out[3]
    out[5] = tx * out[0] + ty * out[3] - tz * out[2]
    out[6] = ty * out[0] + tz * out[1] - tx * out[3]
    out[7] = tz * out[0] + tx * out[2] - ty * out[1]


cdef bint simple_law(const double* M, double k, double k0, double k_v, double* twist) noexcept nogil:
    """Law (9)/(16): U = −2K vect(M)/scal(M) with K = k + s k0 [1/s]; ``k_v`` a separate moment gain. False when
    the law is singular (m^0 = 0: the error rotation is π)."""
    cdef double m0 = M[0], d0 = M[4]
    cdef int j
    if m0 == 0.0:
        return False
    for j in range(3):
        twist[3 + j] = -2.0 * k * M[1 + j] / m0
        twist[j] = -2.0 * (k_v * (m0 * M[5 + j] - d0 * M[1 + j]) + k0 * m0 * M[1 + j]) / (m0 * m0)
    return True


cdef inline bint converged(const double* M, double eps_rot, double eps_dual) noexcept nogil:
    """|m⃗| < eps_rot and |m0⃗| < eps_dual (near ±1, m⃗ ≈ δθ/2 and m0⃗ ≈ ½R*ᵀΔp)."""
    return M[1] * M[1] + M[2] * M[2] + M[3] * M[3] < eps_rot * eps_rot \
        and M[5] * M[5] + M[6] * M[6] + M[7] * M[7] < eps_dual * eps_dual


cdef void jacobian_local(const double* e, const double* o, const long long* kind, int n, const double* p,
                         const double* R, double* J) noexcept nogil:
    """J (6 × n, row-major) ← the tool Jacobian in the tool frame (rows v, ω), from the chain's axes and points."""
    cdef double v[3]
    cdef double w[3]
    cdef double Rv[3]
    cdef double Rw[3]
    cdef double r0, r1, r2, one = 1.0, zero = 0.0
    cdef int i, j, three = 3, inc = 1
    cdef char nt = b'n'
    for i in range(n):
        if kind[i] == PRISMATIC:
            v[0], v[1], v[2] = e[3 * i], e[3 * i + 1], e[3 * i + 2]
            w[0] = w[1] = w[2] = 0.0
        else:
            r0, r1, r2 = p[0] - o[3 * i], p[1] - o[3 * i + 1], p[2] - o[3 * i + 2]
            v[0] = e[3 * i + 1] * r2 - e[3 * i + 2] * r1
            v[1] = e[3 * i + 2] * r0 - e[3 * i] * r2
            v[2] = e[3 * i] * r1 - e[3 * i + 1] * r0
            w[0], w[1], w[2] = e[3 * i], e[3 * i + 1], e[3 * i + 2]
        dgemv(&nt, &three, &three, &one, <double*> R, &three, v, &inc, &zero, Rv, &inc)
        dgemv(&nt, &three, &three, &one, <double*> R, &three, w, &inc, &zero, Rw, &inc)
        for j in range(3):
            J[j * n + i] = Rv[j]
            J[(3 + j) * n + i] = Rw[j]


cdef bint joint_rates(const double* J, int n, const double* twist, double damping, double* qd) noexcept nogil:
    """qd ← A(q)⁻¹U (eq. 8 inverted) from the local tool Jacobian J (6 × n, row-major). Square and undamped: an
    exact solve (NaN marks a singular A). Otherwise the damped pseudo-inverse V diag(σ/(σ² + λ²)) Uᵀ, λ =
    ``damping``. False when out of memory."""
    cdef int i, j, six = 6, inc = 1, info = 0, k = 6 if n > 6 else n, lwork = -1
    cdef double one = 1.0, zero = 0.0, acc = 0.0, query
    cdef char tr = b't', nt = b'n', jobz = b'S'
    cdef double* F = <double*> malloc(sizeof(double) * (6 * n + 6 * k + k * n + 2 * k + 6))
    cdef int* iwork = <int*> malloc(sizeof(int) * 8 * (k if k > 0 else 1))
    cdef double* work
    if F == NULL or iwork == NULL:
        free(F)
        free(iwork)
        return False
    cdef double* U = F + 6 * n
    cdef double* Vt = U + 6 * k
    cdef double* s = Vt + k * n
    cdef double* y = s + k
    for i in range(6):  # J in Fortran order, as NumPy hands it to LAPACK
        for j in range(n):
            F[i + 6 * j] = J[i * n + j]
    if n == 6 and damping == 0.0:
        for i in range(6):
            qd[i] = twist[i]
        dgetrf(&six, &six, F, &six, iwork, &info)
        if info == 0:
            for i in range(6):
                acc += log(fabs(F[7 * i]))
        if info > 0 or exp(acc) < 1e-300:
            for i in range(6):
                qd[i] = NAN
        else:
            for i in range(6):  # dgetrf overwrote the copy: solve from a fresh one, as NumPy does
                for j in range(6):
                    F[i + 6 * j] = J[i * 6 + j]
            dgesv(&six, &inc, F, &six, iwork, qd, &six, &info)
        free(F)
        free(iwork)
        return True
    dgesdd(&jobz, &six, &n, F, &six, s, U, &six, Vt, &k, &query, &lwork, iwork, &info)
    lwork = <int> query
    work = <double*> malloc(sizeof(double) * (lwork if lwork > 1 else 1))
    if work == NULL:
        free(F)
        free(iwork)
        return False
    dgesdd(&jobz, &six, &n, F, &six, s, U, &six, Vt, &k, work, &lwork, iwork, &info)
    dgemv(&tr, &six, &k, &one, U, &six, <double*> twist, &inc, &zero, y, &inc)
    for i in range(k):
        y[i] = s[i] / (s[i] * s[i] + damping * damping) * y[i]
    dgemv(&tr, &k, &n, &one, Vt, &k, y, &inc, &zero, qd, &inc)
    free(work)
    free(F)
    free(iwork)
    return True


cdef bint wrap_into_limits(double* q, const long long* kind, const double* lower, const double* upper,
                           int n) noexcept nogil:
    """Wrap revolute joints by 2πk into their limits, continuous ones into (−π, π]; True if all fit."""
    cdef bint ok = True
    cdef double shifted
    cdef int i
    for i in range(n):
        if kind[i] == CONTINUOUS:
            q[i] = atan2(sin(q[i]), cos(q[i]))
        elif kind[i] != PRISMATIC and (q[i] < lower[i] or q[i] > upper[i]):
            shifted = q[i] + TWO_PI * ceil((lower[i] - q[i]) / TWO_PI)
            if shifted <= upper[i]:
                q[i] = shifted
        if kind[i] != CONTINUOUS and (q[i] < lower[i] - 1e-9 or q[i] > upper[i] + 1e-9):
            ok = False
    return ok


cdef int integrate(double* q, const Chain* ch, const Control* pb, int max_steps, int* steps,
                   double* model_time) noexcept nogil:
    """Euler steps of q̇ = A⁻¹U(M*) with law (9) (k0 = 0) from q, in place. Returns the code, the steps and the
    model time [s] in the out-arguments."""
    cdef int n = ch.n, step, i, code = MAX_STEPS
    cdef double t = 0.0, fastest, dt
    cdef double p[3]
    cdef double R[9]
    cdef double M[8]
    cdef double twist[6]
    cdef double* block = <double*> malloc(sizeof(double) * (13 * n))
    if block == NULL:
        steps[0], model_time[0] = 0, 0.0
        return SINGULAR
    cdef double* e = block
    cdef double* o = block + 3 * n
    cdef double* J = block + 6 * n
    cdef double* qd = block + 12 * n
    steps[0] = max_steps
    for step in range(max_steps + 1):
        steps[0] = step
        chain_fk(ch, q, e, o, p, R)
        error_biquaternion(p, R, pb.pstar, pb.Rstar, M)
        if converged(M, pb.eps_rot, pb.eps_dual):
            code = CONVERGED
            break
        if M[0] == 0.0:
            code = SINGULAR
            break
        if step == max_steps:
            code = MAX_STEPS
            break
        simple_law(M, pb.k, 0.0, pb.k, twist)
        if not (isfinite(twist[0]) and isfinite(twist[1]) and isfinite(twist[2]) and isfinite(twist[3])
                and isfinite(twist[4]) and isfinite(twist[5])):
            code = SINGULAR  # the law overflowed (m^0 tiny against the gain)
            break
        jacobian_local(e, o, ch.kind, n, p, R, J)
        if not joint_rates(J, n, twist, pb.damping, qd):
            code = SINGULAR
            break
        fastest = 0.0
        code = MAX_STEPS
        for i in range(n):
            if not isfinite(qd[i]):
                code = SINGULAR
                break
            fastest = fastest if fastest >= fabs(qd[i]) else fabs(qd[i])
        if code == SINGULAR:
            break
        dt = pb.h if fastest * pb.h <= pb.max_step else pb.max_step / fastest
        for i in range(n):
            q[i] += dt * qd[i]
        t += dt
    free(block)
    model_time[0] = t
    return code


cdef int multistart(double* q, const Chain* ch, const double* lower, const double* upper, const Control* pb,
                    unsigned long long* rng_state, int max_attempts, double step_budget, double* stats,
                    const double* restart_lower, const double* restart_upper) noexcept nogil:
    """Attempts from q, then from seeded uniform starts in the restart windows, until one converges inside the
    joint limits. Called in chunks: an attempt that ``step_budget`` (a total) cuts is resumed by the next call from
    the same q with the steps it has left. stats has the slots T_*. Returns an integrate() code, or
    OUTSIDE_LIMITS, or BUDGET."""
    cdef int code = BUDGET, a, left, budget, steps = 0
    cdef double t = 0.0, spare
    for a in range(max_attempts):
        if stats[T_CUT] == 0.0:
            if stats[T_ATTEMPTS] > 0.0:
                random_configuration(q, ch.kind, restart_lower, restart_upper, ch.n, rng_state)
            stats[T_ATTEMPT_STEPS] = 0.0
            stats[T_ATTEMPT_TIME] = 0.0
        stats[T_CUT] = 0.0
        left = pb.max_steps - <int> stats[T_ATTEMPT_STEPS]
        spare = step_budget - stats[T_STEPS]
        budget = left if spare >= 2e9 or left < <int> spare else <int> spare
        code = integrate(q, ch, pb, budget, &steps, &t)
        stats[T_STEPS] += steps
        stats[T_ATTEMPT_STEPS] += steps
        stats[T_ATTEMPT_TIME] += t
        if code == MAX_STEPS and budget < left:  # cut by the chunk: the next call resumes this attempt
            stats[T_CUT] = 1.0
            return BUDGET
        stats[T_ATTEMPTS] += 1.0
        if code == CONVERGED:
            if wrap_into_limits(q, ch.kind, lower, upper, ch.n):
                stats[T_MODEL_TIME] = stats[T_ATTEMPT_TIME]
                return CONVERGED
            stats[T_OUTSIDE] += 1.0
            code = OUTSIDE_LIMITS
        elif code == SINGULAR:
            stats[T_SINGULAR] += 1.0
        if stats[T_STEPS] >= step_budget:
            return BUDGET
    return code


cdef int timed(double* q, const Chain* ch, const double* lower, const double* upper, const Control* pb,
               unsigned long long* rng_state, int attempts, int first_chunk, int later_chunk, double deadline,
               const double* restart_lower, const double* restart_upper, double* stats) noexcept nogil:
    """The multistart in chunks of steps (``first_chunk`` before the first look at the clock, ``later_chunk``
    between two), until an attempt converges, the attempts are spent or the deadline (:func:`now`) has passed after
    a chunk; returns the last chunk's code (-1: no attempt)."""
    cdef int code = -1, size
    cdef double before
    while attempts > 0:
        before = stats[T_ATTEMPTS]
        size = first_chunk if stats[T_STEPS] == 0.0 else later_chunk
        code = multistart(q, ch, lower, upper, pb, rng_state, attempts, stats[T_STEPS] + size, stats, restart_lower,
                          restart_upper)
        attempts -= <int> (stats[T_ATTEMPTS] - before)
        if code == CONVERGED or now() > deadline:
            break
    return code


# ---- Python's side ----

cdef Control _control(object control, list keep) except *:
    cdef Control c
    pstar = _array(control.pstar, 3, "pstar", keep)
    Rstar = _array(control.Rstar, 9, "Rstar", keep)
    cdef const double[::1] ps = pstar
    cdef const double[::1] Rs = Rstar.reshape(-1)
    c.pstar, c.Rstar = &ps[0], &Rs[0]
    c.k, c.h, c.max_step, c.max_steps = control.k, control.h, control.max_step, control.max_steps
    c.eps_rot, c.eps_dual, c.damping = control.eps_rot, control.eps_dual, control.damping
    return c


cdef object _array(object values, Py_ssize_t size, str name, list keep):
    import numpy as np
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.size != size:
        raise ValueError(f"{name}: {size} values expected, got shape {np.shape(values)}")
    keep.append(a)
    return a


def run_timed(double[::1] q, chain, const double[::1] lower, const double[::1] upper, control,
              unsigned long long[::1] rng_state, int attempts, int first_chunk, int later_chunk, double deadline,
              const double[::1] restart_lower, const double[::1] restart_upper, double[::1] stats) -> int:
    """The preset's multistart in chunks with the clock looked at between them (see ``timed`` in the C part;
    ``control`` a :class:`kinelab.ik.biquat.kernel.Control`, ``deadline`` a ``time.perf_counter()`` value [s]).
    Returns its code."""
    cdef Packed packed = pack_chain(chain)
    cdef int n = packed.n
    if q.shape[0] != n or lower.shape[0] != n or upper.shape[0] != n or restart_lower.shape[0] != n \
            or restart_upper.shape[0] != n or stats.shape[0] < 8 or rng_state.shape[0] < 1:
        raise ValueError("run_timed: q and the windows one value per joint, stats 8 slots, a generator state")
    cdef list keep = []
    cdef Control c = _control(control, keep)
    cdef int code
    with nogil:
        code = timed(&q[0], &packed.ch, &lower[0], &upper[0], &c, &rng_state[0], attempts, first_chunk, later_chunk,
                     deadline, &restart_lower[0], &restart_upper[0], &stats[0])
    return code


def error_biquaternion_of(const double[::1] p, const double[:, :] R, const double[::1] pstar,
                          const double[:, :] Rstar):
    """M* = N̄∘Λ as an (8,) array: the tool's pose (p [m], R) in the target frame (p*, R*)."""
    import numpy as np
    ready()
    cdef double Rc[9]
    cdef double Sc[9]
    cdef int i, j
    if p.shape[0] != 3 or pstar.shape[0] != 3 or R.shape[0] != 3 or R.shape[1] != 3 or Rstar.shape[0] != 3 \
            or Rstar.shape[1] != 3:
        raise ValueError("error_biquaternion: points (3,) and rotations (3, 3) expected")
    for i in range(3):
        for j in range(3):
            Rc[3 * i + j], Sc[3 * i + j] = R[i, j], Rstar[i, j]
    out = np.empty(8)
    cdef double[::1] M = out
    error_biquaternion(&p[0], Rc, &pstar[0], Sc, &M[0])
    return out


def simple_law_of(const double[::1] M, double k, double k0, double k_v, double[::1] twist) -> bool:
    """Law (9)/(16) into ``twist`` ([v; ω]); False when singular (m^0 = 0)."""
    if M.shape[0] != 8 or twist.shape[0] != 6:
        raise ValueError("simple_law: M (8,) and twist (6,) expected")
    return simple_law(&M[0], k, k0, k_v, &twist[0])


def converged_of(const double[::1] M, double eps_rot, double eps_dual) -> bool:
    """|m⃗| < eps_rot and |m0⃗| < eps_dual."""
    if M.shape[0] != 8:
        raise ValueError("converged: M (8,) expected")
    return converged(&M[0], eps_rot, eps_dual)


def joint_rates_of(const double[:, :] J, const double[::1] twist, double damping):
    """q̇ = A(q)⁻¹U from the local tool Jacobian J (6 × n) and the twist [v; ω] (see ``joint_rates``)."""
    import numpy as np
    ready()
    cdef int n = J.shape[1], i, j
    if J.shape[0] != 6 or n < 1 or twist.shape[0] != 6:
        raise ValueError("joint_rates: J (6, n) and twist (6,) expected")
    Jc = np.empty((6, n))
    cdef double[:, ::1] Jv = Jc
    for i in range(6):
        for j in range(n):
            Jv[i, j] = J[i, j]
    out = np.empty(n)
    cdef double[::1] qd = out
    if not joint_rates(&Jv[0, 0], n, &twist[0], damping, &qd[0]):
        raise MemoryError("joint_rates")
    return out


def jacobian_local_of(const double[:, ::1] e, const double[:, ::1] o, const long long[::1] kind,
                      const double[::1] p, const double[:, :] R):
    """6 × n tool Jacobian in the tool frame (rows v, ω) from the chain's axes e and points o (n × 3, base frame)
    and the tool pose (p [m], R): the one the compiled preset integrates with."""
    import numpy as np
    ready()
    cdef int n = e.shape[0], i, j
    if o.shape[0] != n or kind.shape[0] != n or e.shape[1] != 3 or o.shape[1] != 3 or p.shape[0] != 3 \
            or R.shape[0] != 3 or R.shape[1] != 3 or n == 0:
        raise ValueError("jacobian_local: e and o (n, 3), kind (n,), p (3,) and R (3, 3) expected")
    cdef double Rc[9]
    for i in range(3):
        for j in range(3):
            Rc[3 * i + j] = R[i, j]
    J = np.empty((6, n))
    cdef double[:, ::1] Jv = J
    jacobian_local(&e[0, 0], &o[0, 0], &kind[0], n, &p[0], Rc, &Jv[0, 0])
    return J


def run_integrate(double[::1] q, chain, control, int max_steps):
    """Euler steps of the preset from q (in place): (code, steps, model time [s])."""
    cdef Packed packed = pack_chain(chain)
    if q.shape[0] != packed.n or packed.n == 0:
        raise ValueError(f"run_integrate: {packed.n} joint values expected")
    cdef list keep = []
    cdef Control c = _control(control, keep)
    cdef int code, steps = 0
    cdef double t = 0.0
    with nogil:
        code = integrate(&q[0], &packed.ch, &c, max_steps, &steps, &t)
    return code, steps, t
