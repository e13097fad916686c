"""The compiled path follower: every sample of a path solved inside one kernel call, warm-started from
the sample before (FRDM's direct-control use, Danilov 2019).

Each sample runs in two phases. The first minimises E plus a rest term pulling towards the previous
sample's answer (``w_rest`` Σ 2(1 − cos Δq)): among the configurations that reach the target it
prefers the nearest one, which on a redundant arm keeps the self-motion from drifting into a joint
limit or a branch jump. The second, run only when the first has not met the tolerances, is plain
FRDM from where the first stopped, so the rest term never costs accuracy. Near a singular point FRDM
crawls (its rate tends to 1); with ``lm_iterations`` > 0 a sample it leaves short of the tolerances
gets damped Gauss–Newton steps (Levenberg–Marquardt): not an FRDM step, so the follower reports that
mode under its own name.

With the Newton finish on (the default FRDM mode), a sample none of this meets is recovered, so that a
smooth path loses no sample: first by continuation — the step from the last reached target to this one is
cut into 2, 4, then 8 sub-steps (points along the segment, rotations along the geodesic), each solved
from the answer before, which keeps the arm on its branch — and only then by seeded restarts within ±0.1,
±0.3 and ±1 rad (or m) of the last reached configuration. Every sample starts from the last reached
configuration: a sample that fails leaves no stray configuration for the next one to start from. With
``finish="none"`` (the paper's FRDM) the follower is the plain one: no recovery.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from kinelab.ik.chain import chain_fk, rotation_angle, rotm, xorshift_uniform
from kinelab.ik.frdm.kernel import CONVERGED, STATE_SIZE, Memory, Objective, Settings, run
from kinelab.ik.frdm.newton import lm_polish, within, world_error, world_jacobian

# the Gauss–Newton steps of a sample move no joint by more than TRUST_FLOOR + TRUST_FACTOR × the last sample's
# largest joint step [rad or m]: a smooth path's answer lies about that far from the last one
TRUST_FLOOR = 0.02
TRUST_FACTOR = 2.0


class Follow(NamedTuple):
    """A path's solve settings, the same for every sample (see :func:`follow`'s inputs)."""

    st: Settings
    order: int
    max_sweeps: int
    w_rest: float
    rest_sweeps: int
    centre: np.ndarray
    pull: float
    lm_iterations: int


@njit(cache=True)
def follow(Q, q0, ch, lower, upper, free, pstars, Rstars, w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
           st, order, max_sweeps, w_rest, rest_sweeps, centre, pull, lm_iterations, rng_state, codes, sweeps):
    """Solve sample k of the path (pstars[k], Rstars[k]) from the answer to sample k − 1 (q0 for the first).

    Inputs, in order:
        Q (np.ndarray): (N, n) output, one configuration per sample [rad or m].
        q0 (np.ndarray): (n,) configuration before the first sample.
        ch (Chain): the chain.
        lower, upper, free (np.ndarray): joint windows and free mask, shared by every sample.
        pstars (np.ndarray): (N, 3) target points [m]; Rstars: (N, 3, 3) target rotations (base frame).
        w_p (float), w_ax (np.ndarray): objective weights; tol_pos [m], tol_rot [rad], check_pos, check_rot.
        st (Settings), order (int): sweep settings and order code (st.finish_below > 0: recovery on).
        max_sweeps (int): sweep cap of each phase.
        w_rest (float): weight of the rest term in the first phase (0: one plain phase).
        rest_sweeps (int): sweep cap of the first phase.
        centre (np.ndarray), pull (float): the rest configuration is q_prev + s (centre − q_prev), s = pull times
            the joint's limit measure (see :func:`_limit_pull`).
        lm_iterations (int): Levenberg–Marquardt steps after FRDM for a sample still short (0: none).
        rng_state (np.ndarray): (1,) uint64 state of the recovery's restarts.
        codes, sweeps (np.ndarray): (N,) outputs: run() code and sweeps spent per sample.
    """
    n = q0.shape[0]
    mem = Memory(np.zeros((st.accel_m + 1, n)), np.zeros((st.accel_m + 1, n)), np.zeros(STATE_SIZE), np.zeros(0),
                 np.zeros((2 * n + 4, 3)))
    pb = Objective(lower, upper, free, pstars[0], Rstars[0], w_p, w_ax, tol_pos, tol_rot, check_pos, check_rot,
                   q0, 0.0, -1)
    recover = st.finish_below > 0.0
    fw = Follow(st, order, max_sweeps, w_rest, rest_sweeps, centre, pull, lm_iterations)
    q = q0.copy()
    q_good = q0.copy()  # the last reached configuration: every sample starts here
    rest = q0.copy()
    e, o = np.empty((n, 3)), np.empty((n, 3))
    p_good, R_good = np.empty(3), np.empty((3, 3))  # the last reached tool pose
    chain_fk(ch, q0, e, o, p_good, R_good)
    trust = TRUST_FLOOR
    velocity = np.zeros(n)  # the last reached sample's joint step: the predictor's
    for k in range(Q.shape[0]):
        if recover:
            code, spent = _tracked(q, q_good, p_good, R_good, velocity, ch, pb, fw, trust, pstars[k], Rstars[k], rest,
                                   mem, rng_state)
        else:
            code, spent = _sample(q, ch, pb, fw, trust, pstars[k], Rstars[k], rest, mem)
        velocity[:] = 0.0
        if code == CONVERGED:
            velocity[:] = q - q_good
            trust = TRUST_FLOOR + TRUST_FACTOR * np.max(np.abs(velocity))
            q_good[:] = q
            p_good[:] = pstars[k]
            R_good[:] = Rstars[k]
        Q[k] = q
        codes[k] = code
        sweeps[k] = spent


@njit(cache=True)
def redundant_newton(q, ch, pb, iterations, max_step, centre, pull):
    """Damped Gauss–Newton steps in their minimum-norm form, dq = Jᵀ(JJᵀ + λI)⁻¹ err, the first plus the
    projection onto the task's null space of a pull towards mid-range (each joint's share from
    :func:`_limit_pull`): a redundant arm's self-motion turns away from its limits instead of drifting into
    one. Steps capped at
    ``max_step`` [rad or m]. Returns (CONVERGED or −1, steps); q is updated in place."""
    n = q.shape[0]
    e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
    J, err, z = np.empty((6, n)), np.empty(6), np.empty(n)
    for it in range(iterations + 1):
        chain_fk(ch, q, e, o, p, R)
        if within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis):
            return CONVERGED, it
        if it == iterations:
            break
        world_error(p, R, pb, err)
        world_jacobian(e, o, p, R, ch.kind, pb, J)
        A = J @ J.T
        damping = 1e-9 + 1e-3 * (err @ err)
        for r in range(6):
            A[r, r] += damping
        for i in range(n):  # the pull acts on the first step only: the later ones converge as Gauss–Newton does
            z[i] = _limit_pull(q[i], pb.lower[i], pb.upper[i], pull) * (centre[i] - q[i]) \
                if it == 0 and pb.free[i] else 0.0
        dq = J.T @ np.linalg.solve(A, err) + z - J.T @ np.linalg.solve(A, J @ z)
        largest = np.max(np.abs(dq))
        if largest > max_step:
            dq *= max_step / largest
        for i in range(n):
            q[i] = min(max(q[i] + dq[i], pb.lower[i]), pb.upper[i])
    return -1, iterations


@njit(cache=True)
def _tracked(q, q_good, p_good, R_good, velocity, ch, pb, fw, trust, pstar, Rstar, rest, mem, rng_state):
    """One sample with the Newton finish on: the predictor, then the sample's phases from the last reached
    configuration, then the recovery; a sample none of them reaches keeps the phases' answer, the nearest to the
    last reached one. Returns (code, sweeps and steps); q holds the answer."""
    code, spent = _predicted(q, q_good, velocity, ch, pb, fw, trust, pstar, Rstar)
    if code == CONVERGED:
        return code, spent
    q[:] = q_good
    code, more = _sample(q, ch, pb, fw, trust, pstar, Rstar, rest, mem)
    spent += more
    if code == CONVERGED:
        return code, spent
    first = q.copy()
    code, more = _recover(q, q_good, p_good, R_good, ch, pb, fw, trust, pstar, Rstar, rest, mem, rng_state)
    if code != CONVERGED:
        q[:] = first
    return code, spent + more


@njit(cache=True)
def _predicted(q, q_good, velocity, ch, pb, fw, trust, pstar, Rstar):
    """Gauss–Newton steps from the predictor q_good + velocity (clipped to the limits): through a singular
    point, where two branches meet, the path's own joint velocity carries the arm on along its branch. A
    redundant arm (a rest weight > 0) starts from q_good instead: its velocity holds self-motion that the
    predictor would carry on for ever. Returns (code, steps); q holds the answer."""
    carry = 0.0 if fw.w_rest > 0.0 else 1.0
    for i in range(q.shape[0]):
        q[i] = min(max(q_good[i] + carry * velocity[i], pb.lower[i]), pb.upper[i])
    aim = Objective(pb.lower, pb.upper, pb.free, pstar, Rstar, pb.w_p, pb.w_ax, pb.tol_pos, pb.tol_rot,
                    pb.check_pos, pb.check_rot, q_good, 0.0, -1)
    if fw.w_rest > 0.0:
        return redundant_newton(q, ch, aim, 2 * fw.st.finish_steps, trust, fw.centre, fw.pull)
    return lm_polish(q, ch, aim, 2 * fw.st.finish_steps, trust)


@njit(cache=True)
def _sample(q, ch, pb, fw, trust, pstar, Rstar, rest, mem):
    """One sample from q (in place): with the Newton finish on, Gauss–Newton steps from q first (continuation:
    their minimum-norm steps keep the branch); then the rest phase, the plain phase, the polish. Returns (code,
    sweeps)."""
    n = q.shape[0]
    q_prev = q.copy()
    spent = 0
    code = -1
    plain = Objective(pb.lower, pb.upper, pb.free, pstar, Rstar, pb.w_p, pb.w_ax, pb.tol_pos, pb.tol_rot,
                      pb.check_pos, pb.check_rot, q_prev, 0.0, -1)
    if fw.st.finish_below > 0.0:
        code, spent = lm_polish(q, ch, plain, 2 * fw.st.finish_steps, trust)
        if code == CONVERGED:
            return code, spent
        q[:] = q_prev
    if fw.w_rest > 0.0:
        for i in range(n):
            rest[i] = q_prev[i] + _limit_pull(q_prev[i], pb.lower[i], pb.upper[i], fw.pull) * (fw.centre[i] - q_prev[i])
        rested = Objective(pb.lower, pb.upper, pb.free, pstar, Rstar, pb.w_p, pb.w_ax, pb.tol_pos, pb.tol_rot,
                           pb.check_pos, pb.check_rot, rest, fw.w_rest, -1)
        mem.state[:] = 0.0
        code, more = run(q, ch, rested, fw.st, fw.order, fw.rest_sweeps, mem)
        spent += more
    if code != CONVERGED:
        mem.state[:] = 0.0
        code, more = run(q, ch, plain, fw.st, fw.order, fw.max_sweeps, mem)
        spent += more
    if code != CONVERGED and fw.lm_iterations > 0:
        code, more = lm_polish(q, ch, plain, fw.lm_iterations)
        spent += more
    return code, spent


@njit(cache=True)
def _recover(q, q_good, p_good, R_good, ch, pb, fw, trust, pstar, Rstar, rest, mem, rng_state):
    """A sample the plain follower missed: sub-steps from the last reached pose, then restarts about the last
    reached configuration (see the module's docstring). Returns (code, sweeps); q holds the answer."""
    spent = 0
    p_mid, R_mid = np.empty(3), np.empty((3, 3))
    for cuts in (2, 4, 8):
        q[:] = q_good
        code = CONVERGED
        for j in range(1, cuts + 1):
            pose_between(p_good, R_good, pstar, Rstar, j / cuts, p_mid, R_mid)
            code, more = _sample(q, ch, pb, fw, trust, p_mid, R_mid, rest, mem)
            spent += more
            if code != CONVERGED:
                break
        if code == CONVERGED:
            return code, spent
    for radius in (0.1, 0.3, 1.0):
        for _ in range(4):
            for i in range(q.shape[0]):
                lo, hi = max(pb.lower[i], q_good[i] - radius), min(pb.upper[i], q_good[i] + radius)
                q[i] = lo + (hi - lo) * xorshift_uniform(rng_state)
            code, more = _sample(q, ch, pb, fw, trust, pstar, Rstar, rest, mem)
            spent += more
            if code == CONVERGED:
                return code, spent
    return code, spent


@njit(cache=True)
def pose_between(p0, R0, p1, R1, s, p_out, R_out):
    """The pose a share s ∈ [0, 1] of the way from (p0, R0) to (p1, R1): the point along the segment, the
    rotation R0 exp(s log(R0ᵀ R1)) (the shorter way round)."""
    for i in range(3):
        p_out[i] = p0[i] + s * (p1[i] - p0[i])
    M = R0.T @ R1
    angle = rotation_angle(R1, R0)
    x, y, z = M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]
    norm = np.sqrt(x * x + y * y + z * z)
    if angle < 1e-12 or norm < 1e-300:
        R_out[:, :] = R0  # no turn (or a half turn, whose axis the skew part loses: the end pose's rotation)
        if s >= 0.5:
            R_out[:, :] = R1
        return
    m = rotm(x / norm, y / norm, z / norm, s * angle)
    for r in range(3):
        for c in range(3):
            R_out[r, c] = R0[r, 0] * m[c] + R0[r, 1] * m[3 + c] + R0[r, 2] * m[6 + c]


@njit(cache=True)
def _limit_pull(x, lo, hi, pull):
    """The share of the way to mid-range the rest configuration takes for a joint at x: ``pull`` times the
    Chan–Dubey measure (hi − lo)² / (4 (x − lo)(hi − x)), 1 at mid-range and growing without bound at a
    limit, capped at 1/2: a joint in mid-range is left where it is, one near a limit is drawn back."""
    dl, du = x - lo, hi - x
    if not (dl > 0.0 and du > 0.0) or dl + du == np.inf:
        return pull if dl + du != np.inf else 0.0
    return min(0.5, pull * (dl + du) * (dl + du) / (4.0 * dl * du))
