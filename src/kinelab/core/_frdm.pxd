# The FRDM kernel's C interface, shared by the compiled modules that run it (the batch, the path follower).

# Codes written once: Python reads the same enums (kinelab.ik.chain and kinelab.ik.frdm.kernel import them).
cpdef enum JointKind:
    REVOLUTE = 0
    PRISMATIC = 1
    CONTINUOUS = 2

cpdef enum Order:
    TIP_TO_BASE = 0
    BASE_TO_TIP = 1
    ALTERNATE = 2
    MIXED = 3  # per restart, in turn

# what every compiled kernel's run and multistart return, one table for FRDM's and the biquaternion preset's (the
# engine of either reads the same CONVERGED and BUDGET); NOT_STARTED, STOPPED: a batch row the deadline cut before
# or while it ran
cpdef enum Code:
    CONVERGED = 0
    STALL_STEP = 1  # FRDM: a sweep moved no joint
    STALL_WINDOW = 2  # FRDM: the error stopped falling over the stall window
    BUDGET = 3  # the iterations or the time chunk ran out (the caller resumes or stops)
    SINGULAR = 4  # the biquaternion law met a singular configuration
    MAX_STEPS = 5  # the biquaternion preset took its steps without converging
    OUTSIDE_LIMITS = 6  # the biquaternion preset's answer lies outside the limits
    NOT_STARTED = -2
    STOPPED = -3

# slots of an attempt's state array, named in Python too (kinelab.ik.frdm.kernel; a named enum cannot index a C
# array in Cython) (S_FINISH: 0 the Newton finish not tried, 1 tried and fell short, 2 converged;
# S_NEWTON: its Gauss–Newton steps)
cdef enum:
    S_HISTORY = 0
    S_SWEEPS = 1
    S_E_WINDOW = 2
    S_WINDOW_START = 3
    S_ACCEPTED = 4
    S_E = 5
    S_KICKED = 6
    S_HELD = 7
    S_SINCE_FK = 8
    S_FINISH = 9
    S_NEWTON = 10
    STATE_SIZE = 11

# slots of a multistart's statistics array (T_NEWTON: Gauss–Newton steps of the finish, every attempt)
cdef enum:
    T_ATTEMPTS = 0
    T_SWEEPS = 1
    T_STALLS = 2
    T_ACCEPTED = 3
    T_BEST_E = 4
    T_CUT = 5
    T_POLISHED = 6
    T_NEWTON = 7
    STATS_SIZE = 8

cdef struct Chain:
    int n
    const double* PR       # (n, 3, 3) joint frames in their parents' at q = 0
    const double* Pt       # (n, 3) [m]
    const double* axis     # (n, 3) unit axes in the joint frames
    const long long* kind  # (n,) REVOLUTE 0, PRISMATIC, CONTINUOUS
    const double* TR       # (3, 3) tool frame in the last joint's
    const double* Tt       # (3,) [m]

cdef struct Objective:
    const double* lower    # (n,) windows [rad or m]
    const double* upper
    const unsigned char* free  # (n,) 0: the joint is frozen
    const double* pstar    # (3,) target point [m]
    const double* Rstar    # (3, 3) target rotation
    double w_p
    const double* w_ax     # (3,)
    double tol_pos
    double tol_rot
    int check_pos
    int check_rot
    const double* q_rest   # (n,)
    double w_rest
    int rot_axis

cdef struct Settings:
    double relax
    double eps_q
    int window
    double window_rel
    int accel_m
    int polish
    double finish_below
    int finish_steps

cdef struct Memory:
    double* X              # (accel_m + 1, n)
    double* G              # (accel_m + 1, n)
    double* state          # (STATE_SIZE,)
    double* trace          # (trace_len,)
    int trace_len
    double* held           # (2n + 4, 3)

cdef void chain_fk(const Chain* ch, const double* q, double* e, double* o, double* p, double* R) noexcept nogil
cdef double rotation_angle(const double* R, const double* Rstar) noexcept nogil
cdef int within(const double* p, const double* R, const Objective* pb) noexcept nogil
cdef double total_objective(const double* q, const Chain* ch, const double* p, const double* R,
                            const Objective* pb) noexcept nogil
cdef int run(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
             Memory* mem, int* sweeps) noexcept nogil
cdef int lm_polish(double* q, const Chain* ch, const Objective* pb, int iterations, double max_step,
                   int* spent) noexcept nogil
cdef int multistart(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
                    unsigned long long* rng_state, int max_attempts, double sweep_budget, double* best_q,
                    double* stats, Memory* mem, double deadline) noexcept nogil
cdef int timed(double* q, const Chain* ch, const Objective* pb, const Settings* st, int order, int max_sweeps,
               unsigned long long* rng_state, int attempts, double first_chunk, double later_chunk, double deadline,
               int stop_before, double* best_q, double* stats, Memory* mem) noexcept nogil
cdef void random_configuration(double* q, const long long* kind, const double* lower, const double* upper, int n,
                               unsigned long long* rng_state) noexcept nogil
cdef void restart_windows(const Chain* ch, const double* q, const double* pstar, const double* lower,
                          const double* upper, const unsigned char* wide, double length, double* scratch,
                          double* out_lower, double* out_upper) noexcept nogil
cdef double now() noexcept nogil
cdef double uniform(unsigned long long* state) noexcept nogil
cdef void world_error(const double* p, const double* R, const Objective* pb, double* err) noexcept nogil
cdef void world_jacobian(const double* e, const double* o, const double* p, const double* R, const Chain* ch,
                         const Objective* pb, double* J) noexcept nogil


cdef class Packed:
    cdef Chain ch
    cdef Objective pb
    cdef Settings st
    cdef Memory mem
    cdef list keep
    cdef readonly int n
    cdef void _objective(self, pb) except *
    cdef void _settings(self, st) except *
    cdef void _memory(self, mem) except *
    cdef object _written(self, object array, Py_ssize_t size, str name)
    cdef void _check(self, double[::1] q, str name) except *
    cdef void _check_multistart(self, double[::1] q, double[::1] best_q, double[::1] stats,
                                unsigned long long[::1] rng_state) except *
