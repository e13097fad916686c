# The loop equations of a revolute chain, for the compiled kernels that polish roots (_loop.pyx).

cdef enum:
    MAX_JOINTS = 8

cdef void loop_row(const double* h, const double* o, const double* R0, const double* N0, double scale,
                   const double* q, const double* H, double* F, double* J, int n) noexcept nogil
