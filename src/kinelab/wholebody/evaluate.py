"""Each task's error and rate matrix at a configuration, from one Pinocchio pass (``computeJointJacobians``).

A task gives ``(A, e)``: its error e (m, rad) and A with ``de/dt = A v`` to first order (v: nv velocities). A frame's
pose error is its position's and its rotation's, apart: the frame origin's offset from the target's in world axes
[m], and Pinocchio's logarithm of the rotation between them, in the frame's axes (``log3``), with the Jacobian of the
logarithm (``Jlog3``) in A; an axis error is the difference of the two unit axes. A relative pose's error is the same
in the root frame's axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import ConfigurationError, JointNotFoundError, OptionError
from kinelab.robot.tree import Robot
from kinelab.wholebody.tasks import ComTask, CouplingTask, FrameTask, PostureTask, RelativeFrameTask, Task

LOCAL = pin.ReferenceFrame.LOCAL


@dataclass
class Rows:
    """The weighted rows of one priority level: ``A v ≈ b`` with b = −gain·e/dt, each row's weight ``w``, and the
    posture's diagonal part (``diag``: the weight per velocity, ``target``: its b)."""

    A: list[np.ndarray]
    b: list[np.ndarray]
    w: list[np.ndarray]
    diag: np.ndarray
    target: np.ndarray


def skew(a: np.ndarray) -> np.ndarray:
    """The 3 × 3 matrix of a × (·)."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def forward(robot: Robot, q: np.ndarray, com: bool) -> None:
    """Pinocchio's pass at q: joint placements and Jacobians, frame placements, and with ``com`` the centre of mass
    and its Jacobian (in ``robot.data``)."""
    pin.computeJointJacobians(robot.model, robot.data, q)
    pin.updateFramePlacements(robot.model, robot.data)
    if com:
        pin.jacobianCenterOfMass(robot.model, robot.data, False)


Rowset = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]  # A, e, the rows' weights, a pose's gap


def frame_rows(robot: Robot, task: FrameTask) -> Rowset:
    """(A, e, per-row weight, the translation gap of a pose [m]) of a frame task at ``robot.data``'s configuration."""
    fid = robot.frame_id(task.frame)
    oMf = robot.data.oMf[fid]
    J = pin.getFrameJacobian(robot.model, robot.data, fid, LOCAL)
    wp, wo = task.weight, task.orientation_weight
    if task.task == "pose":
        E_R = oMf.rotation.T @ task.target.rotation
        A = np.vstack([oMf.rotation @ J[:3], -pin.Jlog3(E_R.T) @ J[3:]])
        e = np.concatenate([oMf.translation - task.target.translation, pin.log3(E_R)])
        return A, e, np.array([wp, wp, wp, wo, wo, wo]), None
    if task.task == "position":
        return oMf.rotation @ J[:3], oMf.translation - task.target.translation, np.full(3, wp), None
    if task.task == "orientation":
        E_R = oMf.rotation.T @ task.target.rotation
        return -pin.Jlog3(E_R.T) @ J[3:], pin.log3(E_R), np.full(3, wo), None
    k = "xyz".index(task.axis)
    a, t = oMf.rotation[:, k], task.target.rotation[:, k]
    A = np.vstack([oMf.rotation @ J[:3], -skew(a) @ oMf.rotation @ J[3:]])
    e = np.concatenate([oMf.translation - task.target.translation, a - t])
    return A, e, np.array([wp, wp, wp, wo, wo, wo]), None


def relative_rows(robot: Robot, task: RelativeFrameTask) -> Rowset:
    """(A, e, per-row weight) of a relative frame task: the frame's body velocity less the root's, in the frame."""
    fid, rid = robot.frame_id(task.frame), robot.frame_id(task.root)
    oMf, oMr = robot.data.oMf[fid], robot.data.oMf[rid]
    Jf = pin.getFrameJacobian(robot.model, robot.data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    Jr = pin.getFrameJacobian(robot.model, robot.data, rid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    Rr, Rf = oMr.rotation, oMf.rotation
    gap = oMf.translation - oMr.translation
    E_R = Rf.T @ Rr @ task.target.rotation
    A = np.vstack([Rr.T @ (Jf[:3] - Jr[:3] + skew(gap) @ Jr[3:]), -pin.Jlog3(E_R.T) @ Rf.T @ (Jf[3:] - Jr[3:])])
    e = np.concatenate([Rr.T @ gap - task.target.translation, pin.log3(E_R)])
    wp, wo = task.weight, task.orientation_weight
    return A, e, np.array([wp, wp, wp, wo, wo, wo]), None


def com_rows(robot: Robot, task: ComTask) -> Rowset:
    """(A, e, per-row weight, None) of the centre-of-mass task (``forward`` ran with com=True)."""
    index = list(task.index)
    return robot.data.Jcom[index], (robot.data.com[0] - task.target)[index], np.full(len(index), task.weight), None


def posture_mask(robot: Robot, task: PostureTask) -> np.ndarray:
    """(nv,) the velocities a posture task pulls (all but a free-flyer's six unless ``base``)."""
    mask = np.ones(robot.nv, dtype=bool)
    if robot.floating and not task.base:
        mask[:6] = False
    return mask


def posture_weight(robot: Robot, task: PostureTask) -> np.ndarray:
    """(nv,) the posture's weight per velocity (zero where it does not pull: a free-flyer's six unless ``base``).

    Raises:
        OptionError: per-velocity weights of another length than nv.
    """
    if isinstance(task.weight, np.ndarray):
        if task.weight.shape != (robot.nv,):
            raise OptionError("weight", task.weight, f"a number, or nv = {robot.nv} numbers for {robot.name}")
        weight = task.weight.copy()
    else:
        weight = np.full(robot.nv, float(task.weight))
    weight[~posture_mask(robot, task)] = 0.0
    return weight


def checked_ref(robot: Robot, task: PostureTask) -> np.ndarray:
    """A posture's reference q (the robot's neutral one for None).

    Raises:
        ConfigurationError: a q_ref that is not a configuration of the robot.
    """
    if task.q_ref is None:
        return robot.neutral()
    q_ref = task.q_ref
    if q_ref.shape != (robot.nq,):
        raise ConfigurationError(f"PostureTask.q_ref must have nq = {robot.nq} numbers for {robot.name}, got "
                                 f"{q_ref.shape[0]}")
    robot.check_q(q_ref, what="PostureTask.q_ref")  # its quaternions unit, its coordinates within reason
    return q_ref


def posture_error(robot: Robot, task: PostureTask, q: np.ndarray) -> np.ndarray:
    """q ⊖ q_ref (nv) [rad or m].

    Raises:
        ConfigurationError: a q_ref that is not a configuration of the robot.
    """
    return np.asarray(pin.difference(robot.model, checked_ref(robot, task), q), dtype=float)


def coupling_row(robot: Robot, task: CouplingTask, q: np.ndarray, dt: float) -> tuple[np.ndarray, float]:
    """(a, c): the equality a·v = c that keeps ``joint = ratio · leader + offset`` after the step (and brings it
    back when it is off).

    Raises:
        JointNotFoundError: an unknown joint. OptionError: a joint with more than one coordinate.
    """
    a = np.zeros(robot.nv)
    idx = []
    for name in (task.joint, task.leader):
        if not robot.model.existJointName(name):
            raise JointNotFoundError(name, robot.joint_names)
        joint = robot.model.joints[robot.model.getJointId(name)]
        if joint.nq != 1 or joint.nv != 1:
            raise OptionError("CouplingTask", name, "a joint with one coordinate (revolute or prismatic)")
        idx.append((joint.idx_q, joint.idx_v))
    (qj, vj), (ql, vl) = idx
    a[vj], a[vl] = 1.0, -task.ratio
    return a, -(q[qj] - task.ratio * q[ql] - task.offset) / dt


def task_rows(robot: Robot, task: Task) -> Rowset:
    """(A, e, per-row weight, a pose's translation gap) of a frame, relative frame or centre-of-mass task."""
    if isinstance(task, FrameTask):
        return frame_rows(robot, task)
    if isinstance(task, RelativeFrameTask):
        return relative_rows(robot, task)
    assert isinstance(task, ComTask)
    return com_rows(robot, task)
