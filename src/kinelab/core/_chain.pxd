# The compiled chain FK that judges answers (certified equal to Pinocchio's on each robot), shared with the engines
# that judge inside one compiled call.

cdef void fk_row(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t,
                 const double[:, ::1] axis, const long long[::1] kind, const double[:, ::1] tool_R,
                 const double[::1] tool_t, const double* q, double* out) noexcept nogil
cdef void fk_chain(int n, const double* placement_R, const double* placement_t, const double* axis,
                   const long long* kind, const double* tool_R, const double* tool_t, const double* q,
                   double* out) noexcept nogil


cdef class Judge:
    cdef const double[:, :, ::1] placement_R
    cdef const double[:, ::1] placement_t
    cdef const double[:, ::1] axis
    cdef const long long[::1] kind
    cdef const double[:, ::1] tool_R
    cdef const double[::1] tool_t
    cdef int n  # the data of the arrays above, read by pose() (the memoryviews keep them alive)
    cdef const double* pR
    cdef const double* pt
    cdef const double* pa
    cdef const long long* pk
    cdef const double* tR
    cdef const double* tt
    cdef void pose(self, const double* q, double* T) noexcept nogil
