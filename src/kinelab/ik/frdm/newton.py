"""Damped Gauss–Newton (Levenberg–Marquardt) steps on the world-frame error: FRDM's finish.

FRDM's sweeps are coordinate descent and converge linearly; near the answer Gauss–Newton steps with the
analytic Jacobian converge quadratically. :func:`lm_polish` is called by the kernel's Newton finish
(``FRDMOptions.finish="newton"``, once the objective falls below ``finish_below``), by the multistart on a
stalled attempt (``stall_polish``) and by the compiled path follower for a sample still short.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.chain import PRISMATIC, chain_fk, rotation_angle

CONVERGED = 0  # kernel.CONVERGED (the kernel imports this module)


@njit(cache=True, inline="always")
def within(p, R, pstar, Rstar, tol_pos, tol_rot, check_pos, check_rot, rot_axis):
    """Both tolerances met (those checked): position [m] and rotation angle [rad] (of R*ᵀR, or with
    ``rot_axis`` ≥ 0 between that tool axis and the target's)."""
    dp = np.sqrt((p[0] - pstar[0]) ** 2 + (p[1] - pstar[1]) ** 2 + (p[2] - pstar[2]) ** 2)
    if check_pos and not dp <= tol_pos:
        return False
    if not check_rot:
        return True
    if rot_axis < 0:
        return rotation_angle(R, Rstar) <= tol_rot
    k = rot_axis
    c0 = R[1, k] * Rstar[2, k] - R[2, k] * Rstar[1, k]
    c1 = R[2, k] * Rstar[0, k] - R[0, k] * Rstar[2, k]
    c2 = R[0, k] * Rstar[1, k] - R[1, k] * Rstar[0, k]
    dot = R[0, k] * Rstar[0, k] + R[1, k] * Rstar[1, k] + R[2, k] * Rstar[2, k]
    return np.arctan2(np.sqrt(c0 * c0 + c1 * c1 + c2 * c2), dot) <= tol_rot


@njit(cache=True)
def lm_polish(q, ch, pb, iterations, max_step=np.inf):
    """Levenberg–Marquardt on the world-frame error of the constrained components, steps kept in the windows:
    [p* − p; log(R* Rᵀ)], or for task "axis" [p* − p; a* − a] with a the tool axis (da/dq_i = e_i × a).
    ``max_step`` [rad or m] caps every step's largest joint change (a trust region: near a singular
    configuration a Gauss–Newton step can throw the arm onto another branch).

    Returns (CONVERGED or −1, iterations spent); q is updated in place.
    """
    n = q.shape[0]
    e, o, p, R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
    J = np.empty((6, n))
    err = np.empty(6)
    for it in range(iterations):
        chain_fk(ch, q, e, o, p, R)
        if within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis):
            return CONVERGED, it
        world_error(p, R, pb, err)
        world_jacobian(e, o, p, R, ch.kind, pb, J)
        A = J.T @ J
        damping = 1e-9 + 1e-3 * (err @ err)
        for i in range(n):
            A[i, i] += damping
        dq = np.linalg.solve(A, J.T @ err)
        if max_step < np.inf:
            largest = np.max(np.abs(dq))
            if largest > max_step:
                dq *= max_step / largest
        for i in range(n):
            q[i] = min(max(q[i] + dq[i], pb.lower[i]), pb.upper[i])
    chain_fk(ch, q, e, o, p, R)
    if within(p, R, pb.pstar, pb.Rstar, pb.tol_pos, pb.tol_rot, pb.check_pos, pb.check_rot, pb.rot_axis):
        return CONVERGED, iterations
    return -1, iterations


@njit(cache=True)
def world_jacobian(e, o, p, R, kind, pb, J):
    """J ← the error's Jacobian rows (position; rotation, or the tool axis of task "axis"); unchecked rows 0, and
    the columns of frozen joints (``pb.free`` False) 0: a step never moves a joint a bypass holds."""
    for i in range(e.shape[0]):
        if not pb.free[i]:
            J[:, i] = 0.0
        elif kind[i] == PRISMATIC:
            J[0:3, i] = e[i]
            J[3:6, i] = 0.0
        else:
            J[0:3, i] = np.cross(e[i], p - o[i])
            J[3:6, i] = e[i] if pb.rot_axis < 0 else np.cross(e[i], R[:, pb.rot_axis])
        if not pb.check_pos:
            J[0:3, i] = 0.0
        if not pb.check_rot:
            J[3:6, i] = 0.0


@njit(cache=True)
def world_error(p, R, pb, err):
    """err = [p* − p; log(R* Rᵀ) or a* − a] with the constrained components only (an unchecked component
    must not pull)."""
    for k in range(3):
        err[k] = pb.pstar[k] - p[k] if pb.check_pos else 0.0
    if pb.rot_axis >= 0:
        for k in range(3):
            err[3 + k] = pb.Rstar[k, pb.rot_axis] - R[k, pb.rot_axis] if pb.check_rot else 0.0
        return
    M = pb.Rstar @ R.T
    cos_a = min(1.0, max(-1.0, (M[0, 0] + M[1, 1] + M[2, 2] - 1.0) / 2.0))
    angle = np.arccos(cos_a)
    scale = 0.5 if angle < 1e-8 else angle / (2.0 * np.sin(angle))
    w = (M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1])
    for k in range(3):
        err[3 + k] = scale * w[k] if pb.check_rot else 0.0
