"""FRDM carried to the tree: each joint in turn takes the finite rotation (or displacement) that is optimal for the
weighted errors of every task frame below it, in closed form; a free-flyer takes the optimal rigid motion of all of
them (weighted Procrustes). This is the method of Danilov et al. (docs/methods.md) for one tool of one chain, where
a joint sees the tool alone; on a tree a joint sees every task point of its subtree, and the sweeps repeat until the
errors stop falling. The converged solve finishes with the Gauss–Newton step, as kinelab's FRDM finishes a chain.

Tasks as points (world frame): a frame's origin with its target's (weight: the task's position weight); its
rotation as its three unit axes against the target's (directions: turned, never moved; weight half the
orientation weight, so that Σ‖R eₖ − R* eₖ‖² ≈ 2θ² counts θ² once); an axis task one axis; the centre of mass as
the point the subtree's mass moves (a share m_subtree / m of it), its free coordinates' targets its current ones.
A posture is left to the finish; a coupling is held by projection after each sweep.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.ik.result import Status
from kinelab.robot.tree import Robot
from kinelab.wholebody.evaluate import PointRow
from kinelab.wholebody.iterate import SolveSettings, iterate, posture_second
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.tasks import Task

FALL = 0.2  # a sweep that takes off less than this share of the weighted error ends the sweeps
HANDOVER = 1e-2  # [m or rad] below this error the Gauss–Newton finish takes over


@dataclass
class Points:
    """The task points at a configuration: per point its frame (or -1 for the centre of mass), world position p,
    target t, weight w, and whether it is a direction (turned, never moved); ``com`` the mass shares."""

    frame: np.ndarray
    p: np.ndarray
    t: np.ndarray
    w: np.ndarray
    direction: np.ndarray
    carrier: np.ndarray  # the frame whose motion moves the target (a relative task's root), or -1: fixed
    free: np.ndarray  # (n, 3): 1 where the target follows the point (a centre of mass's unconstrained coordinates)


def task_points(robot: Robot, tasks: tuple[Task, ...], data: pin.Data, com: np.ndarray | None) -> Points:
    """Every task's points (:meth:`~kinelab.wholebody.tasks.Task.points`) at the configuration in ``data`` (frame
    placements updated)."""
    rows: list[PointRow] = [row for task in tasks for row in task.points(robot, data, com)]
    frame, p, t, w, direction, carrier, free = zip(*rows, strict=True) if rows else ((),) * 7
    return Points(np.array(frame, dtype=int), np.array(p, dtype=float).reshape(-1, 3),
                  np.array(t, dtype=float).reshape(-1, 3), np.array(w, dtype=float), np.array(direction, dtype=bool),
                  np.array(carrier, dtype=int), np.array(free, dtype=float).reshape(-1, 3))


def _rotation_angle(a: np.ndarray, b: np.ndarray, w: np.ndarray, u: np.ndarray) -> float:
    """θ maximizing Σ w bᵀR(u, θ)a: atan2(B, A) (a, b relative to a point of the axis, or directions)."""
    ua, ub = a @ u, b @ u
    A = float(w @ (np.einsum("ij,ij->i", a, b) - ua * ub))
    B = float(w @ np.einsum("ij,ij->i", b, a @ pin.skew(u).T))
    return math.atan2(B, A) if A or B else 0.0


def _clamped(best: float, lo: float, hi: float) -> float:
    """The increment in [lo, hi] nearest (on the circle) to ``best``, the unconstrained optimum of R cos(θ − best)."""
    if lo <= best <= hi:
        return best
    for shift in (-2 * math.pi, 2 * math.pi):
        if lo <= best + shift <= hi:
            return best + shift
    gap = lambda x: abs(math.remainder(x - best, 2 * math.pi))  # noqa: E731
    return lo if gap(lo) <= gap(hi) else hi


@dataclass(frozen=True)
class TreeJoint:
    """A 1-DoF joint of the tree FRDM turns or slides: its id, q and v index, kind, and its subtree's frames."""

    jid: int
    iq: int
    iv: int
    prismatic: bool
    continuous: bool
    frames: np.ndarray  # frame ids in its subtree (bool mask over the model's frames)
    mass_share: float  # the subtree's share of the robot's mass
    ancestors: tuple[int, ...]  # the joints above it, the universe (0) first


def tree_joints(robot: Robot) -> list[TreeJoint]:
    """The robot's 1-DoF joints, tip to base (children before parents), with their subtrees."""
    model = robot.model
    mass = sum(i.mass for i in model.inertias)
    out = []
    for jid in range(model.njoints - 1, 0, -1):
        joint = model.joints[jid]
        if joint.nv != 1 or joint.shortname() == "JointModelMimic":
            continue
        below = set(model.subtrees[jid])
        frames = np.array([f.parentJoint in below for f in model.frames], dtype=bool)
        share = sum(model.inertias[j].mass for j in below) / mass if mass > 0 else 0.0
        kind = joint.shortname()
        above = tuple(int(j) for j in model.supports[jid] if j != jid)
        out.append(TreeJoint(jid, joint.idx_q, joint.idx_v, "JointModelP" in kind, joint.nq == 2, frames, share,
                             above))
    return out


def sweep(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, joints: list[TreeJoint], data: pin.Data) -> None:
    """One sweep, tip to base, over the joints; then the free-flyer's optimal rigid motion (q changed in place)."""
    sweep_joints(robot, tasks, q, joints, data)
    if robot.floating:
        pin.framesForwardKinematics(robot.model, data, q)
        has_com = any(t.uses_com for t in tasks)
        com = pin.centerOfMass(robot.model, data, q) if has_com else None
        move_base(robot, q, task_points(robot, tasks, data, com))
    _couple(robot, tasks, q)


def sweep_joints(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, joints: list[TreeJoint],
                 data: pin.Data) -> Points:
    """The joints' turns of one sweep, tip to base (q changed in place).

    One forward kinematics a sweep: a joint's placement depends on its ancestors alone, which turn after it, so
    each turn moves only the task points (and subtree centres of mass) below it, updated here as rigid motions.

    Returns:
        The task points at the new q (as Pinocchio's FK there gives them).
    """
    model = robot.model
    has_com = any(t.uses_com for t in tasks)
    pin.framesForwardKinematics(model, data, q)
    com = pin.centerOfMass(model, data, q) if has_com else None
    points = task_points(robot, tasks, data, com)
    coms = _subtree_coms(data) if has_com else np.zeros((0, 3))
    masses = np.asarray(data.mass, dtype=float)
    for joint in joints:
        mine = (points.frame >= 0) & joint.frames[np.maximum(points.frame, 0)]
        com_rows = points.frame < 0
        if not mine.any() and not (com_rows.any() and joint.mass_share > 0):
            continue
        oMi = data.oMi[joint.jid]
        u, o = oMi.rotation @ _axis(robot, joint), np.array(oMi.translation)
        lever = joint.mass_share * (coms[joint.jid] - o) if has_com else np.zeros(3)
        R, shift = _move_joint(robot, joint, q, u, o, points, mine, com_rows, lever)
        _carry(points, joint, mine, R, o, shift)
        if has_com:
            _carry_masses(coms, masses, joint, points, R, o, shift)
    return points


def _subtree_coms(data: pin.Data) -> np.ndarray:
    """Each joint's subtree centre of mass in the world frame [m] (Pinocchio keeps it in the joint's own frame)."""
    return np.array([np.asarray(data.com[0], dtype=float)]
                    + [np.asarray(data.oMi[i].act(data.com[i]), dtype=float) for i in range(1, len(data.com))])


def _moved(x: np.ndarray, R: np.ndarray, o: np.ndarray, shift: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Points (rows of x; directions only turned) after the rigid motion x → o + R (x − o) + shift."""
    turned = (x - np.where(direction[:, None], 0.0, o)) @ R.T
    return turned + np.where(direction[:, None], 0.0, o + shift)


def _carry(points: Points, joint: TreeJoint, mine: np.ndarray, R: np.ndarray, o: np.ndarray,
           shift: np.ndarray) -> None:
    """The task points and targets the joint's subtree carries, moved with it."""
    if mine.any():
        points.p[mine] = _moved(points.p[mine], R, o, shift, points.direction[mine])
    carried = (points.carrier >= 0) & joint.frames[np.maximum(points.carrier, 0)]
    if carried.any():
        points.t[carried] = _moved(points.t[carried], R, o, shift, points.direction[carried])


def _carry_masses(coms: np.ndarray, masses: np.ndarray, joint: TreeJoint, points: Points, R: np.ndarray,
                  o: np.ndarray, shift: np.ndarray) -> None:
    """The subtree centres of mass above the joint, and the centre-of-mass points, after its motion."""
    before = coms[joint.jid].copy()
    coms[joint.jid] = o + R @ (before - o) + shift
    for a in joint.ancestors:
        if masses[a] > 0:
            coms[a] += masses[joint.jid] / masses[a] * (coms[joint.jid] - before)
    rows = points.frame < 0
    if rows.any():
        moved = coms[0] - points.p[rows]
        points.p[rows] = coms[0]
        points.t[rows] += moved * points.free[rows]


def _move_joint(robot: Robot, joint: TreeJoint, q: np.ndarray, u: np.ndarray, o: np.ndarray, points: Points,
                mine: np.ndarray, com_rows: np.ndarray, lever: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint ``joint``'s optimal finite rotation or displacement for the points it moves, within its limits
    (q changed in place).

    Returns:
        (R, shift): the motion it gave its subtree, a turn R about the axis through o, then a shift [m].
    """
    a, b, w, d = points.p[mine], points.t[mine], points.w[mine], points.direction[mine]
    if com_rows.any() and joint.mass_share > 0:
        # the centre of mass moves as a point at o + share·(c_subtree − o) would (its target shifted alike)
        k = np.flatnonzero(com_rows)
        a = np.vstack([a, np.tile(lever + o, (len(k), 1))])
        b = np.vstack([b, points.t[k] - points.p[k] + lever + o])
        w, d = np.concatenate([w, points.w[k]]), np.concatenate([d, np.zeros(len(k), dtype=bool)])
    value = q[joint.iq] if not joint.continuous else math.atan2(q[joint.iq + 1], q[joint.iq])
    lo, hi = robot.space.lower[joint.iq] - value, robot.space.upper[joint.iq] - value
    if joint.prismatic:
        moved = ~d
        step = float(w[moved] @ ((b[moved] - a[moved]) @ u)) / float(w[moved].sum()) if moved.any() else 0.0
        step = min(max(step, lo), hi)
        q[joint.iq] += step
        return np.eye(3), step * u
    rel_a = np.where(d[:, None], a, a - o)
    rel_b = np.where(d[:, None], b, b - o)
    theta = _rotation_angle(rel_a, rel_b, w, u)
    theta = _clamped(theta, lo, hi) if not joint.continuous else theta
    if joint.continuous:
        angle = value + theta
        q[joint.iq], q[joint.iq + 1] = math.cos(angle), math.sin(angle)
    else:
        q[joint.iq] += theta
    return pin.exp3(theta * u), np.zeros(3)


def _axis(robot: Robot, joint: TreeJoint) -> np.ndarray:
    """The joint's unit axis in its own frame (its motion subspace's angular part, or linear for a slide)."""
    key = f"frdm axis {joint.jid}"
    if key not in robot._derived:
        jm = robot.model.joints[joint.jid]
        jd = jm.createData()
        jm.calc(jd, np.array([1.0, 0.0]) if jm.nq == 2 else np.zeros(jm.nq))
        S = np.asarray(jd.S, dtype=float).ravel()
        axis = S[:3] if joint.prismatic else S[3:]
        robot._derived[key] = axis / np.linalg.norm(axis)
    return robot._derived[key]


def move_base(robot: Robot, q: np.ndarray, points: Points) -> None:
    """The free-flyer's optimal rigid motion for every task point (weighted Procrustes), applied to q[:7]."""
    if not len(points.w):
        return
    pts, dirs = ~points.direction, points.direction
    w = points.w
    if pts.any():
        pc = (w[pts] @ points.p[pts]) / w[pts].sum()
        tc = (w[pts] @ points.t[pts]) / w[pts].sum()
    else:
        pc = tc = np.zeros(3)
    a = np.where(dirs[:, None], points.p, points.p - pc)
    b = np.where(dirs[:, None], points.t, points.t - tc)
    H = (a * w[:, None]).T @ b
    U, _, Vt = np.linalg.svd(H)
    sign = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ np.diag([1.0, 1.0, sign]) @ U.T
    t = (tc - R @ pc) if pts.any() else np.zeros(3)
    oMb = pin.XYZQUATToSE3(q[:7])
    moved = pin.SE3(R, t) * oMb
    q[:7] = pin.SE3ToXYZQUAT(moved)


def _couple(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray) -> None:
    """Each task that can be met outright (a coupling) met, q changed in place."""
    for task in tasks:
        task.project(robot, q)


def weighted_error(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, data: pin.Data) -> tuple[float, float]:
    """(Σ w‖p − t‖², the largest point or direction gap [m or ≈ rad]) at q."""
    pin.framesForwardKinematics(robot.model, data, q)
    com = pin.centerOfMass(robot.model, data, q) if any(t.uses_com for t in tasks) else None
    pts = task_points(robot, tasks, data, com)
    gaps = np.linalg.norm(pts.p - pts.t, axis=1)
    return float(pts.w @ gaps**2), float(gaps.max(initial=0.0))


def frdm_solve(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, settings: SolveSettings,
               deadline: float) -> tuple[np.ndarray, int, Status]:
    """Sweeps from q until the error stops falling or is small, then the Gauss–Newton finish (the solve's step).

    Returns:
        (q, sweeps and finishing steps, status of the last phase).
    """

    q = np.array(q, dtype=float)
    data = robot.model.createData()
    joints = robot.derived("frdm tree joints", tree_joints)
    frdm_tasks = tuple(t for t in tasks if not t.preference)  # a preference has no points: left to the finish
    error, _ = weighted_error(robot, frdm_tasks, q, data)
    used = 0
    for used in range(1, settings.max_iterations + 1):
        if time.perf_counter() > deadline:
            return q, used, Status.TIME_BUDGET
        sweep(robot, frdm_tasks, q, joints, data)
        new, largest = weighted_error(robot, frdm_tasks, q, data)
        if largest < HANDOVER or new > error * (1.0 - FALL):
            break
        error = new
    q, finish, status = iterate(robot, posture_second(tasks), q, settings, Limits(velocity=1.0), deadline)
    return q, used + finish, status
