"""Independent references for a Chain's model: yourdfpy's FK against Pinocchio's, Pinocchio's Jacobians
against finite differences. Used by the tests and by ``kinelab validate``; each returns measured figures.

yourdfpy is a second URDF reader, independent of Pinocchio; meshes are never loaded, so kinematics
work whether or not ``package://`` mesh paths resolve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import yourdfpy

from kinelab.errors import ChainError
from kinelab.geometry import pose_error
from kinelab.robot import Chain


@dataclass(frozen=True)
class Agreement:
    """Largest disagreement found over ``count`` seeded configurations."""

    robot: str
    what: str
    count: int
    max_position: float  # [m] for FK checks; unused (0) for Jacobian checks
    max_rotation: float  # [rad] for FK checks; max abs entry difference for Jacobian checks


def fk_vs_yourdfpy(robot: Chain, count: int = 1000, seed: int = 0) -> Agreement:
    """Tool pose from Pinocchio and from yourdfpy at ``count`` random configurations within limits."""
    other = YourdfpyFK(robot)
    worst_p = worst_r = 0.0
    for q in robot.random_qs(count, seed):
        dp, dr = pose_error(robot.fk(q), other.fk(q))
        worst_p, worst_r = max(worst_p, dp), max(worst_r, dr)
    return Agreement(robot.name, "fk_vs_yourdfpy", count, worst_p, worst_r)


def jacobian_local_fd(robot: Chain, q, eps: float = 1e-6) -> np.ndarray:
    """Central finite-difference LOCAL tool Jacobian: log6 of the tool displacement, steps by pin.integrate."""
    q = robot.check_q(q)
    oMtool = robot.fk(q)
    J = np.empty((6, robot.nv))
    for k in range(robot.nv):
        step = np.zeros(robot.nv)
        step[k] = eps
        plus = oMtool.actInv(robot.fk(robot.integrate(q, step)))
        minus = oMtool.actInv(robot.fk(robot.integrate(q, -step)))
        J[:, k] = (pin.log6(plus).vector - pin.log6(minus).vector) / (2 * eps)
    return J


def jacobians_vs_fd(robot: Chain, count: int = 100, seed: int = 0, eps: float = 1e-6) -> Agreement:
    """Pinocchio's LOCAL, WORLD and LOCAL_WORLD_ALIGNED tool Jacobians against finite differences.

    The LOCAL Jacobian is compared with differences directly; the other two with the difference
    Jacobian carried to their frame (WORLD: Ad(oMtool); LOCAL_WORLD_ALIGNED: rotation only).
    """
    worst = 0.0
    for q in robot.random_qs(count, seed):
        J_fd = jacobian_local_fd(robot, q, eps)
        oMtool = robot.fk(q)
        R = oMtool.rotation
        rot6 = np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]])
        pairs = (
            (robot.jacobian_local(q), J_fd),
            (robot.jacobian_world(q), oMtool.action @ J_fd),
            (robot.jacobian_local_world_aligned(q), rot6 @ J_fd),
        )
        for J, ref in pairs:
            worst = max(worst, float(np.max(np.abs(J - ref))))
    return Agreement(robot.name, "jacobians_vs_fd", count, 0.0, worst)


def tool_link(robot: Chain) -> str:
    """The URDF link whose placement is the tool frame's (yourdfpy knows links, not joint frames)."""
    frames = robot.model.frames
    fid = robot.tool_frame_id
    if frames[fid].type == pin.FrameType.BODY:
        return frames[fid].name
    children = [f.name for f in frames if f.parentFrame == fid and f.type == pin.FrameType.BODY]
    if frames[fid].type == pin.FrameType.FIXED_JOINT and children:
        return children[0]
    raise ChainError(f"tool frame {robot.tool!r} is not a URDF link; yourdfpy cannot place it")


class YourdfpyFK:
    """FK of the robot's tool link relative to its base link (the URDF root unless ``load(base=...)``),
    computed by yourdfpy."""

    def __init__(self, robot: Chain):
        self.robot = robot
        self.urdf = yourdfpy.URDF.load(
            str(robot.urdf_path), build_scene_graph=True, load_meshes=False,
            build_collision_scene_graph=False, load_collision_meshes=False,
        )
        self.tool_link = tool_link(robot)
        self.base_link = robot.base if robot.base in self.urdf.link_map else self.urdf.base_link
        self._cfg = {name: robot.locked.get(name, 0.0) for name in self.urdf.actuated_joint_names}

    def fk(self, q) -> pin.SE3:
        """oMtool from yourdfpy at kinelab coordinates ``q`` (rad, m)."""
        q = self.robot.check_q(q)
        cfg = dict(self._cfg)
        cfg.update(zip(self.robot.joint_names, q, strict=True))
        self.urdf.update_cfg(cfg)
        T = self.urdf.get_transform(frame_to=self.tool_link, frame_from=self.base_link)
        return pin.SE3(np.asarray(T, dtype=float))
