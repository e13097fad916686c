"""FRDM written plainly: the vector model from Pinocchio's Jacobian, the exact steps, one sweep.

This is the readable statement of the method (methods.md §1.2–1.5) and the reference the compiled
kernel is tested against. It is slow on purpose: FK and the vector model come from Pinocchio at every
joint, nothing is cached.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from kinelab.robot import Chain


def vector_model(robot: Chain, q) -> dict[str, np.ndarray]:
    """Axes e_i, points o_i (base frame) from Pinocchio's WORLD joint Jacobians, tool point p and axes R.

    A revolute column is (v, ω) with v = o × ω, so e = ω and o = ω × v (the foot of the perpendicular
    from the base origin); a prismatic column is (v, 0), e = v.
    """
    model, data = robot.model, robot.data
    q_pin = robot.to_pin_q(q)
    pin.computeJointJacobians(model, data, q_pin)
    pin.updateFramePlacements(model, data)
    e, o = np.zeros((robot.n, 3)), np.zeros((robot.n, 3))
    for i, joint in enumerate(robot.joints):
        col = pin.getJointJacobian(model, data, i + 1, pin.WORLD)[:, joint.idx_v]
        v, w = col[:3], col[3:]
        if joint.kind == "prismatic":
            e[i], o[i] = v, data.oMi[i + 1].translation
        else:
            e[i], o[i] = w, np.cross(w, v)
    oMtool = data.oMf[robot.tool_frame_id]
    return {"e": e, "o": o, "p": oMtool.translation.copy(), "R": oMtool.rotation.copy()}


def objective(p, R, pstar, Rstar, w_p, w_ax) -> float:
    """E = w_p ‖p − p*‖² + Σ_j w_j ‖u_j − u*_j‖²."""
    return float(w_p * np.sum((p - pstar) ** 2) + sum(w_ax[j] * np.sum((R[:, j] - Rstar[:, j]) ** 2) for j in range(3)))


def revolute_step(e, o, p, R, pstar, Rstar, w_p, w_ax, window=(-np.inf, np.inf)) -> float:
    """The angle [rad] about the line (e, o) minimising E, within ``window`` ∋ 0 (methods.md §1.3, §1.5)."""
    def perp(x):
        return x - e * (e @ x)

    r, d = p - o, pstar - o
    B = w_p * perp(d) @ perp(r) + sum(w_ax[j] * perp(Rstar[:, j]) @ perp(R[:, j]) for j in range(3))
    C = e @ (w_p * np.cross(r, d) + sum(w_ax[j] * np.cross(R[:, j], Rstar[:, j]) for j in range(3)))
    if B == 0 and C == 0:
        return 0.0
    return _within_window(np.arctan2(C, B), window)


def _within_window(best: float, window: tuple[float, float]) -> float:
    """The copy of the angle ``best`` [rad] (modulo 2π) inside ``window`` nearest 0, or the window's edge where E
    is least when no copy is inside (E is a cosine in the angle)."""
    lo, hi = window
    if np.isinf(lo) and np.isinf(hi):
        return best
    inside = [t for t in (best - 2 * np.pi, best, best + 2 * np.pi) if lo <= t <= hi]
    if inside:
        return min(inside, key=abs)
    return lo if np.cos(lo - best) >= np.cos(hi - best) else hi


def prismatic_step(e, p, pstar, w_p, window=(-np.inf, np.inf)) -> float:
    """The displacement [m] along e minimising E: the projection of the position error, clipped."""
    s = float(e @ (pstar - p)) if w_p > 0 else 0.0
    return float(np.clip(s, *window))


def sweep(robot: Chain, q, oMtarget: pin.SE3, w_p: float, w_ax=(1.0, 1.0, 1.0), base_to_tip: bool = True):
    """One FRDM sweep, re-reading the vector model from Pinocchio after every joint step. Returns q."""
    q = np.array(q, dtype=float)
    order = range(robot.n) if base_to_tip else reversed(range(robot.n))
    for i in order:
        vm = vector_model(robot, q)
        joint = robot.joints[i]
        window = (joint.lower - q[i], joint.upper - q[i]) if joint.kind != "continuous" else (-np.inf, np.inf)
        if joint.kind == "prismatic":
            step = prismatic_step(vm["e"][i], vm["p"], oMtarget.translation, w_p, window)
        else:
            step = revolute_step(vm["e"][i], vm["o"][i], vm["p"], vm["R"], oMtarget.translation,
                                 oMtarget.rotation, w_p, w_ax, window)
        q[i] += step
    return q
