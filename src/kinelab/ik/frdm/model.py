"""The FRDM vector model of a serial chain, built from a Robot and inspectable on its own.

Arrays describe the chain at q = 0 in Pinocchio's terms (joint placements, local axes, tool placement),
from which the compiled FK gives, at any q, the paper's vector model: unit joint axes e_i and points
o_i (base frame), type flags (p = 1 revolute, 0 prismatic), limits L(2, n), and the tool point N with
the tool vectors (the columns of the tool rotation).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinelab.errors import ChainError
from kinelab.ik.frdm import kernel
from kinelab.robot import Robot

_KINDS = {"revolute": kernel.REVOLUTE, "prismatic": kernel.PRISMATIC, "continuous": kernel.CONTINUOUS}


@dataclass(frozen=True)
class VectorModel:
    """A chain as arrays for the FRDM kernel. Units: m, rad; frames: the robot's base frame."""

    joint_names: tuple[str, ...]
    kind: np.ndarray  # (n,) 0 revolute, 1 prismatic, 2 continuous
    axis_local: np.ndarray  # (n, 3)
    placement_R: np.ndarray  # (n, 3, 3) joint frame in its parent's, at q = 0
    placement_t: np.ndarray  # (n, 3)
    tool_R: np.ndarray  # (3, 3) tool frame in the last joint's frame
    tool_t: np.ndarray  # (3,)
    lower: np.ndarray  # (n,) limits (continuous: −inf, +inf)
    upper: np.ndarray
    length: float  # characteristic length L [m] (mean spacing of joint origins)

    @property
    def n(self) -> int:
        return len(self.joint_names)

    @property
    def limits(self) -> np.ndarray:
        """L(2, n): first row lower, second row upper limits."""
        return np.vstack([self.lower, self.upper])

    def vectors(self, q) -> dict[str, np.ndarray]:
        """The paper's vectors at q: axes e (n×3), points o (n×3), type flags p, link vectors M
        (o_{i+1} − o_i and N − o_n), tool point N, tool vectors u_x, u_y, u_z (base frame)."""
        q = np.asarray(q, dtype=float)
        e, o, p, R = np.empty((self.n, 3)), np.empty((self.n, 3)), np.empty(3), np.empty((3, 3))
        kernel.chain_fk(self.placement_R, self.placement_t, self.axis_local, self.kind, self.tool_R,
                        self.tool_t, q, e, o, p, R)
        links = np.vstack([np.diff(o, axis=0), p - o[-1]])
        return {"e": e, "o": o, "p": (self.kind != kernel.PRISMATIC).astype(int), "M": links, "N": p,
                "u_x": R[:, 0], "u_y": R[:, 1], "u_z": R[:, 2], "R": R}


def build(robot: Robot) -> VectorModel:
    """The vector model of ``robot``'s base → tool chain (every joint must be 1-DoF: checked by Robot)."""
    model = robot.model
    for jid in range(1, model.njoints):
        if model.parents[jid] != jid - 1:
            raise ChainError(f"joint {model.names[jid]!r} is not in series with the previous one")
    tool = model.frames[robot.tool_frame_id]
    if tool.parentJoint != model.njoints - 1:
        raise ChainError(f"the tool frame {robot.tool!r} is not carried by the last chain joint")
    kind = np.array([_KINDS[k] for k in robot.joint_kinds], dtype=np.int64)
    lower = np.where(kind == kernel.CONTINUOUS, -np.inf, robot.lower)
    upper = np.where(kind == kernel.CONTINUOUS, np.inf, robot.upper)
    return VectorModel(
        joint_names=tuple(robot.joint_names),
        kind=kind,
        axis_local=np.array([j.axis_local for j in robot.joints], dtype=float),
        placement_R=np.array([model.jointPlacements[j].rotation for j in range(1, model.njoints)]),
        placement_t=np.array([model.jointPlacements[j].translation for j in range(1, model.njoints)]),
        tool_R=tool.placement.rotation.copy(),
        tool_t=tool.placement.translation.copy(),
        lower=lower.astype(float),
        upper=upper.astype(float),
        length=robot.characteristic_length(),
    )
