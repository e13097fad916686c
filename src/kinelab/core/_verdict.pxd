# The verdict on one answer, shared by Pinocchio's judge (_verdict.pose_verdict) and the compiled one (_chain.Judge).

cdef tuple verdict_of(const double* T, const double[:, :] H_target, const double[::1] q, const double[::1] lower,
                      const double[::1] upper, int axis)
cdef int pose_defect_of(const double[:, :] H) noexcept nogil
cdef int pose_defect_row_major(const double* T) noexcept nogil
cdef void pose_errors(const double* T, const double* pstar, const double* Rstar, int axis, double* dp,
                      double* dr) noexcept nogil
cdef bint take_target(const double[:, :] H, const double[::1] anchor, double radius, double[::1] pstar,
                      double[:, ::1] Rstar) noexcept
