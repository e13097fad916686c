# cython: language_level=3, boundscheck=False, wraparound=False
"""BLAS and LAPACK for the compiled kernels: SciPy's (``scipy.linalg.cython_blas`` and ``cython_lapack``, the very
functions NumPy's matmul, solve and svd reach through SciPy-linked code), taken on first use.

Loading them imports SciPy, a tenth of a second or more: ``kinelab fk``, ``info`` and ``robots`` never need them,
so every entry point that may reach a kernel using them calls :func:`ready` first (the packed solve does, in
:class:`kinelab.core._frdm.Packed`). They are read from the two extension modules directly, without running
``scipy.linalg``'s package import (three times as long); where that is not possible the plain import serves.
"""

from cpython.pycapsule cimport PyCapsule_GetName, PyCapsule_GetPointer

ctypedef void (*dgemm_t)(char*, char*, int*, int*, int*, double*, double*, int*, double*, int*, double*, double*,
                         int*) noexcept nogil
ctypedef void (*dgemv_t)(char*, int*, int*, double*, double*, int*, double*, int*, double*, double*,
                         int*) noexcept nogil
ctypedef double (*ddot_t)(int*, double*, int*, double*, int*) noexcept nogil
ctypedef void (*dgesv_t)(int*, int*, double*, int*, int*, double*, int*, int*) noexcept nogil
ctypedef void (*dgetrf_t)(int*, int*, double*, int*, int*, int*) noexcept nogil
ctypedef void (*dgesdd_t)(char*, int*, int*, double*, int*, double*, double*, int*, double*, int*, double*, int*,
                          int*, int*) noexcept nogil
ctypedef void (*dgetrs_t)(char*, int*, int*, double*, int*, int*, double*, int*, int*) noexcept nogil
ctypedef void (*dgecon_t)(char*, int*, double*, int*, double*, double*, double*, int*, int*) noexcept nogil
ctypedef void (*dgeev_t)(char*, char*, int*, double*, int*, double*, double*, double*, int*, double*, int*, double*,
                         int*, int*) noexcept nogil
ctypedef void (*dggev_t)(char*, char*, int*, double*, int*, double*, int*, double*, double*, double*, double*, int*,
                         double*, int*, double*, int*, int*) noexcept nogil

cdef dgemm_t _dgemm = NULL
cdef dgemv_t _dgemv = NULL
cdef ddot_t _ddot = NULL
cdef dgesv_t _dgesv = NULL
cdef dgetrf_t _dgetrf = NULL
cdef dgesdd_t _dgesdd = NULL
cdef dgetrs_t _dgetrs = NULL
cdef dgecon_t _dgecon = NULL
cdef dgeev_t _dgeev = NULL
cdef dggev_t _dggev = NULL


cdef void dgemm(char* transa, char* transb, int* m, int* n, int* k, double* alpha, double* a, int* lda, double* b,
                int* ldb, double* beta, double* c, int* ldc) noexcept nogil:
    _dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)


cdef void dgemv(char* trans, int* m, int* n, double* alpha, double* a, int* lda, double* x, int* incx, double* beta,
                double* y, int* incy) noexcept nogil:
    _dgemv(trans, m, n, alpha, a, lda, x, incx, beta, y, incy)


cdef double ddot(int* n, double* x, int* incx, double* y, int* incy) noexcept nogil:
    return _ddot(n, x, incx, y, incy)


cdef void dgesv(int* n, int* nrhs, double* a, int* lda, int* ipiv, double* b, int* ldb, int* info) noexcept nogil:
    _dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)


cdef void dgetrf(int* m, int* n, double* a, int* lda, int* ipiv, int* info) noexcept nogil:
    _dgetrf(m, n, a, lda, ipiv, info)


cdef void dgesdd(char* jobz, int* m, int* n, double* a, int* lda, double* s, double* u, int* ldu, double* vt,
                 int* ldvt, double* work, int* lwork, int* iwork, int* info) noexcept nogil:
    _dgesdd(jobz, m, n, a, lda, s, u, ldu, vt, ldvt, work, lwork, iwork, info)


cdef void dgetrs(char* trans, int* n, int* nrhs, double* a, int* lda, int* ipiv, double* b, int* ldb,
                 int* info) noexcept nogil:
    _dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)


cdef void dgecon(char* norm, int* n, double* a, int* lda, double* anorm, double* rcond, double* work, int* iwork,
                 int* info) noexcept nogil:
    _dgecon(norm, n, a, lda, anorm, rcond, work, iwork, info)


cdef void dgeev(char* jobvl, char* jobvr, int* n, double* a, int* lda, double* wr, double* wi, double* vl, int* ldvl,
                double* vr, int* ldvr, double* work, int* lwork, int* info) noexcept nogil:
    _dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)


cdef void dggev(char* jobvl, char* jobvr, int* n, double* a, int* lda, double* b, int* ldb, double* alphar,
                double* alphai, double* beta, double* vl, int* ldvl, double* vr, int* ldvr, double* work, int* lwork,
                int* info) noexcept nogil:
    _dggev(jobvl, jobvr, n, a, lda, b, ldb, alphar, alphai, beta, vl, ldvl, vr, ldvr, work, lwork, info)


def _module(name):
    """SciPy's extension module ``scipy.linalg.<name>``, loaded from its file when scipy.linalg is not imported
    yet (its package import is what costs), else the imported one."""
    import importlib
    import importlib.machinery
    import importlib.util
    import sys
    from pathlib import Path

    full = f"scipy.linalg.{name}"
    if full in sys.modules or "scipy.linalg" in sys.modules:
        return importlib.import_module(full)
    try:
        spec = importlib.util.find_spec("scipy")
        folder = Path(spec.origin).parent / "linalg"
        suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
        path = next(p for p in folder.iterdir() if p.name.startswith(name + ".") and p.name.endswith(suffixes))
        loader = importlib.machinery.ExtensionFileLoader(full, str(path))
        module = importlib.util.module_from_spec(importlib.util.spec_from_loader(full, loader))
        loader.exec_module(module)
        return module
    except Exception:  # an unusual SciPy layout: the plain import works wherever SciPy does
        return importlib.import_module(full)


cdef void* _pointer(dict table, str name) except NULL:
    capsule = table[name]
    return PyCapsule_GetPointer(capsule, PyCapsule_GetName(capsule))


cpdef void ready() except *:
    """Take BLAS and LAPACK from SciPy, once per process (a no-op afterwards)."""
    global _dgemm, _dgemv, _ddot, _dgesv, _dgetrf, _dgesdd, _dgetrs, _dgecon, _dgeev, _dggev
    if _dggev != NULL:
        return
    blas, lapack = _module("cython_blas").__pyx_capi__, _module("cython_lapack").__pyx_capi__
    _dgemm = <dgemm_t> _pointer(blas, "dgemm")
    _dgemv = <dgemv_t> _pointer(blas, "dgemv")
    _ddot = <ddot_t> _pointer(blas, "ddot")
    _dgesv = <dgesv_t> _pointer(lapack, "dgesv")
    _dgetrf = <dgetrf_t> _pointer(lapack, "dgetrf")
    _dgesdd = <dgesdd_t> _pointer(lapack, "dgesdd")
    _dgetrs = <dgetrs_t> _pointer(lapack, "dgetrs")
    _dgecon = <dgecon_t> _pointer(lapack, "dgecon")
    _dgeev = <dgeev_t> _pointer(lapack, "dgeev")
    _dggev = <dggev_t> _pointer(lapack, "dggev")
