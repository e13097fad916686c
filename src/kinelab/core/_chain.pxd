# The compiled chain FK that judges answers (certified equal to Pinocchio's on each robot), shared with the engines
# that judge inside one compiled call.

cdef void fk_row(const double[:, :, ::1] placement_R, const double[:, ::1] placement_t,
                 const double[:, ::1] axis, const long long[::1] kind, const double[:, ::1] tool_R,
                 const double[::1] tool_t, const double* q, double* out) noexcept nogil


cdef class Judge:
    cdef const double[:, :, ::1] placement_R
    cdef const double[:, ::1] placement_t
    cdef const double[:, ::1] axis
    cdef const long long[::1] kind
    cdef const double[:, ::1] tool_R
    cdef const double[::1] tool_t
    cdef void pose(self, const double* q, double* T) noexcept nogil
