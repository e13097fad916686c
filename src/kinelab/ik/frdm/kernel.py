"""The compiled FRDM inner loop (numba): the exact per-joint steps, sweeps, acceleration, restarts.

Everything here works on the arrays of the chain model (:mod:`kinelab.ik.chain`); the readable
reference of the same mathematics is :mod:`kinelab.ik.frdm.reference`, and the tests hold the two
together. Notation (docs/methods.md §1): e, o = joint axis and a point on it (base frame), p = tool
point, R = tool rotation (columns u_x, u_y, u_z), starred = target. Objective

    E = w_p ‖p − p*‖² + Σ_j w_j ‖u_j − u*_j‖².

Inputs travel as typed tuples: :class:`~kinelab.ik.chain.Chain` (the robot), :class:`Objective` (the
target, weights, tolerances and windows of one solve), :class:`Settings` (the sweep and monitor
settings) and :class:`Memory` (work arrays the caller keeps between calls). State and statistics are
float arrays whose slots have names (``S_*``, ``T_*``).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np
from numba import njit

from kinelab.ik.chain import (
    CONTINUOUS,
    PRISMATIC,
    TWO_PI,
    Chain,
    chain_fk,
    rotate_about,
    rotate_rows,
    rotm,
)
from kinelab.ik.frdm.newton import lm_polish
from kinelab.ik.frdm.newton import within as _within

REFRESH_SWEEPS = 8  # sweeps carried incrementally before the chain FK is recomputed
TIP_TO_BASE, BASE_TO_TIP, ALTERNATE, MIXED = 0, 1, 2, 3  # sweep order codes (MIXED: per restart, in turn)

# run() return codes
CONVERGED, STALL_STEP, STALL_WINDOW, BUDGET = 0, 1, 2, 3

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


Problem = Objective  # its name before 0.2: numba caches written by 0.1 refer to it and must still load


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


@njit(cache=True, inline="always")
def _hold(mem, e, o, p, R, since_fk):
    """Keep the carried state of a cut run, so that resuming it repeats exactly what one run would do."""
    n = e.shape[0]
    held = mem.held
    held[:n] = e
    held[n:2 * n] = o
    held[2 * n] = p
    held[2 * n + 1:] = R
    mem.state[S_HELD] = 1.0
    mem.state[S_SINCE_FK] = since_fk


@njit(cache=True, inline="always")
def _resume(mem, e, o, p, R):
    """The held state back into e, o, p, R; returns (fresh, since_fk)."""
    if mem.state[S_HELD] == 0.0:
        return False, 0
    n = e.shape[0]
    held = mem.held
    e[:] = held[:n]
    o[:] = held[n:2 * n]
    p[:] = held[2 * n]
    R[:] = held[2 * n + 1:]
    mem.state[S_HELD] = 0.0
    return True, int(mem.state[S_SINCE_FK])


@njit(cache=True, inline="always")
def objective(p, R, pstar, Rstar, w_p, w_ax):
    """FRDM's weighted objective at tool pose (p, R) against (pstar, Rstar) (docs/methods.md §1.2)."""
    d0, d1, d2 = p[0] - pstar[0], p[1] - pstar[1], p[2] - pstar[2]
    E = w_p * (d0 * d0 + d1 * d1 + d2 * d2)
    for j in range(3):
        u0 = R[0, j] - Rstar[0, j]
        u1 = R[1, j] - Rstar[1, j]
        u2 = R[2, j] - Rstar[2, j]
        E += w_ax[j] * (u0 * u0 + u1 * u1 + u2 * u2)
    return E


@njit(cache=True, inline="always")
def rest_term(q, kind, q_rest, w_rest):
    """w_rest Σ 2(1 − cos(q_i − r_i)) over revolute joints + w_rest Σ (q_i − r_i)² over prismatic ones."""
    if w_rest == 0.0:
        return 0.0
    acc = 0.0
    for i in range(q.shape[0]):
        d = q[i] - q_rest[i]
        acc += d * d if kind[i] == PRISMATIC else 2.0 * (1.0 - np.cos(d))
    return w_rest * acc


@njit(cache=True, inline="always")
def total_objective(q, kind, p, R, pb):
    """The objective E plus the rest term of the problem."""
    return objective(p, R, pb.pstar, pb.Rstar, pb.w_p, pb.w_ax) + rest_term(q, kind, pb.q_rest, pb.w_rest)


@njit(cache=True, inline="always")
def _bc(e0, e1, e2, o0, o1, o2, p, R, pstar, Rstar, w_p, w_ax):
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about the line (e, o)."""
    r0, r1, r2 = p[0] - o0, p[1] - o1, p[2] - o2
    d0, d1, d2 = pstar[0] - o0, pstar[1] - o1, pstar[2] - o2
    er = e0 * r0 + e1 * r1 + e2 * r2
    ed = e0 * d0 + e1 * d1 + e2 * d2
    B = w_p * (d0 * r0 + d1 * r1 + d2 * r2 - ed * er)  # d⊥·r⊥
    C = w_p * (e0 * (r1 * d2 - r2 * d1) + e1 * (r2 * d0 - r0 * d2) + e2 * (r0 * d1 - r1 * d0))  # e·(r×d)
    for j in range(3):
        w = w_ax[j]
        if w != 0.0:
            u0, u1, u2 = R[0, j], R[1, j], R[2, j]
            s0, s1, s2 = Rstar[0, j], Rstar[1, j], Rstar[2, j]
            eu = e0 * u0 + e1 * u1 + e2 * u2
            es = e0 * s0 + e1 * s1 + e2 * s2
            B += w * (s0 * u0 + s1 * u1 + s2 * u2 - es * eu)
            C += w * (e0 * (u1 * s2 - u2 * s1) + e1 * (u2 * s0 - u0 * s2) + e2 * (u0 * s1 - u1 * s0))
    return B, C


@njit(cache=True)
def revolute_BC(e, o, p, R, pstar, Rstar, w_p, w_ax):
    """B, C of E(θ) = a − 2B cos θ − 2C sin θ for a rotation θ about (e, o) (array arguments)."""
    return _bc(e[0], e[1], e[2], o[0], o[1], o[2], p, R, pstar, Rstar, w_p, w_ax)


@njit(cache=True, inline="always")
def revolute_angle(B, C, lo, hi, continuous):
    """The exact minimiser of E(θ) over the window [lo, hi] ∋ 0 (methods.md §1.5)."""
    if B == 0.0 and C == 0.0:
        return 0.0
    t = np.arctan2(C, B)
    if continuous:
        return t
    best = 0.0
    found = False
    for k in (-1.0, 0.0, 1.0):
        cand = t + k * TWO_PI
        if lo <= cand <= hi and (not found or abs(cand) < abs(best)):
            best = cand
            found = True
    if found:
        return best
    return lo if np.cos(lo - t) >= np.cos(hi - t) else hi


@njit(cache=True, inline="always")
def _carry_axis(Rg, tg, e, o, i):
    """Move joint i's axis (e_i, o_i) by the rigid motion (Rg, tg) of the joints stepped before it, in place.

    Base → tip, no later step moves joint i's axis: written back, e and o hold the axes at the new q when
    the sweep ends, and the next sweep needs no chain FK.
    """
    e0 = Rg[0, 0] * e[i, 0] + Rg[0, 1] * e[i, 1] + Rg[0, 2] * e[i, 2]
    e1 = Rg[1, 0] * e[i, 0] + Rg[1, 1] * e[i, 1] + Rg[1, 2] * e[i, 2]
    e2 = Rg[2, 0] * e[i, 0] + Rg[2, 1] * e[i, 1] + Rg[2, 2] * e[i, 2]
    norm = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)  # keep rounding in Rg from compounding
    o0 = Rg[0, 0] * o[i, 0] + Rg[0, 1] * o[i, 1] + Rg[0, 2] * o[i, 2] + tg[0]
    o1 = Rg[1, 0] * o[i, 0] + Rg[1, 1] * o[i, 1] + Rg[1, 2] * o[i, 2] + tg[1]
    o2 = Rg[2, 0] * o[i, 0] + Rg[2, 1] * o[i, 1] + Rg[2, 2] * o[i, 2] + tg[2]
    e[i, 0], e[i, 1], e[i, 2] = e0 / norm, e1 / norm, e2 / norm
    o[i, 0], o[i, 1], o[i, 2] = o0, o1, o2


@njit(cache=True, inline="always")
def _slide(e0, e1, e2, p, pstar, w_p, relax, off_rest, w_rest):
    """A prismatic joint's exact step [m] along (e0, e1, e2): the position error's projection, weighed against
    the rest term (``off_rest`` = q_i − r_i), times ``relax``."""
    if w_p <= 0.0 and w_rest <= 0.0:
        return 0.0
    along = e0 * (pstar[0] - p[0]) + e1 * (pstar[1] - p[1]) + e2 * (pstar[2] - p[2])
    return relax * (w_p * along - w_rest * off_rest) / (w_p + w_rest)


@njit(cache=True, inline="always")
def sweep(q, e, o, kind, lower, upper, free, p, R, pstar, Rstar, w_p, w_ax, relax, base_to_tip, q_rest, w_rest):
    """One sweep over the free joints, tip → base or base → tip; updates q, p, R in place.

    ``e``, ``o`` must hold the axes at the sweep's starting q (from ``chain_fk``). Tip → base needs
    nothing more (a joint never moves the joints upstream of it); base → tip carries the rigid motion
    (Rg, tg) of the joints already stepped to the downstream axes, and leaves e, o at the new q (tip →
    base leaves them stale). With ``w_rest`` > 0 each step is the exact minimiser of E plus the rest term
    (the term keeps the closed form: it adds w_rest cos φ to B and −w_rest sin φ to C, φ = q_i − r_i).
    Returns Σ|Δq_i|.
    """
    n = q.shape[0]
    total = 0.0
    Rg = np.eye(3)
    tg = np.zeros(3)
    moved_any = False
    for k in range(n):
        i = k if base_to_tip else n - 1 - k
        if moved_any:
            _carry_axis(Rg, tg, e, o, i)
        e0, e1, e2 = e[i, 0], e[i, 1], e[i, 2]
        o0, o1, o2 = o[i, 0], o[i, 1], o[i, 2]
        if not free[i]:
            continue
        lo = lower[i] - q[i]
        hi = upper[i] - q[i]
        if kind[i] == PRISMATIC:
            s = min(max(_slide(e0, e1, e2, p, pstar, w_p, relax, q[i] - q_rest[i], w_rest), lo), hi)
            if s == 0.0:
                continue
            p[0] += e0 * s
            p[1] += e1 * s
            p[2] += e2 * s
            if base_to_tip:
                tg[0] += e0 * s
                tg[1] += e1 * s
                tg[2] += e2 * s
            step = s
        else:
            B, C = _bc(e0, e1, e2, o0, o1, o2, p, R, pstar, Rstar, w_p, w_ax)
            if w_rest != 0.0:
                B += w_rest * np.cos(q[i] - q_rest[i])
                C -= w_rest * np.sin(q[i] - q_rest[i])
            theta = revolute_angle(B, C, lo, hi, kind[i] == CONTINUOUS)
            if relax != 1.0:
                theta = relax * theta
                if kind[i] != CONTINUOUS:
                    theta = min(max(theta, lo), hi)
            if theta == 0.0:
                continue
            m = rotm(e0, e1, e2, theta)
            rotate_about(m, o0, o1, o2, p)
            rotate_rows(m, R)
            if base_to_tip:
                rotate_rows(m, Rg)
                rotate_about(m, o0, o1, o2, tg)
            step = theta
        moved_any = base_to_tip
        q[i] += step
        total += abs(step)
    return total


@njit(cache=True)
def _anderson(X, G, count, m, x, g, out, dG, dX, A, rhs, gamma):
    """Type-II Anderson mixing of the last ``count`` (x, g = F(x) − x) pairs; result in ``out``.

    Solves the small least-squares problem min ‖g − ΔG γ‖ by a regularised Cholesky factorisation.
    dG, dX (n × m), A (m × m), rhs, gamma (m): work arrays, allocated once per run (allocation inside
    the sweep loop cost more than the arithmetic).
    """
    k = min(count, m)
    n = x.shape[0]
    for c in range(k):
        a = (count - k + c) % (m + 1)
        b = (count - k + c + 1) % (m + 1)
        for i in range(n):
            dG[i, c] = G[b, i] - G[a, i]
            dX[i, c] = X[b, i] - X[a, i]
    trace = _normal_equations(dG, g, k, A, rhs)
    if trace <= 0.0:  # no change in the residuals: nothing to extrapolate
        out[:] = x + g
        return
    for r in range(k):
        A[r, r] += 1e-10 * trace
    _cholesky_solve(A, rhs, gamma, k)
    for i in range(n):
        acc = x[i] + g[i]
        for c in range(k):
            acc -= (dX[i, c] + dG[i, c]) * gamma[c]
        out[i] = acc


@njit(cache=True, inline="always")
def _normal_equations(dG, g, k, A, rhs):
    """A = ΔGᵀΔG, rhs = ΔGᵀg over the first k columns; returns trace(A)."""
    n = g.shape[0]
    trace = 0.0
    for r in range(k):
        rhs[r] = 0.0
        for i in range(n):
            rhs[r] += dG[i, r] * g[i]
        for c in range(r + 1):
            acc = 0.0
            for i in range(n):
                acc += dG[i, r] * dG[i, c]
            A[r, c] = acc
            A[c, r] = acc
        trace += A[r, r]
    return trace


@njit(cache=True, inline="always")
def _cholesky_solve(A, rhs, gamma, k):
    """gamma = A⁻¹ rhs for the symmetric positive definite leading k × k block (A is overwritten)."""
    for j in range(k):
        acc = A[j, j]
        for t in range(j):
            acc -= A[j, t] * A[j, t]
        A[j, j] = np.sqrt(max(acc, 1e-300))
        for r in range(j + 1, k):
            acc = A[r, j]
            for t in range(j):
                acc -= A[r, t] * A[j, t]
            A[r, j] = acc / A[j, j]
    for r in range(k):
        gamma[r] = rhs[r]
        for t in range(r):
            gamma[r] -= A[r, t] * gamma[t]
        gamma[r] /= A[r, r]
    for r in range(k - 1, -1, -1):
        for t in range(r + 1, k):
            gamma[r] -= A[t, r] * gamma[t]
        gamma[r] /= A[r, r]


class _Scratch(NamedTuple):
    """Work arrays of the acceleration step (allocated once per run() call, never inside the sweep loop)."""

    x_old: np.ndarray
    cand: np.ndarray
    g: np.ndarray
    dG: np.ndarray
    dX: np.ndarray
    A: np.ndarray
    rhs: np.ndarray
    gamma: np.ndarray


@njit(cache=True, inline="always")
def _scratch(n, accel_m):
    m = max(accel_m, 1)
    return _Scratch(np.empty(n), np.empty(n), np.empty(n), np.empty((n, m)), np.empty((n, m)), np.empty((m, m)),
                    np.empty(m), np.empty(m))


@njit(cache=True, inline="always")
def _extrapolate(q, ch, pb, st, mem, w, ec, oc, pc, Rc, E1):
    """Record the sweep in the history and try the Anderson extrapolation; keep it only if it lowers E.

    Returns (objective after this step, accepted). When accepted, q and the candidate FK arrays (ec, oc,
    pc, Rc) hold the new state, and the caller swaps them with its own.
    """
    # tuple fields read once into locals: a field read inside a loop costs a reference-count pair
    X, G, state = mem.X, mem.G, mem.state
    x_old, cand, g = w.x_old, w.cand, w.g
    lower, upper, free, kind = pb.lower, pb.upper, pb.free, ch.kind
    n = q.shape[0]
    cnt = int(state[S_HISTORY])
    slot = cnt % (st.accel_m + 1)
    for i in range(n):
        g[i] = q[i] - x_old[i]
        X[slot, i] = x_old[i]
        G[slot, i] = g[i]
    state[S_HISTORY] = cnt + 1.0
    if cnt < 1:
        return E1, False
    _anderson(X, G, cnt, st.accel_m, x_old, g, cand, w.dG, w.dX, w.A, w.rhs, w.gamma)
    finite = True
    for i in range(n):
        finite = finite and np.isfinite(cand[i])
    if not finite:  # a degenerate history: drop it, keep the plain sweep
        state[S_HISTORY] = 0.0
        cand[:] = q
    for i in range(n):
        if kind[i] != CONTINUOUS:
            cand[i] = min(max(cand[i], lower[i]), upper[i])
        if not free[i]:
            cand[i] = q[i]
    chain_fk(ch, cand, ec, oc, pc, Rc)
    Ec = total_objective(cand, kind, pc, Rc, pb)
    if Ec < E1:
        q[:] = cand
        state[S_ACCEPTED] += 1.0
        return Ec, True
    return E1, False


@njit(cache=True, inline="always")
def _fk_converged(q, ch, pb, e, o, p, R, since_fk):
    """Recompute the FK if the state was carried incrementally, then test both tolerances."""
    if since_fk > 0:
        chain_fk(ch, q, e, o, p, R)
    return _within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis)


@njit(cache=True, inline="always")
def _converged_here(q, ch, pb, e, o, p, R, since_fk, state):
    """Both tolerances met at q, on an exact FK (the carried state only says where to look); then the
    objective goes into state[S_E]."""
    if _within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis) and \
            _fk_converged(q, ch, pb, e, o, p, R, since_fk):
        state[S_E] = total_objective(q, ch.kind, p, R, pb)
        return True
    return False


@njit(cache=True, inline="always")
def _finish_due(st, state):
    """The Newton finish is on, not yet tried in this attempt, and the objective at q (the last sweep's, or the
    start's before the first sweep) is below its threshold."""
    now = state[S_E_WINDOW] if state[S_SWEEPS] == 0.0 else state[S_E]
    return st.finish_below > 0.0 and state[S_FINISH] == 0.0 and now < st.finish_below


@njit(cache=True)
def _finished(q, ch, pb, steps, state):
    """The Newton finish, tried once per attempt: True (q converged, its objective in state) if Gauss–Newton
    steps from q meet the tolerances, else q is left exactly as it was and the sweeps go on."""
    q_kept = q.copy()
    code, spent = lm_polish(q, ch, pb, steps)
    state[S_NEWTON] += spent
    if code == CONVERGED:
        state[S_FINISH] = 2.0
        n = q.shape[0]
        e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
        chain_fk(ch, q, e, o, p, R)
        state[S_E] = total_objective(q, ch.kind, p, R, pb)
        return True
    state[S_FINISH] = 1.0
    q[:] = q_kept
    return False


@njit(cache=True, inline="always")
def _window_stalled(state, st, E1):
    """The monitor's window test: True when E fell by less than window_rel over the last window."""
    if state[S_SWEEPS] - state[S_WINDOW_START] >= st.window:
        if state[S_E_WINDOW] - E1 <= st.window_rel * state[S_E_WINDOW]:
            return True
        state[S_E_WINDOW] = E1
        state[S_WINDOW_START] = state[S_SWEEPS]
    return False


@njit(cache=True, inline="always")
def _base_to_tip(order, state):
    """This sweep's direction: the order's, base → tip after a kick; clears the kick flag."""
    forward = order == BASE_TO_TIP or (order == ALTERNATE and int(state[S_SWEEPS]) % 2 == 1) or state[S_KICKED] != 0.0
    state[S_KICKED] = 0.0
    return forward


@njit(cache=True, inline="always")
def _count_sweep(state, trace, E):
    state[S_SWEEPS] += 1.0
    if int(state[S_SWEEPS]) - 1 < trace.shape[0]:
        trace[int(state[S_SWEEPS]) - 1] = E


@njit(cache=True)
def run(q: np.ndarray, ch: Chain, pb: Objective, st: Settings, order: int, max_sweeps: int,
        mem: Memory) -> tuple[int, int]:
    """Sweep until converged, stalled or ``max_sweeps`` sweeps; q is updated in place. Returns (code,
    sweeps in this call); the state slots S_* carry the rest.

    Args:
        q (np.ndarray): start, one number per joint [rad or m]; holds the result on return.
        ch (Chain): the chain.
        pb (Objective): the target, weights, tolerances and windows.
        st (Settings): sweep and monitor settings.
        order (int): TIP_TO_BASE, BASE_TO_TIP or ALTERNATE.
        max_sweeps (int): sweeps allowed in this call.
        mem (Memory): work arrays kept between calls.
    """
    state, trace = mem.state, mem.trace
    lower, upper, free, pstar, Rstar, w_p, w_ax = pb.lower, pb.upper, pb.free, pb.pstar, pb.Rstar, pb.w_p, pb.w_ax
    kind, n = ch.kind, q.shape[0]
    w = _scratch(n, st.accel_m)
    x_old = w.x_old
    e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
    ec, oc, pc, Rc = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
    # fresh: e, o, p, R hold the state at q (carried by the last sweep or an accepted extrapolation);
    # since_fk: sweeps since p, R came from a chain FK (incremental updates carry rounding)
    fresh, since_fk = _resume(mem, e, o, p, R)
    for s in range(max_sweeps):
        if not fresh or since_fk >= REFRESH_SWEEPS:
            chain_fk(ch, q, e, o, p, R)
            since_fk = 0
        if state[S_SWEEPS] == 0.0:
            state[S_E_WINDOW] = total_objective(q, kind, p, R, pb)
        if _converged_here(q, ch, pb, e, o, p, R, since_fk, state):
            return CONVERGED, s
        if _finish_due(st, state) and _finished(q, ch, pb, st.finish_steps, state):
            return CONVERGED, s
        x_old[:] = q
        base_to_tip = _base_to_tip(order, state)
        moved = sweep(q, e, o, kind, lower, upper, free, p, R, pstar, Rstar, w_p, w_ax, st.relax, base_to_tip,
                      pb.q_rest, pb.w_rest)
        fresh = base_to_tip
        since_fk += 1
        E1 = total_objective(q, kind, p, R, pb)
        _count_sweep(state, trace, E1)
        if moved < st.eps_q:
            state[S_E] = E1
            return STALL_STEP, s + 1
        if st.accel_m > 0:
            E1, accepted = _extrapolate(q, ch, pb, st, mem, w, ec, oc, pc, Rc, E1)
            if accepted:
                e, ec = ec, e
                o, oc = oc, o
                p, pc = pc, p
                R, Rc = Rc, R
                fresh = True
                since_fk = 0
        state[S_E] = E1
        if _window_stalled(state, st, E1):
            return STALL_WINDOW, s + 1
    if fresh:
        _hold(mem, e, o, p, R, since_fk)
    return BUDGET, max_sweeps


@functools.cache
def no_rest(n: int) -> np.ndarray:
    """A shared rest configuration for problems whose rest weight is 0 (the kernel never reads it then)."""
    return np.zeros(n)
