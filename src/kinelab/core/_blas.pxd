# BLAS and LAPACK as SciPy's cython_blas / cython_lapack export them, loaded on first use (blas.pyx: ready()).

cdef void dgemm(char* transa, char* transb, int* m, int* n, int* k, double* alpha, double* a, int* lda, double* b,
                int* ldb, double* beta, double* c, int* ldc) noexcept nogil
cdef void dgemv(char* trans, int* m, int* n, double* alpha, double* a, int* lda, double* x, int* incx, double* beta,
                double* y, int* incy) noexcept nogil
cdef double ddot(int* n, double* x, int* incx, double* y, int* incy) noexcept nogil
cdef void dgesv(int* n, int* nrhs, double* a, int* lda, int* ipiv, double* b, int* ldb, int* info) noexcept nogil
cdef void dgetrf(int* m, int* n, double* a, int* lda, int* ipiv, int* info) noexcept nogil
cdef void dgesdd(char* jobz, int* m, int* n, double* a, int* lda, double* s, double* u, int* ldu, double* vt,
                 int* ldvt, double* work, int* lwork, int* iwork, int* info) noexcept nogil
cdef void dgetrs(char* trans, int* n, int* nrhs, double* a, int* lda, int* ipiv, double* b, int* ldb,
                 int* info) noexcept nogil
cdef void dgecon(char* norm, int* n, double* a, int* lda, double* anorm, double* rcond, double* work, int* iwork,
                 int* info) noexcept nogil
cdef void dgeev(char* jobvl, char* jobvr, int* n, double* a, int* lda, double* wr, double* wi, double* vl, int* ldvl,
                double* vr, int* ldvr, double* work, int* lwork, int* info) noexcept nogil
cdef void dggev(char* jobvl, char* jobvr, int* n, double* a, int* lda, double* b, int* ldb, double* alphar,
                double* alphai, double* beta, double* vl, int* ldvl, double* vr, int* ldvr, double* work, int* lwork,
                int* info) noexcept nogil
cpdef void ready() except *
