"""Kinematics of a chain written with biquaternions (Chelnokov): Λ(q) and A(q).

Λ(q) = Λ_1(q_1)∘…∘Λ_n(q_n)∘Λ_tool, with Λ_i(q_i) = Λ(placement_i)∘Λ(joint motion q_i): only the
constant joint placements and axes are read from the Chain's model, the products are our own.

A(q) maps q̇ to U = ω + s v, the end link's angular velocity and the velocity of its origin, both in
its own axes (2Λ̇ = Λ∘U). Column i is the joint's unit screw carried to the tool frame,
U_i = Λ̄_(i→tool)∘S_i∘Λ_(i→tool), with S_i = a_i (revolute) or s a_i (prismatic), a_i the local axis.
Rows: angular (ω) then linear (v), the paper's order, i.e. Pinocchio's LOCAL Jacobian with its two
row blocks swapped.
"""

from __future__ import annotations

import numpy as np

from kinelab.dq.algebra import DualQuat, qconj, qmul
from kinelab.robot import Chain


def _joint_motion(kind: str, axis: np.ndarray, value: float) -> DualQuat:
    if kind == "prismatic":
        return DualQuat(np.array([1.0, 0, 0, 0]), np.r_[0.0, 0.5 * value * axis])
    half = 0.5 * value
    return DualQuat(np.r_[np.cos(half), np.sin(half) * axis], np.zeros(4))


def _build_constants(robot: Chain) -> tuple[list[DualQuat], DualQuat]:
    model = robot.model
    placements = [DualQuat.from_se3(model.jointPlacements[j]) for j in range(1, model.njoints)]
    return placements, DualQuat.from_se3(model.frames[robot.tool_frame_id].placement)


def _constants(robot: Chain) -> tuple[list[DualQuat], DualQuat]:
    """The joint placements and the tool placement as biquaternions, computed once per Chain."""
    return robot.derived("biquaternion_constants", _build_constants)


def tool_in_last_joint(robot: Chain) -> DualQuat:
    """The constant tool placement in the last joint's frame, as a unit biquaternion."""
    return _constants(robot)[1]


def chain(robot: Chain, q) -> list[DualQuat]:
    """Λ_0i for i = 1..n (joint frames after their motion, base frame) and, last, Λ of the tool."""
    q = robot.check_q(q)
    out, acc = [], DualQuat.identity()
    placements, tool = _constants(robot)
    for placement, joint, value in zip(placements, robot.joints, q, strict=True):
        acc = acc * placement * _joint_motion(joint.kind, np.array(joint.axis_local), value)
        out.append(acc)
    out.append(acc * tool)
    return out


def pose(robot: Chain, q) -> DualQuat:
    """Λ(q): the tool's biquaternion in the base frame."""
    return chain(robot, q)[-1]


def screw_transform(screw: tuple[np.ndarray, np.ndarray], lam: DualQuat) -> tuple[np.ndarray, np.ndarray]:
    """Λ̄∘S∘Λ for a dual vector S = a + s a0: the same screw in the frame Λ leads to."""
    S_real, S_dual = np.r_[0.0, screw[0]], np.r_[0.0, screw[1]]
    lr, ld = lam.real_wxyz, lam.dual_wxyz
    cr, cd = qconj(lr), qconj(ld)
    real = qmul(qmul(cr, S_real), lr)
    dual = qmul(qmul(cr, S_real), ld) + qmul(qmul(cr, S_dual), lr) + qmul(qmul(cd, S_real), lr)
    return real[1:], dual[1:]


def a_matrix(robot: Chain, q) -> np.ndarray:
    """A(q), 6 × n: (ω; v) of the end link in its own axes per unit joint rate (the paper's eq. 8)."""
    frames = chain(robot, q)
    tool = frames[-1]
    A = np.empty((6, robot.n))
    for i, joint in enumerate(robot.joints):
        axis = np.array(joint.axis_local)
        screw = (np.zeros(3), axis) if joint.kind == "prismatic" else (axis, np.zeros(3))
        to_tool = frames[i].conj() * tool  # Λ_(i→tool)
        w, v = screw_transform(screw, to_tool)
        A[:3, i], A[3:, i] = w, v
    return A
