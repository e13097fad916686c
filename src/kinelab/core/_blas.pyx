# cython: language_level=3, boundscheck=False, wraparound=False
"""BLAS and LAPACK for the compiled kernels: SciPy's (the functions ``scipy.linalg.cython_blas`` and
``cython_lapack`` wrap, which NumPy's matmul, solve and svd reach through SciPy-linked code), taken on first use.

Where SciPy's wheel bundles its OpenBLAS (``scipy.libs/libscipy_openblas-*.so``, 32-bit integers: the library
``cython_blas`` itself links), the functions are looked up in that library directly, a few milliseconds; SciPy is
not imported. Anywhere else (another layout, another BLAS) they come from the two extension modules' capsules,
which imports SciPy (a few tens of milliseconds). ``kinelab fk``, ``info`` and ``robots`` never need them, so every
entry point that may reach a kernel using them calls :func:`ready` first (the packed solve does, in
:class:`kinelab.core._frdm.Packed`).
"""

from cpython.pycapsule cimport PyCapsule_GetName, PyCapsule_GetPointer
from posix.dlfcn cimport RTLD_LOCAL, RTLD_NOW, dlopen, dlsym

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


_SOURCE = None
cdef list _NAMES = ["dgemm", "dgemv", "ddot", "dgesv", "dgetrf", "dgesdd", "dgetrs", "dgecon", "dgeev", "dggev"]


def _bundled_library():
    """The path of SciPy's bundled 32-bit-integer OpenBLAS, or None (not a wheel that bundles one)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("scipy")  # finds the package without importing it
    if spec is None or spec.origin is None:
        return None
    found = sorted(p for p in (Path(spec.origin).parent.parent / "scipy.libs").glob("libscipy_openblas-*.so*")
                   if "64_" not in p.name)
    return str(found[0]) if len(found) == 1 else None


cdef dict _from_library():
    """Name → function pointer from the bundled OpenBLAS (its exports carry a ``scipy_`` prefix), or None."""
    path = _bundled_library()
    if path is None:
        return None
    cdef void* handle = dlopen(path.encode(), RTLD_NOW | RTLD_LOCAL)
    if handle == NULL:
        return None
    cdef void* f
    table = {}
    for name in _NAMES:
        f = dlsym(handle, f"scipy_{name}_".encode())
        if f == NULL:
            return None
        table[name] = <size_t> f
    return table


cdef dict _from_capsules():
    """Name → function pointer from SciPy's ``cython_blas`` and ``cython_lapack`` capsules (imports them)."""
    blas, lapack = _module("cython_blas").__pyx_capi__, _module("cython_lapack").__pyx_capi__
    return {name: <size_t> _pointer(blas if name in ("dgemm", "dgemv", "ddot") else lapack, name)
            for name in _NAMES}


cdef bint _answers(dict table):
    """Whether the functions compute what they should on a small case (a library whose integers are not the
    C ints these declarations pass would not)."""
    cdef double a[4]
    cdef double b[4]
    cdef double c[4]
    cdef int n = 2, one = 1
    cdef char* no = b"N"
    cdef double alpha = 1.0, beta = 0.0
    a[:] = [1.0, 3.0, 2.0, 4.0]  # column-major [[1, 2], [3, 4]]
    b[:] = [5.0, 7.0, 6.0, 8.0]
    c[:] = [0.0, 0.0, 0.0, 0.0]
    (<dgemm_t> <size_t> table["dgemm"])(no, no, &n, &n, &n, &alpha, a, &n, b, &n, &beta, c, &n)
    if (<ddot_t> <size_t> table["ddot"])(&n, a, &one, b, &one) != 26.0:
        return False
    return c[0] == 19.0 and c[1] == 43.0 and c[2] == 22.0 and c[3] == 50.0


cpdef void ready() except *:
    """Take BLAS and LAPACK from SciPy, once per process (a no-op afterwards)."""
    global _dgemm, _dgemv, _ddot, _dgesv, _dgetrf, _dgesdd, _dgetrs, _dgecon, _dgeev, _dggev, _SOURCE
    if _dggev != NULL:
        return
    table, _SOURCE = _from_library(), "bundled OpenBLAS"
    if table is None or not _answers(table):
        table, _SOURCE = _from_capsules(), "SciPy's capsules"
    _dgemm = <dgemm_t> <size_t> table["dgemm"]
    _dgemv = <dgemv_t> <size_t> table["dgemv"]
    _ddot = <ddot_t> <size_t> table["ddot"]
    _dgesv = <dgesv_t> <size_t> table["dgesv"]
    _dgetrf = <dgetrf_t> <size_t> table["dgetrf"]
    _dgesdd = <dgesdd_t> <size_t> table["dgesdd"]
    _dgetrs = <dgetrs_t> <size_t> table["dgetrs"]
    _dgecon = <dgecon_t> <size_t> table["dgecon"]
    _dgeev = <dgeev_t> <size_t> table["dgeev"]
    _dggev = <dggev_t> <size_t> table["dggev"]


def source():
    """Where :func:`ready` took the functions from: "bundled OpenBLAS" or "SciPy's capsules" (None before)."""
    return _SOURCE


def ggev(a, b):
    """LAPACK's QZ (``dggev``) of the real pencil (a, b), both n × n, with left and right eigenvectors: what
    ``scipy.linalg.lapack.dggev(a, b, 1, 1)`` computes (the same function), without importing ``scipy.linalg``
    (0.15–0.3 s, which would otherwise be paid inside a first general pose's time budget).

    Returns:
        (alphar, alphai, beta, vl, vr, info): the homogeneous eigenvalues' parts, the eigenvectors as LAPACK packs
        them (a complex pair as two real columns), and LAPACK's info (0: success).
    """
    import numpy as np

    ready()
    cdef double[::1, :] A = np.array(a, dtype=np.float64, order="F")  # copies: dggev overwrites its inputs
    cdef double[::1, :] B = np.array(b, dtype=np.float64, order="F")
    cdef int n = A.shape[0], info = 0, lwork = -1
    if A.shape[1] != n or B.shape[0] != n or B.shape[1] != n or n < 1:
        raise ValueError(f"ggev takes two n × n matrices, n ≥ 1 (got {A.shape[0]}×{A.shape[1]} and "
                         f"{B.shape[0]}×{B.shape[1]})")
    out = [np.empty(n), np.empty(n), np.empty(n), np.empty((n, n), order="F"), np.empty((n, n), order="F")]
    cdef double[::1] ar = out[0], ai = out[1], be = out[2]
    cdef double[::1, :] vl = out[3], vr = out[4]
    cdef double query = 0.0
    cdef char* v = b"V"
    _dggev(v, v, &n, &A[0, 0], &n, &B[0, 0], &n, &ar[0], &ai[0], &be[0], &vl[0, 0], &n, &vr[0, 0], &n, &query,
           &lwork, &info)
    lwork = max(int(query), 8 * n)
    cdef double[::1] work = np.empty(lwork)
    _dggev(v, v, &n, &A[0, 0], &n, &B[0, 0], &n, &ar[0], &ai[0], &be[0], &vl[0, 0], &n, &vr[0, 0], &n, &work[0],
           &lwork, &info)
    return (*out, info)
