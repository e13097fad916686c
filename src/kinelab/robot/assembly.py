"""The kinematics of closed loops: each closure's error and Jacobian, and the assembly — the passive joints moved
until every loop is closed with the actuated joints held (:mod:`kinelab.robot.closures` says what a closure is).

Errors are [m, rad] in ``frame_a``'s axes; Jacobians map a velocity v (nv numbers, Pinocchio's) to the errors' rate.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np
import pinocchio as pin

from kinelab.errors import AssemblyError
from kinelab.robot.closures import ASSEMBLY_TOL, NEWTON_ITERATIONS, RESTARTS, Closure


class Robot(Protocol):
    """What the assembly reads of a robot (:class:`kinelab.robot.tree.Robot`, which imports this module)."""

    name: str
    model: pin.Model
    data: pin.Data
    nv: int
    floating: bool
    closures: tuple[Closure, ...]
    actuated: tuple[str, ...]

    def within_limits(self, q: Any) -> bool:
        """Whether q is within the joint limits."""

    def derived(self, key: str, build: Any) -> Any:
        """Data derived from the robot, built on first use and kept."""

    def random_q(self, rng: np.random.Generator) -> np.ndarray:
        """A configuration drawn within the limits."""

    def difference(self, q0: Any, q1: Any) -> np.ndarray:
        """q1 ⊖ q0 (nv numbers)."""

    def integrate(self, q: Any, v: Any) -> np.ndarray:
        """q ⊕ v."""


def closure_error(model: pin.Model, data: pin.Data, closure: Closure, frames: tuple[int, int]) -> np.ndarray:
    """The held components of ``[aMb.translation; log3(aMb.rotation)]`` at ``data``'s frame placements.

    Args:
        model: Pinocchio's model.
        data: its data, frames placed (``updateFramePlacements``).
        closure: the loop.
        frames: the ids of its ``frame_a`` and ``frame_b``.

    Returns:
        The error [m, rad], one number per held component.
    """
    aMb = data.oMf[frames[0]].actInv(data.oMf[frames[1]])
    if closure.rows[-1] < 3:  # a point loop: its rotation is not held
        return aMb.translation[closure.rows]
    return np.concatenate([aMb.translation, pin.log3(aMb.rotation)])[closure.rows]


def closure_jacobian(model: pin.Model, data: pin.Data, closure: Closure, frames: tuple[int, int]) -> np.ndarray:
    """d(error)/dv: rows × nv, at ``data``'s joint Jacobians (``computeJointJacobians``) and frame placements.

    The linear rows are ``R_aᵀ (J_b − J_a + [p_b − p_a]× ω_a)``, the angular ``Jlog3(R_ab) R_bᵀ (ω_b − ω_a)`` with
    world-aligned frame Jacobians (docs/closures.md derives them).
    """
    oMa, oMb = data.oMf[frames[0]], data.oMf[frames[1]]
    Ja = pin.getFrameJacobian(model, data, frames[0], pin.LOCAL_WORLD_ALIGNED)
    Jb = pin.getFrameJacobian(model, data, frames[1], pin.LOCAL_WORLD_ALIGNED)
    J = np.zeros((6, model.nv))
    rows = closure.rows
    J[:3] = oMa.rotation.T @ (Jb[:3] - Ja[:3] + pin.skew(oMb.translation - oMa.translation) @ Ja[3:])
    if rows[-1] >= 3:  # a loop that holds a rotation (a point loop's rows are all linear)
        R_ab = oMa.rotation.T @ oMb.rotation
        J[3:] = pin.Jlog3(R_ab) @ oMb.rotation.T @ (Jb[3:] - Ja[3:])
    return J[rows]


def frame_ids(model: pin.Model, closures: Sequence[Closure]) -> list[tuple[int, int]]:
    """Each closure's two frame ids."""
    return [(model.getFrameId(c.frame_a), model.getFrameId(c.frame_b)) for c in closures]


def loop_state(model: pin.Model, data: pin.Data, q: np.ndarray, closures: Sequence[Closure],
               jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Every closure's error stacked, and with ``jacobian`` their Jacobian (rows × nv), at q."""
    ids = frame_ids(model, closures)
    if jacobian:
        pin.computeJointJacobians(model, data, q)
    else:
        pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    e = np.concatenate([closure_error(model, data, c, f) for c, f in zip(closures, ids, strict=True)]
                       or [np.zeros(0)])
    if not jacobian:
        return e, None
    J = np.vstack([closure_jacobian(model, data, c, f) for c, f in zip(closures, ids, strict=True)] or
                  [np.zeros((0, model.nv))])
    return e, J


def actuated_indices(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """The declared actuated joints' q indices and v indices (one each: actuated joints have one coordinate)."""
    joints = [robot.model.joints[robot.model.getJointId(a)] for a in robot.actuated]
    return np.array([j.idx_q for j in joints], dtype=int), np.array([j.idx_v for j in joints], dtype=int)


def passive_indices(robot: Robot, actuated: Sequence[str]) -> np.ndarray:
    """The v indices the assembly moves: every joint but the actuated ones and a free-flyer."""
    held = set(actuated)
    idx = [robot.model.joints[j].idx_v + k for j in range(1, robot.model.njoints)
           for k in range(robot.model.joints[j].nv)
           if robot.model.names[j] not in held and not (robot.floating and j == 1)]
    return np.array(idx, dtype=int)


def assemble(robot: Robot, q: np.ndarray, actuated: Sequence[str], tol: float = ASSEMBLY_TOL) -> np.ndarray:
    """q with its passive joints moved so that every loop closes (≤ ``tol``), the actuated joints and a free-flyer
    held: Levenberg–Marquardt from q (usually the assembly nearest the start), then from seeded random passive values.

    Raises:
        AssemblyError: no assembly within the joint limits was found; the smallest residual reached is named.
    """
    passive = passive_indices(robot, actuated)
    best = np.inf
    rng = np.random.default_rng(0)
    start = q.copy()
    for _ in range(RESTARTS + 1):
        found, residual = newton(robot, start, passive, tol)
        if residual <= tol and robot.within_limits(found):
            return found
        best = min(best, residual)
        start = _random_passive(robot, q, passive, rng)
    raise AssemblyError(f"{robot.name}: no assembly closes every loop with the actuated joints "
                        f"({', '.join(actuated) or 'none'}) held within the limits: the closest reached leaves "
                        f"{best:.3g} m/rad open ({RESTARTS + 1} starts)", best)


def newton(robot: Robot, q: np.ndarray, passive: np.ndarray, tol: float) -> tuple[np.ndarray, float]:
    """Levenberg–Marquardt on the passive joints (damping μ = |e|², Fan and Yuan's: Gauss–Newton's quadratic
    convergence near a closed loop, steady steps far from one), a halving line search: (q reached, its largest
    error)."""
    model, data = robot.model, robot.data
    e, _ = loop_state(model, data, q, robot.closures, jacobian=False)
    if np.max(np.abs(e), initial=0.0) <= tol * 1e-2:  # closed already (every step's start): no Jacobian to build
        return q, float(np.max(np.abs(e), initial=0.0))
    e, J = loop_state(model, data, q, robot.closures)
    norm, slow, free = float(np.linalg.norm(e)), 0, passive
    bounds = robot.derived(f"passive bounds {passive.tobytes().hex()}", lambda r: _scalar_bounds(r.model, passive))
    for _ in range(NEWTON_ITERATIONS):
        if np.max(np.abs(e), initial=0.0) <= tol * 1e-2 or J is None or free.size == 0:
            break
        Jp = J[:, free]
        dx = np.linalg.solve(Jp.T @ Jp + (norm * norm + 1e-14) * np.eye(free.size), -Jp.T @ e)
        dv = np.zeros(model.nv)
        for alpha in (1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125):
            dv[free] = alpha * dx
            trial, clamped = _clamped(bounds, pin.integrate(model, q, dv))
            e_trial, _ = loop_state(model, data, trial, robot.closures, jacobian=False)
            if np.linalg.norm(e_trial) < norm:
                break
        else:
            break
        q, free = trial, np.setdiff1d(free, clamped)
        e, J = loop_state(model, data, q, robot.closures)
        slow = slow + 1 if np.linalg.norm(e) > 0.99 * norm else 0
        norm = float(np.linalg.norm(e))
        if slow >= 3:  # a gap that no longer shrinks: a local least-squares minimum, not a closing loop
            break
    return q, float(np.max(np.abs(e), initial=0.0))


def _scalar_bounds(model: pin.Model, passive: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The passive joints with one coordinate and finite limits: (their v indices, q indices, lower, upper)."""
    moving = set(passive.tolist())
    pairs = [(model.joints[j].idx_v, model.joints[j].idx_q) for j in range(1, model.njoints)
             if model.joints[j].nq == model.joints[j].nv == 1 and model.joints[j].idx_v in moving
             and np.isfinite(model.lowerPositionLimit[model.joints[j].idx_q])
             and np.isfinite(model.upperPositionLimit[model.joints[j].idx_q])]
    iv = np.array([p[0] for p in pairs], dtype=int)
    iq = np.array([p[1] for p in pairs], dtype=int)
    return iv, iq, model.lowerPositionLimit[iq], model.upperPositionLimit[iq]


def _clamped(bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
             q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """q with its bounded passive coordinates put back into their limits, and the v indices that were put back
    (held at their limit from there on: the other passive joints close the loop, as the real mechanism's stop)."""
    iv, iq, lower, upper = bounds
    clipped = np.clip(q[iq], lower, upper)
    moved = clipped != q[iq]
    q = q.copy()
    q[iq] = clipped
    return q, iv[moved]


def _random_passive(robot: Robot, q: np.ndarray, passive: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """q with its passive joints drawn at random within their limits (a restart)."""
    other = robot.random_q(rng)
    dv = robot.difference(q, other)
    mask = np.zeros(robot.nv)
    mask[passive] = 1.0
    return robot.integrate(q, dv * mask)
