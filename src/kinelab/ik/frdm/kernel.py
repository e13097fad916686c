"""The compiled FRDM inner loop (:mod:`kinelab.core._frdm`, built at install) as Python calls it: the exact
per-joint steps, sweeps, acceleration, restarts.

Everything here works on the arrays of the chain model (:mod:`kinelab.ik.chain`); the readable
reference of the same mathematics is :mod:`kinelab.ik.frdm.reference`, and the tests hold the two
together. Notation (docs/methods.md §1): e, o = joint axis and a point on it (base frame), p = tool
point, R = tool rotation (columns u_x, u_y, u_z), starred = target. Objective

    E = w_p ‖p − p*‖² + Σ_j w_j ‖u_j − u*_j‖².

Inputs travel as typed tuples: :class:`~kinelab.ik.chain.PackedChain` (the robot), :class:`Objective` (the
target, weights, tolerances and windows of one solve), :class:`Settings` (the sweep and monitor
settings) and :class:`Memory` (work arrays the caller keeps between calls). State and statistics are
float arrays whose slots have names (``S_*``, ``T_*``).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from kinelab.core import _frdm
from kinelab.core._frdm import Code, Order
from kinelab.ik.chain import PackedChain

# sweep order codes (MIXED: per restart, in turn) and run()'s return codes: the compiled core's enums, as ints
TIP_TO_BASE, BASE_TO_TIP, ALTERNATE, MIXED = (int(o) for o in (Order.TIP_TO_BASE, Order.BASE_TO_TIP, Order.ALTERNATE,
                                                               Order.MIXED))
CONVERGED, STALL_STEP, STALL_WINDOW, BUDGET = (int(c) for c in (Code.CONVERGED, Code.STALL_STEP, Code.STALL_WINDOW,
                                                                Code.BUDGET))

# slots of an attempt's state array (S_FINISH: 0 the Newton finish not tried, 1 tried and fell short, 2 converged;
# S_NEWTON: its Gauss–Newton steps)
S_HISTORY, S_SWEEPS, S_E_WINDOW, S_WINDOW_START, S_ACCEPTED, S_E, S_KICKED, S_HELD, S_SINCE_FK, S_FINISH, \
    S_NEWTON = range(11)
STATE_SIZE = 11
# slots of a multistart's statistics array (T_NEWTON: Gauss–Newton steps of the finish, every attempt)
T_ATTEMPTS, T_SWEEPS, T_STALLS, T_ACCEPTED, T_BEST_E, T_CUT, T_POLISHED, T_NEWTON = range(8)
STATS_SIZE = 8


class Objective(NamedTuple):
    """One solve: target, weights, tolerances, and the joint windows the bypasses may tighten."""

    lower: np.ndarray  # (n,) [rad or m]; −inf where unbounded
    upper: np.ndarray  # (n,)
    free: np.ndarray  # (n,) bool; False: the joint is frozen
    pstar: np.ndarray  # (3,) target point [m], base frame
    Rstar: np.ndarray  # (3, 3) target rotation
    w_p: float  # position weight [1/m²]
    w_ax: np.ndarray  # (3,) weights of the tool x, y, z axes
    tol_pos: float  # [m]
    tol_rot: float  # [rad]
    check_pos: bool
    check_rot: bool
    q_rest: np.ndarray  # (n,) rest configuration [rad or m] the rest term pulls towards
    w_rest: float  # weight of the rest term (0: none, the paper's objective)
    rot_axis: int  # rotation check: −1 the whole rotation; 0, 1, 2 only that tool axis (roll free)


class Settings(NamedTuple):
    """Sweep and monitor settings (docs/methods.md §1.5–1.6)."""

    relax: float  # step = relax × the exact optimum, 0 < relax < 2
    eps_q: float  # a sweep moving less than this in Σ|Δq| is a stall [rad or m]
    window: int  # sweeps over which the objective must fall by window_rel
    window_rel: float
    accel_m: int  # Anderson memory (0: plain FRDM)
    polish: int  # Gauss–Newton steps tried on a stalled attempt before the restart (0: none)
    finish_below: float  # the Newton finish starts once the objective is below this (0: never, the paper's FRDM)
    finish_steps: int  # Gauss–Newton steps of the finish


class Memory(NamedTuple):
    """Work arrays kept by the caller between kernel calls of one attempt."""

    X: np.ndarray  # (accel_m + 1, n) ring of iterates
    G: np.ndarray  # (accel_m + 1, n) ring of sweep residuals F(x) − x
    state: np.ndarray  # (STATE_SIZE,) slots S_*
    trace: np.ndarray  # per-sweep objective (length 0: not recorded)
    held: np.ndarray  # (2n + 4, 3): e, o, p, R of a run the sweep budget cut (S_HELD = 1), for its resumption


def new_memory(n: int, accel_m: int, trace_length: int = 0) -> Memory:
    """Zeroed work arrays for an attempt on an n-joint chain."""
    return Memory(np.zeros((accel_m + 1, n)), np.zeros((accel_m + 1, n)), np.zeros(STATE_SIZE),
                  np.full(trace_length, -1.0), np.zeros((2 * n + 4, 3)))


def revolute_BC(e: np.ndarray, o: np.ndarray, p: np.ndarray, R: np.ndarray, pstar: np.ndarray, Rstar: np.ndarray,
                w_p: float, w_ax: np.ndarray) -> tuple[float, float]:
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about the line (e, o) (docs/methods.md §1.3)."""
    e, o, p, pstar, w_ax = (np.ascontiguousarray(v, dtype=float) for v in (e, o, p, pstar, w_ax))
    return _frdm.revolute_bc(e, o, p, R, pstar, Rstar, float(w_p), w_ax)


def sweep(q: np.ndarray, e: np.ndarray, o: np.ndarray, kind: np.ndarray, lower: np.ndarray, upper: np.ndarray,
          free: np.ndarray, p: np.ndarray, R: np.ndarray, pstar: np.ndarray, Rstar: np.ndarray, w_p: float,
          w_ax: np.ndarray, relax: float, base_to_tip: bool, q_rest: np.ndarray, w_rest: float) -> float:
    """One sweep over the free joints, tip → base or base → tip; updates q, p, R (and e, o base → tip) in place.

    ``e``, ``o`` must hold the axes at the sweep's starting q. With ``w_rest`` > 0 each step is the exact
    minimiser of E plus the rest term. Returns Σ|Δq_i|.
    """
    return _frdm.sweep_once(q, e, o, kind, lower, upper, np.ascontiguousarray(free, dtype=np.bool_).view(np.uint8),
                            p, R, np.ascontiguousarray(pstar, dtype=float), np.ascontiguousarray(Rstar, dtype=float),
                            float(w_p), np.ascontiguousarray(w_ax, dtype=float), float(relax), bool(base_to_tip),
                            np.ascontiguousarray(q_rest, dtype=float), float(w_rest))


def run(q: np.ndarray, ch: PackedChain, pb: Objective, st: Settings, order: int, max_sweeps: int,
        mem: Memory) -> tuple[int, int]:
    """Sweep until converged, stalled or ``max_sweeps`` sweeps; q is updated in place. Returns (code, sweeps in
    this call); the state slots S_* carry the rest."""
    return _frdm.run_kernel(q, ch, pb, st, order, max_sweeps, mem)


def multistart(q: np.ndarray, ch: PackedChain, pb: Objective, st: Settings, order: int, max_sweeps: int,
               rng_state: np.ndarray, max_attempts: int, sweep_budget: float, best_q: np.ndarray, stats: np.ndarray,
               mem: Memory) -> int:
    """Attempts from q, then from seeded uniform starts, until one converges, ``max_attempts`` have run or
    ``sweep_budget`` sweeps (a total) are spent; one chunk of the compiled multistart. Returns a run() code."""
    return _frdm.Packed(ch, pb, st, mem).multistart(q, order, max_sweeps, rng_state, max_attempts, sweep_budget,
                                                    best_q, stats)


@functools.cache
def no_rest(n: int) -> np.ndarray:
    """A shared rest configuration for problems whose rest weight is 0 (the kernel never reads it then)."""
    return np.zeros(n)
