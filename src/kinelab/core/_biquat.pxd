# The biquaternion preset's C interface, shared with the engine that runs it in one call (kinelab.core._engine).

from kinelab.core._frdm cimport Chain

# codes of an attempt: the kernels' one table (kinelab.core._frdm's Code); statistics slots of a multistart, written
# once (kinelab.ik.biquat.kernel imports them)
from kinelab.core._frdm cimport BUDGET, CONVERGED, MAX_STEPS, OUTSIDE_LIMITS, SINGULAR

cdef enum:
    T_ATTEMPTS = 0
    T_STEPS = 1
    T_MODEL_TIME = 2
    T_OUTSIDE = 3
    T_SINGULAR = 4
    T_CUT = 5
    T_ATTEMPT_STEPS = 6
    T_ATTEMPT_TIME = 7
    STATS_SIZE = 8

cdef struct Control:
    const double* pstar  # (3,) target point [m], base frame
    const double* Rstar  # (3, 3) target rotation, row-major
    double k  # gain [1/s]
    double h  # step [s]
    double max_step  # largest joint change per step [rad or m]
    int max_steps  # steps per attempt
    double eps_rot  # stop when |m⃗| < eps_rot
    double eps_dual  # and |m0⃗| < eps_dual [m]
    double damping  # λ of the damped pseudo-inverse (0: exact solve when n = 6)

cdef int multistart(double* q, const Chain* ch, const double* lower, const double* upper, const Control* pb,
                    unsigned long long* rng_state, int max_attempts, double step_budget, double* stats,
                    const double* restart_lower, const double* restart_upper) noexcept nogil
cdef int timed(double* q, const Chain* ch, const double* lower, const double* upper, const Control* pb,
               unsigned long long* rng_state, int attempts, int first_chunk, int later_chunk, double deadline,
               const double* restart_lower, const double* restart_upper, double* stats) noexcept nogil
