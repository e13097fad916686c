# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The compiled path follower: every sample of a path solved in one call, warm-started from the sample before
(FRDM's direct-control use, Danilov 2019; docs/methods.md §1.9).

Each sample runs in two phases. The first minimises E plus a rest term pulling towards the previous sample's
answer (``w_rest`` Σ 2(1 − cos Δq)): among the configurations that reach the target it prefers the nearest one,
which on a redundant arm keeps the self-motion from drifting into a joint limit or a branch jump. The second,
run only when the first has not met the tolerances, is plain FRDM from where the first stopped, so the rest term
never costs accuracy. With ``lm_iterations`` > 0 a sample FRDM leaves short gets damped Gauss–Newton steps.

With the Newton finish on (the default FRDM mode), a sample none of this meets is recovered, so that a smooth
path loses no sample: first by continuation — the step from the last reached target to this one cut into 2, 4,
then 8 sub-steps (points along the segment, rotations along the geodesic), each solved from the answer before —
and only then by seeded restarts within ±0.1, ±0.3 and ±1 rad (or m) of the last reached configuration. Every
sample starts from the last reached configuration. With ``finish="none"`` (the paper's FRDM) the follower is the
plain one: no recovery. The linear algebra is BLAS and LAPACK's, called as NumPy calls them.
"""

from libc.math cimport exp, fabs, sqrt, INFINITY, NAN
from libc.stdlib cimport calloc, free, malloc

from kinelab.core._blas cimport ddot, dgemm, dgemv, dgesv, ready
from kinelab.core._frdm cimport (
    BUDGET, CONVERGED, NOT_STARTED, STATE_SIZE, Chain, Memory, Objective, Packed, Settings, chain_fk, lm_polish, now,
    rotation_angle, run, uniform, within, world_error, world_jacobian,
)
from kinelab.core._geometry cimport rotm

# the Gauss–Newton steps of a sample move no joint by more than TRUST_FLOOR + TRUST_FACTOR × the last sample's
# largest joint step [rad or m]: a smooth path's answer lies about that far from the last one
cdef double TRUST_FLOOR = 0.02
cdef double TRUST_FACTOR = 2.0
cdef int SWEEPS_PER_LOOK = 32  # a phase's sweeps between two looks at the clock
# a redundant arm's push away from its limits moves no joint by more than PUSH_FLOOR + the larger of PUSH_SHARE × the
# largest joint step the task itself asks of the sample and the path's pace (its typical joint step) [rad or m]: the
# self-motion it steers stays as smooth as the path (uncapped, a path starting at rest moved joints 18 times faster
# than the path itself did; capped by the last sample's whole step, the push fed on itself), and where the path slows
# down (the ends of a blend) the arm can still turn away from a limit at the path's usual pace
cdef double PUSH_FLOOR = 1e-5
cdef double PUSH_SHARE = 0.5
# [1/rad or 1/m] the push's soft minimum of the margins: a joint whose margin is within about 1/MARGIN_SOFTNESS of the
# least one shares the push
cdef double MARGIN_SOFTNESS = 10.0


cdef struct Follow:
    # a path's solve settings, the same for every sample
    const Settings* st
    int order
    int max_sweeps
    double w_rest
    int rest_sweeps
    const double* centre
    double pull
    int lm_iterations
    double deadline  # [s] on time.perf_counter()'s clock (inf: none)
    const double* toward  # (N, n) per sample, the configuration the null-space term draws towards (NULL: the push)
    double pace  # [rad or m] the path's typical joint step: the null-space term may always move a joint this far


cdef inline double _max(double a, double b) noexcept nogil:
    return b if b > a else a


cdef inline double _min(double a, double b) noexcept nogil:
    return b if b < a else a


cdef inline void _copy(double* dst, const double* src, int count) noexcept nogil:
    cdef int i
    for i in range(count):
        dst[i] = src[i]


cdef inline Objective _aimed(const Objective* pb, const double* pstar, const double* Rstar, const double* q_rest,
                             double w_rest) noexcept nogil:
    """The problem ``pb`` aimed at (pstar, Rstar) with this rest configuration and weight (whole rotation)."""
    cdef Objective aim = pb[0]
    aim.pstar, aim.Rstar, aim.q_rest, aim.w_rest, aim.rot_axis = pstar, Rstar, q_rest, w_rest, -1
    return aim


cdef double _limit_pull(double x, double lo, double hi, double pull) noexcept nogil:
    """The share of the way to mid-range the rest configuration takes for a joint at x: ``pull`` times the
    Chan–Dubey measure (hi − lo)² / (4 (x − lo)(hi − x)), capped at 1/2."""
    cdef double dl = x - lo, du = hi - x
    if not (dl > 0.0 and du > 0.0) or dl + du == INFINITY:
        return pull if dl + du != INFINITY else 0.0
    return _min(0.5, pull * (dl + du) * (dl + du) / (4.0 * dl * du))


cdef void _pull_towards_centre(const double* q, int n, const Objective* pb, const double* centre, double pull,
                               double* z) noexcept nogil:
    """z ← the pull of a redundant arm's n joints from q towards mid-range: ``pull`` times each joint's Chan–Dubey
    measure (:func:`_limit_pull`) of the way there; frozen joints 0."""
    cdef int i
    for i in range(n):
        z[i] = _limit_pull(q[i], pb.lower[i], pb.upper[i], pull) * (centre[i] - q[i]) if pb.free[i] else 0.0


cdef void _push_from_limits(const double* q, int n, const Objective* pb, double* z) noexcept nogil:
    """z ← the ascent direction of a soft minimum of the joints' margins min(q − lower, upper − q), its entries summing
    to 1 in size: the joint nearest its limit, and those about as near, move away from it. A margin is measured in
    rad (or m), not as a share of the range, because a joint's distance to its limit is what a path keeps. Joints
    frozen or without a finite range: 0."""
    cdef int i
    cdef double least = INFINITY, total = 0.0, margin, w
    for i in range(n):
        z[i] = 0.0
        if pb.free[i] and pb.upper[i] - pb.lower[i] < INFINITY:
            least = _min(least, _min(q[i] - pb.lower[i], pb.upper[i] - q[i]))
    for i in range(n):
        if pb.free[i] and pb.upper[i] - pb.lower[i] < INFINITY:
            margin = _min(q[i] - pb.lower[i], pb.upper[i] - q[i])
            w = exp(-MARGIN_SOFTNESS * (margin - least))
            z[i] = w if q[i] - pb.lower[i] < pb.upper[i] - q[i] else -w
            total += w
    if total > 0.0:
        for i in range(n):
            z[i] /= total


cdef void _solve6(const double* A, const double* b, double* x, double* F, int* pivots) noexcept nogil:
    """x = A⁻¹ b for the 6 × 6 row-major A, by LAPACK as NumPy's solve calls it (A copied to Fortran order)."""
    cdef int six = 6, one = 1, info = 0, i, j
    for i in range(6):
        x[i] = b[i]
        for j in range(6):
            F[i + 6 * j] = A[6 * i + j]
    dgesv(&six, &one, F, &six, pivots, x, &six, &info)


cdef int redundant_newton(double* q, const Chain* ch, const Objective* pb, int iterations, double max_step,
                          const double* toward, double pace, int* spent) noexcept nogil:
    """Damped Gauss–Newton steps in their minimum-norm form, dq = Jᵀ(JJᵀ + λI)⁻¹ err, the first plus the projection
    onto the task's null space of a push away from the limits (:func:`_push_from_limits`): a redundant arm's
    self-motion turns away from its limits instead of drifting into one; with ``toward`` (not NULL) a draw towards
    that configuration instead (z = toward − q), which brings the self-motion to a path followed from elsewhere.
    The null-space share moves no joint by more than PUSH_FLOOR + max(PUSH_SHARE × the task's share, ``pace``).
    Steps capped at ``max_step`` [rad or m]. Returns CONVERGED or −1, the steps in ``spent``; q is updated in
    place."""
    cdef int n = ch.n, it, i, six = 6, one_i = 1
    cdef double one = 1.0, zero = 0.0, damping, largest, task, pushed, cap, scale
    cdef char t = b't', nt = b'n'
    cdef double p[3]
    cdef double R[9]
    cdef double err[6]
    cdef double A[36]
    cdef double F[36]
    cdef double s1[6]
    cdef double s2[6]
    cdef double Jz[6]
    cdef int pivots[6]
    cdef double* block = <double*> malloc(sizeof(double) * (6 * n + 6 * n + 3 * n))
    if block == NULL:
        spent[0] = 0
        return -1
    cdef double* e = block
    cdef double* o = block + 3 * n
    cdef double* J = block + 6 * n
    cdef double* z = J + 6 * n
    cdef double* a = z + n
    cdef double* b = a + n
    spent[0] = iterations
    for it in range(iterations + 1):
        chain_fk(ch, q, e, o, p, R)
        if within(p, R, pb):
            spent[0] = it
            free(block)
            return CONVERGED
        if it == iterations:
            break
        world_error(p, R, pb, err)
        world_jacobian(e, o, p, R, ch, pb, J)
        dgemm(&t, &nt, &six, &six, &n, &one, J, &n, J, &n, &zero, A, &six)
        damping = 1e-9 + 1e-3 * ddot(&six, err, &one_i, err, &one_i)
        for i in range(6):
            A[7 * i] += damping
        # the null-space term acts on the first step only: the later ones converge as Gauss–Newton does
        if it == 0 and toward != NULL and toward[0] == toward[0]:  # a NaN row: no configuration to draw towards
            for i in range(n):
                z[i] = toward[i] - q[i] if pb.free[i] else 0.0
        elif it == 0:
            _push_from_limits(q, n, pb, z)
        else:
            for i in range(n):
                z[i] = 0.0
        _solve6(A, err, s1, F, pivots)
        dgemv(&nt, &n, &six, &one, J, &n, s1, &one_i, &zero, a, &one_i)
        dgemv(&t, &n, &six, &one, J, &n, z, &one_i, &zero, Jz, &one_i)
        _solve6(A, Jz, s2, F, pivots)
        dgemv(&nt, &n, &six, &one, J, &n, s2, &one_i, &zero, b, &one_i)
        task = pushed = 0.0
        for i in range(n):
            b[i] = z[i] - b[i]  # the push's share in the task's null space
            task, pushed = _max(task, fabs(a[i])), _max(pushed, fabs(b[i]))
        cap = PUSH_FLOOR + _max(PUSH_SHARE * task, pace)
        scale = 1.0 if pushed <= cap else cap / pushed
        largest = 0.0
        for i in range(n):
            a[i] += scale * b[i]
            largest = _max(largest, fabs(a[i]))
        if largest > max_step:
            for i in range(n):
                a[i] *= max_step / largest
        for i in range(n):
            q[i] = _min(_max(q[i] + a[i], pb.lower[i]), pb.upper[i])
    free(block)
    return -1


cdef void pose_between(const double* p0, const double* R0, const double* p1, const double* R1, double s,
                       double* p_out, double* R_out) noexcept nogil:
    """The pose a share s ∈ [0, 1] of the way from (p0, R0) to (p1, R1): the point along the segment, the rotation
    R0 exp(s log(R0ᵀ R1)) (the shorter way round)."""
    cdef int i, r, c, three = 3
    cdef double one = 1.0, zero = 0.0, x, y, z, norm, angle
    cdef char t = b't', nt = b'n'
    cdef double M[9]
    cdef double m[9]
    for i in range(3):
        p_out[i] = p0[i] + s * (p1[i] - p0[i])
    dgemm(&nt, &t, &three, &three, &three, &one, <double*> R1, &three, <double*> R0, &three, &zero, M, &three)
    angle = rotation_angle(R1, R0)
    x, y, z = M[7] - M[5], M[2] - M[6], M[3] - M[1]
    norm = sqrt(x * x + y * y + z * z)
    if angle < 1e-12 or norm < 1e-300:
        # no turn (or a half turn, whose axis the skew part loses: the end pose's rotation)
        _copy(R_out, R1 if s >= 0.5 else R0, 9)
        return
    rotm(x / norm, y / norm, z / norm, s * angle, m)
    for r in range(3):
        for c in range(3):
            R_out[3 * r + c] = R0[3 * r] * m[c] + R0[3 * r + 1] * m[3 + c] + R0[3 * r + 2] * m[6 + c]


cdef inline bint _late(const Follow* fw) noexcept nogil:
    return fw.deadline < INFINITY and now() > fw.deadline


cdef int _phase(double* q, const Chain* ch, const Objective* pb, const Follow* fw, int max_sweeps, Memory* mem,
                int* spent) noexcept nogil:
    """One FRDM phase of up to ``max_sweeps`` sweeps from q, the clock looked at every SWEEPS_PER_LOOK sweeps
    (a cut run resumes where it stopped, so the answer is the one long run's unless the deadline ends it)."""
    cdef int code = BUDGET, more = 0, left = max_sweeps, chunk
    cdef int i
    for i in range(STATE_SIZE):
        mem.state[i] = 0.0
    spent[0] = 0
    while left > 0:
        chunk = left if fw.deadline == INFINITY or left < SWEEPS_PER_LOOK else SWEEPS_PER_LOOK
        code = run(q, ch, pb, fw.st, fw.order, chunk, mem, &more)
        spent[0] += more
        left -= more
        if code != BUDGET or _late(fw):
            break
    return code


cdef int _sample(double* q, const Chain* ch, const Objective* pb, const Follow* fw, double trust,
                 const double* pstar, const double* Rstar, double* rest, double* q_prev, Memory* mem,
                 int* spent) noexcept nogil:
    """One sample from q (in place): with the Newton finish on, Gauss–Newton steps from q first (continuation);
    then the rest phase, the plain phase, the polish. Returns the code, the sweeps and steps in ``spent``."""
    cdef int n = ch.n, i, code = -1, more = 0
    cdef Objective plain, rested
    _copy(q_prev, q, n)
    spent[0] = 0
    plain = _aimed(pb, pstar, Rstar, q_prev, 0.0)
    if fw.st.finish_below > 0.0:
        code = lm_polish(q, ch, &plain, 2 * fw.st.finish_steps, trust, spent)
        if code == CONVERGED:
            return code
        _copy(q, q_prev, n)
    if fw.w_rest > 0.0 and not _late(fw):
        _pull_towards_centre(q_prev, n, pb, fw.centre, fw.pull, rest)
        for i in range(n):
            rest[i] += q_prev[i]
        rested = _aimed(pb, pstar, Rstar, rest, fw.w_rest)
        code = _phase(q, ch, &rested, fw, fw.rest_sweeps, mem, &more)
        spent[0] += more
    if code != CONVERGED and not _late(fw):
        code = _phase(q, ch, &plain, fw, fw.max_sweeps, mem, &more)
        spent[0] += more
    if code != CONVERGED and fw.lm_iterations > 0 and not _late(fw):
        code = lm_polish(q, ch, &plain, fw.lm_iterations, INFINITY, &more)
        spent[0] += more
    return code


cdef int _predicted(double* q, const double* q_good, const double* velocity, const Chain* ch, const Objective* pb,
                    const Follow* fw, double trust, const double* pstar, const double* Rstar, const double* toward,
                    int* spent) noexcept nogil:
    """Gauss–Newton steps from the predictor q_good + velocity (clipped to the limits): through a singular point,
    where two branches meet, the path's own joint velocity carries the arm on along its branch. A redundant arm (a
    rest weight > 0) starts from q_good instead: its velocity holds self-motion that the predictor would carry on
    for ever. Returns the code, the steps in ``spent``; q holds the answer."""
    cdef double carry = 0.0 if fw.w_rest > 0.0 else 1.0
    cdef int i
    cdef Objective aim = _aimed(pb, pstar, Rstar, q_good, 0.0)
    for i in range(ch.n):
        q[i] = _min(_max(q_good[i] + carry * velocity[i], pb.lower[i]), pb.upper[i])
    if fw.w_rest > 0.0:
        return redundant_newton(q, ch, &aim, 2 * fw.st.finish_steps, trust, toward, fw.pace, spent)
    return lm_polish(q, ch, &aim, 2 * fw.st.finish_steps, trust, spent)


cdef int _recover(double* q, const double* q_good, const double* p_good, const double* R_good, const Chain* ch,
                  const Objective* pb, const Follow* fw, double trust, const double* pstar, const double* Rstar,
                  double* rest, double* q_prev, Memory* mem, unsigned long long* rng_state, int* spent) noexcept nogil:
    """A sample the plain follower missed: sub-steps from the last reached pose, then restarts about the last
    reached configuration. Returns the code, the sweeps in ``spent``; q holds the answer."""
    cdef int n = ch.n, cuts, j, k, i, code = CONVERGED, more = 0, r
    cdef double lo, hi, radius
    cdef double p_mid[3]
    cdef double R_mid[9]
    cdef double radii[3]
    radii[0], radii[1], radii[2] = 0.1, 0.3, 1.0
    spent[0] = 0
    cuts = 2
    while cuts <= 8:
        _copy(q, q_good, n)
        code = CONVERGED
        for j in range(1, cuts + 1):
            if _late(fw):
                return code if code != CONVERGED else -1
            pose_between(p_good, R_good, pstar, Rstar, <double> j / <double> cuts, p_mid, R_mid)
            code = _sample(q, ch, pb, fw, trust, p_mid, R_mid, rest, q_prev, mem, &more)
            spent[0] += more
            if code != CONVERGED:
                break
        if code == CONVERGED:
            return code
        cuts *= 2
    for r in range(3):
        radius = radii[r]
        for k in range(4):
            if _late(fw):
                return code
            for i in range(n):
                lo, hi = _max(pb.lower[i], q_good[i] - radius), _min(pb.upper[i], q_good[i] + radius)
                q[i] = lo + (hi - lo) * uniform(rng_state)
            code = _sample(q, ch, pb, fw, trust, pstar, Rstar, rest, q_prev, mem, &more)
            spent[0] += more
            if code == CONVERGED:
                return code
    return code


cdef int _tracked(double* q, const double* q_good, const double* p_good, const double* R_good,
                  const double* velocity, const Chain* ch, const Objective* pb, const Follow* fw, double trust,
                  const double* pstar, const double* Rstar, const double* toward, double* rest, double* q_prev,
                  double* first, Memory* mem, unsigned long long* rng_state, int* spent) noexcept nogil:
    """One sample with the Newton finish on: the predictor, then the sample's phases from the last reached
    configuration, then the recovery; a sample none of them reaches keeps the phases' answer, the nearest to the
    last reached one. Returns the code, the sweeps and steps in ``spent``; q holds the answer."""
    cdef int code, more = 0, n = ch.n
    code = _predicted(q, q_good, velocity, ch, pb, fw, trust, pstar, Rstar, toward, spent)
    if code == CONVERGED:
        return code
    _copy(q, q_good, n)
    code = _sample(q, ch, pb, fw, trust, pstar, Rstar, rest, q_prev, mem, &more)
    spent[0] += more
    if code == CONVERGED or _late(fw):
        return code
    _copy(first, q, n)
    code = _recover(q, q_good, p_good, R_good, ch, pb, fw, trust, pstar, Rstar, rest, q_prev, mem, rng_state, &more)
    if code != CONVERGED:
        _copy(q, first, n)
    spent[0] += more
    return code


cdef void _follow(double* Q, int count, const double* q0, const Chain* ch, const Objective* pb, const Follow* fw,
                  const double* pstars, const double* Rstars, unsigned long long* rng_state, long long* codes,
                  long long* sweeps, double* work) noexcept nogil:
    """Every sample k from the last reached configuration (q0 before the first), the clock looked at before each:
    once it has passed ``fw.deadline`` the samples left are not started (NaN rows, code NOT_STARTED), and the sample
    under way stops at its next look (between phases, every SWEEPS_PER_LOOK sweeps, between recovery steps). ``work``: 12n +
    12 + 2(accel_m + 1)n + STATE_SIZE + 3(2n + 4) values."""
    cdef int n = ch.n, k, i, code, spent = 0, rows = fw.st.accel_m + 1
    cdef int recover = fw.st.finish_below > 0.0
    cdef double trust = TRUST_FLOOR, largest
    cdef double* q = work
    cdef double* q_good = work + n
    cdef double* rest = work + 2 * n
    cdef double* velocity = work + 3 * n
    cdef double* q_prev = work + 4 * n
    cdef double* first = work + 5 * n
    cdef double* e = work + 6 * n  # e and o: 6n values, then p_good, R_good
    cdef double* p_good = work + 12 * n
    cdef double* R_good = p_good + 3
    cdef Memory mem
    mem.X = R_good + 9
    mem.G = mem.X + rows * n
    mem.state = mem.G + rows * n
    mem.held = mem.state + STATE_SIZE
    mem.trace = NULL
    mem.trace_len = 0
    _copy(q, q0, n)
    _copy(q_good, q0, n)
    _copy(rest, q0, n)
    chain_fk(ch, q0, e, e + 3 * n, p_good, R_good)
    for i in range(n):
        velocity[i] = 0.0
    for k in range(count):
        if _late(fw):
            for i in range(n):
                Q[n * k + i] = NAN
            codes[k], sweeps[k] = NOT_STARTED, 0
            continue
        if recover:
            code = _tracked(q, q_good, p_good, R_good, velocity, ch, pb, fw, trust, pstars + 3 * k, Rstars + 9 * k,
                            NULL if fw.toward == NULL else fw.toward + n * k, rest, q_prev, first, &mem, rng_state,
                            &spent)
        else:
            code = _sample(q, ch, pb, fw, trust, pstars + 3 * k, Rstars + 9 * k, rest, q_prev, &mem, &spent)
        for i in range(n):
            velocity[i] = 0.0
        if code == CONVERGED:
            largest = 0.0
            for i in range(n):
                velocity[i] = q[i] - q_good[i]
                largest = _max(largest, fabs(velocity[i]))
            trust = TRUST_FLOOR + TRUST_FACTOR * largest
            _copy(q_good, q, n)
            _copy(p_good, pstars + 3 * k, 3)
            _copy(R_good, Rstars + 9 * k, 9)
        _copy(Q + n * k, q, n)
        codes[k] = code
        sweeps[k] = spent


def follow(double[:, ::1] Q, const double[::1] q0, chain, objective, const double[:, ::1] pstars,
           const double[:, :, ::1] Rstars, settings, int order, int max_sweeps, double w_rest, int rest_sweeps,
           const double[::1] centre, double pull, int lm_iterations, unsigned long long[::1] rng_state,
           double deadline, long long[::1] codes, long long[::1] sweeps, const double[:, ::1] toward=None,
           double pace=0.0):
    """Solve sample k of the path (pstars[k], Rstars[k]) from the last reached configuration (q0 at first).

    Args:
        Q: (N, n) out, one configuration per sample [rad or m].
        q0: (n,) configuration before the first sample.
        chain, objective, settings: the chain, the problem (windows, free mask, weights, tolerances; its own target
            and rest configuration are not read) and the sweep settings (``finish_below`` > 0: recovery on), as
            :class:`kinelab.core._frdm.Packed` takes them.
        pstars, Rstars: (N, 3) target points [m] and (N, 3, 3) rotations, base frame.
        order: sweep order code; max_sweeps: sweep cap of each phase.
        w_rest: weight of the rest term in the first phase (0: one plain phase); rest_sweeps: its sweep cap.
        centre, pull: the rest configuration is q_prev + s (centre − q_prev), s = pull × the joint's limit measure.
        lm_iterations: Levenberg–Marquardt steps after FRDM for a sample still short (0: none).
        rng_state: (1,) uint64 state of the recovery's restarts.
        deadline: a ``time.perf_counter()`` value [s] (inf: none): samples not started by then are left NaN.
        codes, sweeps: (N,) out: run() code (NOT_STARTED −2 past the deadline) and sweeps spent per sample.
        toward: (N, n) per sample, the configuration a redundant arm's null-space term draws towards in place of
            the push from the limits (None, or a NaN row: the push).
        pace: the path's typical joint step [rad or m]: a redundant arm's null-space term may always move a joint
            this far a sample (0: only its share of the task's own step).
    """
    cdef Packed packed = Packed(chain, objective, settings)
    cdef int n = packed.n, count = Q.shape[0], rows = packed.st.accel_m + 1
    cdef Follow fw
    if Q.shape[1] != n or q0.shape[0] != n or centre.shape[0] != n or pstars.shape[0] != count \
            or Rstars.shape[0] != count or codes.shape[0] != count or sweeps.shape[0] != count \
            or pstars.shape[1] != 3 or Rstars.shape[1] != 3 or Rstars.shape[2] != 3 or rng_state.shape[0] < 1 \
            or (toward is not None and (toward.shape[0] != count or toward.shape[1] != n)):
        raise ValueError("follow: inconsistent shapes")
    if count == 0 or n == 0:
        return
    fw.st, fw.order, fw.max_sweeps, fw.w_rest, fw.rest_sweeps = &packed.st, order, max_sweeps, w_rest, rest_sweeps
    fw.centre, fw.pull, fw.lm_iterations, fw.deadline = &centre[0], pull, lm_iterations, deadline
    fw.toward = NULL if toward is None or count == 0 else &toward[0, 0]
    fw.pace = pace if pace > 0.0 else 0.0
    cdef double* work = <double*> calloc(12 * n + 12 + 2 * rows * n + STATE_SIZE + 3 * (2 * n + 4), sizeof(double))
    if work == NULL:
        raise MemoryError("the path follower's work arrays")
    with nogil:
        _follow(&Q[0, 0], count, &q0[0], &packed.ch, &packed.pb, &fw, &pstars[0, 0], &Rstars[0, 0, 0],
                &rng_state[0], &codes[0], &sweeps[0], work)
    free(work)


def pose_between_of(const double[::1] p0, const double[:, :] R0, const double[::1] p1, const double[:, :] R1,
                    double s, double[::1] p_out, double[:, ::1] R_out):
    """The pose a share s ∈ [0, 1] of the way from (p0, R0) to (p1, R1), into p_out, R_out: the point along the
    segment, the rotation R0 exp(s log(R0ᵀ R1)) (the shorter way round)."""
    cdef double A[9]
    cdef double B[9]
    cdef int i, j
    ready()
    if p0.shape[0] != 3 or p1.shape[0] != 3 or p_out.shape[0] != 3 or R0.shape[0] != 3 or R0.shape[1] != 3 \
            or R1.shape[0] != 3 or R1.shape[1] != 3 or R_out.shape[0] != 3 or R_out.shape[1] != 3:
        raise ValueError("pose_between: 3-vectors and 3 × 3 rotations expected")
    for i in range(3):
        for j in range(3):
            A[3 * i + j], B[3 * i + j] = R0[i, j], R1[i, j]
    pose_between(&p0[0], A, &p1[0], B, s, &p_out[0], &R_out[0, 0])
