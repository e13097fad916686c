"""Forward kinematics from yourdfpy: a second URDF reader, independent of Pinocchio.

Used only as a cross-check of Pinocchio's model (see :mod:`kinelab.checks`). Meshes are never loaded,
so kinematics work whether or not ``package://`` mesh paths resolve.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import yourdfpy

from kinelab.errors import ChainError
from kinelab.robot import Robot


def _tool_link(robot: Robot) -> str:
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
    """FK of the robot's tool link relative to its root link, computed by yourdfpy."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.urdf = yourdfpy.URDF.load(
            str(robot.urdf_path), build_scene_graph=True, load_meshes=False,
            build_collision_scene_graph=False, load_collision_meshes=False,
        )
        self.tool_link = _tool_link(robot)
        self.base_link = self.urdf.base_link
        self._cfg = {name: robot.locked.get(name, 0.0) for name in self.urdf.actuated_joint_names}

    def fk(self, q) -> pin.SE3:
        """oMtool from yourdfpy at kinelab coordinates ``q`` (rad, m)."""
        q = self.robot.check_q(q)
        cfg = dict(self._cfg)
        cfg.update(zip(self.robot.joint_names, q, strict=True))
        self.urdf.update_cfg(cfg)
        T = self.urdf.get_transform(frame_to=self.tool_link, frame_from=self.base_link)
        return pin.SE3(np.asarray(T, dtype=float))
