# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""A prepared solver's usual call in one compiled call: check the target and the start, run the kernel, judge the
answer with the certified compiled FK (turned into the limits by whole turns where that is needed).

One engine interface (:class:`Engine`: the checks, the verdict and the result, written once) over the kernels'
timed multistarts: :class:`FRDMEngine` and :class:`BiquatEngine` each supply only their run. The prepared solver
(:class:`kinelab.IK`) builds an engine once; per call only the target, the start, the seed and the clock change.
An unusual call gets the code of why the engine declines it (an int: :class:`kinelab.ik.spec.Decline` names them —
a target that is not a ``pin.SE3`` of a proper pose within the reach bound, a start that is not n real numbers, a
start outside the limits, a seed that is not a whole number in [0, 2⁶⁴)), and the caller takes the general route,
which names what is wrong: the engine changes the cost, never the answer.
"""

import os
from functools import partial

import numpy as np

cimport numpy as cnp
from libc.math cimport M_PI, ceil
from libc.stdlib cimport free, malloc
from libc.string cimport memcpy

from kinelab.core._geometry cimport wrap
cimport kinelab.core._biquat as bq
from kinelab.core._chain cimport Judge
from kinelab.core._frdm cimport (CONTINUOUS, CONVERGED, STATS_SIZE, T_STALLS, Packed, now, random_configuration,
                                 restart_windows, timed)
from kinelab.core._verdict cimport pose_errors, take_target

cnp.import_array()

cdef double TWO_PI = 2.0 * M_PI
cdef int REVOLUTE = 0
# the statistics slots every kernel's multistart shares: its attempts, and its iterations (FRDM's sweeps, the
# biquaternion preset's steps)
cdef int T_ATTEMPTS = 0, T_ITERATIONS = 1
SEED_LIMIT = 1 << 64
# why Engine.solve declines a call (kinelab.ik.spec.Decline names them; the general route serves it)
DECLINE_TARGET = 1  # not a pin.SE3, or not a proper pose, or beyond the reach bound
DECLINE_START = 2  # q0 is not n real numbers
DECLINE_OUTSIDE = 3  # q0 lies outside the limits
DECLINE_SEED = 4  # not a whole number in [0, 2^64)
DECLINE_EMPTY = 5  # a chain without joints


cdef unsigned long long splitmix(unsigned long long x) noexcept nogil:
    """A non-zero generator state from a seed (splitmix64; :func:`kinelab.ik.multistart.seed_state`'s)."""
    x = x + 0x9E3779B97F4A7C15ULL
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL
    return (x ^ (x >> 31)) | 1ULL


if <int> bq.STATS_SIZE != <int> STATS_SIZE:
    raise ImportError("kinelab.core._engine: the kernels' statistics arrays differ in size; rebuild the core")



cdef class Engine:
    """A prepared solver's usual call (see the module's docstring): the checks, the verdict and the result, written
    once; a kernel's engine supplies ``_run`` (its timed multistart) and, where it has them, ``_events``.

    Args:
        judge: the robot's certified compiled FK.
        spec: the call's constants, read once: ``kind`` (n,) joint codes; ``draw_lower``, ``draw_upper`` the
            window random starts are drawn in; ``check_lower``, ``check_upper`` the limits a start and an answer
            must lie within; ``turn_lower``, ``turn_upper`` the limits a whole turn brings a revolute answer into;
            ``wrap_continuous`` (continuous joints of an answer wrapped into (−π, π] before the verdict, as the
            solver's general route does); ``anchor`` (3,) and ``radius`` [m] the reach bound (inf: none); ``pstar``
            (3,), ``Rstar`` (3, 3) the arrays a call's target is copied into (the kernel reads them);
            ``attempts`` (the first and the restarts); ``budget`` [s] (inf: none); ``tol_pos`` [m], ``tol_rot``
            [rad], ``check_pos``, ``check_rot``, ``axis`` (−1, or 0, 1, 2 for task "axis") the verdict's; ``se3``
            the target type of a usual call; ``result`` the result type, ``fields`` the values every converged
            result shares (a dict), ``diagnostics`` (stats → the diagnostics, called when a result's are first
            read) and ``unmet`` (the general result of any other outcome: ``unmet(target, code, q, stats, position
            error, rotation error, met, t_start, deadline, seed)``).
    """

    cdef Judge judge
    cdef const long long[::1] kind
    cdef const double[::1] draw_lower, draw_upper, check_lower, check_upper, turn_lower, turn_upper, anchor
    cdef double[::1] pstar
    cdef double[:, ::1] Rstar
    cdef double radius, budget, tol_pos, tol_rot
    cdef int n, attempts, check_pos, check_rot, axis, continuous
    cdef double* q  # the kernel's working configuration
    cdef object se3, result, fields, diagnostics, unmet

    def __init__(self, Judge judge, spec):
        self.judge, self.kind, self.n = judge, spec.kind, len(spec.kind)
        self.draw_lower, self.draw_upper = spec.draw_lower, spec.draw_upper
        self.check_lower, self.check_upper = spec.check_lower, spec.check_upper
        self.turn_lower, self.turn_upper = spec.turn_lower, spec.turn_upper
        self.anchor, self.radius = spec.anchor, spec.radius
        self.pstar, self.Rstar = spec.pstar, spec.Rstar
        self.attempts, self.budget = spec.attempts, spec.budget
        self.tol_pos, self.tol_rot, self.axis = spec.tol_pos, spec.tol_rot, spec.axis
        self.check_pos, self.check_rot = spec.check_pos, spec.check_rot
        self.se3, self.result, self.fields = spec.se3, spec.result, dict(spec.fields)
        self.diagnostics, self.unmet = spec.diagnostics, spec.unmet
        for name in ("draw_lower", "draw_upper", "check_lower", "check_upper", "turn_lower", "turn_upper"):
            if len(getattr(spec, name)) != self.n:
                raise ValueError(f"{type(self).__name__}: {name} needs one value per joint ({self.n})")
        if self.anchor.shape[0] != 3 or self.pstar.shape[0] != 3 or self.Rstar.shape[0] != 3 \
                or self.Rstar.shape[1] != 3 or judge.kind.shape[0] != self.n or not -1 <= self.axis <= 2:
            raise ValueError(f"{type(self).__name__}: a 3-vector anchor and target point, a 3 × 3 rotation, a judge "
                             "of the chain")
        self.continuous = bool(spec.wrap_continuous) and any(k == CONTINUOUS for k in spec.kind)
        self.q = <double*> malloc(sizeof(double) * max(1, self.n))
        if self.q == NULL:
            raise MemoryError(f"{type(self).__name__}: no memory for one configuration")

    def solve(self, target, q0, seed):
        """The usual call (see the module's docstring), or the code of why it declines (the general route serves).

        Args:
            target: oMtarget (base frame).
            q0: the first start [rad or m] (None: drawn from the seed's generator).
            seed: the restarts' seed (None: fresh entropy).

        Returns:
            The result: built here for a converged answer the judge confirms (the answer turned into the limits
            where whole turns do it; its diagnostics made when first read), else by ``unmet``; for an unusual call,
            an int: why the engine declines it (``DECLINE_TARGET`` ... ``DECLINE_EMPTY``).
        """
        cdef double t_start = now()
        cdef const double* start = NULL
        if self.n == 0:
            return DECLINE_EMPTY
        if type(target) is not self.se3:
            return DECLINE_TARGET
        if q0 is not None:
            start = self._start(q0)
            if start == NULL:
                q0 = _as_start(q0, self.n)  # a list, a float32 or integer array: the same values as float64
                if q0 is None:
                    return DECLINE_START
                start = self._start(q0)
        if seed is None:
            seed = int.from_bytes(os.urandom(8), "little")
        elif type(seed) is not int or not 0 <= seed < SEED_LIMIT:
            return DECLINE_SEED
        if not self._aim(target.homogeneous):
            return DECLINE_TARGET
        if start != NULL and not self._within(start):
            return DECLINE_OUTSIDE
        cdef cnp.npy_intp n = self.n
        cdef cnp.ndarray best = cnp.PyArray_EMPTY(1, &n, cnp.NPY_FLOAT64, 0)
        cdef double* q = <double*> cnp.PyArray_DATA(best)
        cdef double deadline = t_start + self.budget
        cdef double stats[STATS_SIZE]
        cdef unsigned long long rng = splitmix(<unsigned long long> seed)
        cdef int i
        if start == NULL:
            random_configuration(self.q, &self.kind[0], &self.draw_lower[0], &self.draw_upper[0], self.n, &rng)
        else:
            memcpy(self.q, start, sizeof(double) * self.n)
        for i in range(STATS_SIZE):
            stats[i] = 0.0
        cdef int code = self._run(q, stats, &rng, deadline)
        cdef double dp, dr
        cdef bint met = self._judged(q, &dp, &dr)
        if not met or code != CONVERGED:
            return self.unmet(target, code, best, _array(stats, STATS_SIZE), dp, dr, met, t_start, deadline, seed)
        return self._converged(best, stats, dp, dr, t_start)

    cdef int _run(self, double* best, double* stats, unsigned long long* rng, double deadline):
        """The kernel's timed multistart from ``self.q`` (the first start); its answer in ``best``, its statistics
        in ``stats`` (zeroed; attempts and iterations in the shared slots). Returns the kernel's code (its
        convergence is CONVERGED)."""
        raise NotImplementedError

    cdef object _events(self, const double* stats):
        """The result's ``singular_events`` of a converged answer (none unless a kernel reports them)."""
        return []

    cdef const double* _start(self, object q0):
        """The start's values when q0 is n float64 values in one C-contiguous run, else NULL."""
        if type(q0) is not np.ndarray:
            return NULL
        cdef cnp.ndarray a = q0
        if cnp.PyArray_TYPE(a) != cnp.NPY_FLOAT64 or cnp.PyArray_NDIM(a) != 1 or cnp.PyArray_DIM(a, 0) != self.n \
                or not cnp.PyArray_IS_C_CONTIGUOUS(a):
            return NULL
        return <const double*> cnp.PyArray_DATA(a)

    cdef bint _aim(self, object homogeneous):
        """True when the target's matrix is a proper 4 × 4 pose within the reach bound: its point and rotation are
        then the problem's target."""
        if type(homogeneous) is not np.ndarray:
            return False
        cdef cnp.ndarray a = homogeneous
        if cnp.PyArray_TYPE(a) != cnp.NPY_FLOAT64 or cnp.PyArray_NDIM(a) != 2 or cnp.PyArray_DIM(a, 0) != 4 \
                or cnp.PyArray_DIM(a, 1) != 4:
            return False
        return take_target(homogeneous, self.anchor, self.radius, self.pstar, self.Rstar)

    cdef bint _within(self, const double* q) noexcept:
        cdef int i
        for i in range(self.n):
            if not self.check_lower[i] <= q[i] <= self.check_upper[i]:  # also False for NaN
                return False
        return True

    cdef bint _judged(self, double* q, double* dp, double* dr):
        """The judge's word on q (continuous joints wrapped into (−π, π] where the engine wraps them, then the
        whole turn into the limits where one exists): True when the task's components are met and q is within the
        limits."""
        cdef int i, n = self.n
        cdef bint turned = False
        cdef double lowest
        if self.continuous:
            for i in range(n):
                if self.kind[i] == CONTINUOUS:
                    q[i] = wrap(q[i])
        cdef bint within = self._verdict(q, dp, dr)
        if not within:
            for i in range(n):
                if self.kind[i] == REVOLUTE and (q[i] < self.turn_lower[i] or q[i] > self.turn_upper[i]):
                    lowest = q[i] + TWO_PI * ceil((self.turn_lower[i] - q[i]) / TWO_PI)
                    if lowest <= self.turn_upper[i]:
                        q[i], turned = lowest, True
            if turned:
                within = self._verdict(q, dp, dr)
        return within and (not self.check_pos or dp[0] <= self.tol_pos) and (not self.check_rot or dr[0] <= self.tol_rot)

    cdef bint _verdict(self, const double* q, double* dp, double* dr):
        cdef double T[16]
        self.judge.pose(q, T)
        pose_errors(T, &self.pstar[0], &self.Rstar[0, 0], self.axis, dp, dr)
        return self._within(q)

    cdef object _converged(self, object best, const double* stats, double dp, double dr, double t_start):
        """The result of a converged answer the judge confirmed (the result type's ``fast`` factory)."""
        return fast_result(self.result, self.fields, {
            "q": best, "position_error": dp, "rotation_error": dr, "iterations": <int> stats[T_ITERATIONS],
            "restarts": max(0, <int> stats[T_ATTEMPTS] - 1), "singular_events": self._events(stats), "bypasses": [],
            "_make_diagnostics": partial(self.diagnostics, _array(stats, STATS_SIZE)), "wall_time": now() - t_start})

    def __dealloc__(self):
        free(self.q)


cdef class FRDMEngine(Engine):
    """Compiled FRDM's usual call (see :class:`Engine`).

    Args:
        packed: the kernel's chain, problem (its ``pstar`` and ``Rstar`` are the spec's arrays), settings and
            memory.
        judge: the robot's certified compiled FK.
        spec: :class:`Engine`'s, and ``order``, ``cap``, ``first_chunk``, ``later_chunk`` as the timed multistart
            takes them, ``stall_events`` (stalls → the events).
    """

    cdef Packed packed
    cdef double first_chunk, later_chunk
    cdef int order, cap
    cdef object stall_events

    def __init__(self, Packed packed, Judge judge, spec):
        super().__init__(judge, spec)
        if packed.n != self.n:
            raise ValueError(f"FRDMEngine: the kernel's chain has {packed.n} joints, the spec {self.n}")
        self.packed = packed
        self.order, self.cap = spec.order, spec.cap
        self.first_chunk, self.later_chunk = spec.first_chunk, spec.later_chunk
        self.stall_events = spec.stall_events

    cdef int _run(self, double* best, double* stats, unsigned long long* rng, double deadline):
        cdef int code
        cdef Packed pk = self.packed
        memcpy(best, self.q, sizeof(double) * self.n)
        with nogil:
            code = timed(self.q, &pk.ch, &pk.pb, &pk.st, self.order, self.cap, rng, self.attempts, self.first_chunk,
                         self.later_chunk, deadline, 0, best, stats, &pk.mem)
        return code

    cdef object _events(self, const double* stats):
        cdef int stalls = <int> stats[T_STALLS]
        return self.stall_events(stalls) if stalls else []


cdef class BiquatEngine(Engine):
    """The biquaternion preset's usual call (see :class:`Engine`): law (9), newton Euler, seeded restarts, the clock
    looked at between chunks of steps, as :func:`kinelab.ik.biquat.solver.multistart` does.

    Args:
        packed: the chain (its problem and settings unused).
        judge: the robot's certified compiled FK.
        spec: :class:`Engine`'s (``draw_lower``, ``draw_upper`` also the limits a converged answer is wrapped into
            and the restarts' windows), and the control's ``k`` [1/s], ``max_step`` [rad or m], ``max_steps``,
            ``eps_rot``, ``eps_dual`` [m], ``damping``; ``first_chunk``, ``later_chunk`` the steps before the first
            look at the clock and between two; ``wide`` (n,) the base joints whose restart window follows the
            target (``restart_windows`` of :mod:`kinelab.core._frdm`), ``length`` [m] the chain's length.
    """

    cdef Packed packed
    cdef bq.Control control
    cdef int first_chunk, later_chunk, any_wide
    cdef const unsigned char[::1] wide
    cdef double length
    cdef double* scratch  # the restarts' windows (2n), then restart_windows' own scratch (6n + 12)

    def __init__(self, Packed packed, Judge judge, spec):
        super().__init__(judge, spec)
        if packed.n != self.n or len(spec.wide) != self.n:
            raise ValueError(f"BiquatEngine: the chain has {packed.n} joints, the spec {self.n}")
        self.packed, self.wide, self.length = packed, spec.wide, spec.length
        self.any_wide = any(spec.wide)
        self.control.pstar, self.control.Rstar = &self.pstar[0], &self.Rstar[0, 0]
        self.control.k, self.control.h = spec.k, 1.0 / spec.k
        self.control.max_step, self.control.max_steps = spec.max_step, spec.max_steps
        self.control.eps_rot, self.control.eps_dual, self.control.damping = spec.eps_rot, spec.eps_dual, spec.damping
        self.first_chunk, self.later_chunk = spec.first_chunk, spec.later_chunk
        self.scratch = <double*> malloc(sizeof(double) * (8 * self.n + 12))
        if self.scratch == NULL:
            raise MemoryError("BiquatEngine: no memory for the restarts' windows")

    cdef int _run(self, double* best, double* stats, unsigned long long* rng, double deadline):
        cdef int code
        cdef int n = self.n
        cdef const double* lower = &self.draw_lower[0]
        cdef const double* upper = &self.draw_upper[0]
        cdef const double* restart_lower = lower
        cdef const double* restart_upper = upper
        cdef Packed pk = self.packed
        cdef bq.Control* control = &self.control
        if self.any_wide:
            restart_windows(&pk.ch, self.q, &self.pstar[0], lower, upper, &self.wide[0], self.length,
                            self.scratch + 2 * n, self.scratch, self.scratch + n)
            restart_lower, restart_upper = self.scratch, self.scratch + n
        with nogil:
            code = bq.timed(self.q, &pk.ch, lower, upper, control, rng, self.attempts, self.first_chunk,
                            self.later_chunk, deadline, restart_lower, restart_upper, stats)
        memcpy(best, self.q, sizeof(double) * n)
        return code

    def __dealloc__(self):
        free(self.scratch)


cpdef object fast_result(type cls, dict shared, dict values):
    """A result of type ``cls`` (:class:`kinelab.ik.result.IKResult`) from its fields, without ``__init__``'s work:
    the compiled routes' one factory (this engine's converged answers, the closed form's rows).

    Args:
        cls: the result type.
        shared: the fields every result of the route shares (success, status, solver, mode, task, judge, ...).
        values: this result's own (q, errors, wall time, ...); ``_make_diagnostics``, a callable, stands for
            ``diagnostics`` until they are first read.
    """
    made = cls.__new__(cls)
    fields = made.__dict__
    fields.update(shared)
    fields.update(values)
    return made


cdef object _as_start(object q0, int n):
    """q0 as n float64 values in a new C-contiguous array when it holds n real numbers (a list, a tuple, an array of
    another real dtype or layout: the values :meth:`kinelab.Robot.check_q` takes from it), else None (the general
    route names what is wrong)."""
    try:
        raw = np.asarray(q0)
    except (TypeError, ValueError):
        return None
    if raw.dtype.kind not in "fiu" or raw.shape != (n,):
        return None
    return np.ascontiguousarray(raw, dtype=np.float64)


cdef cnp.ndarray _array(const double* values, cnp.npy_intp size):
    """A new float64 array of these values."""
    cdef cnp.ndarray out = cnp.PyArray_EMPTY(1, &size, cnp.NPY_FLOAT64, 0)
    memcpy(cnp.PyArray_DATA(out), values, sizeof(double) * size)
    return out
