"""IK tasks: which components of the tool pose a solve must meet, and Pinocchio's verdict on them.

- ``pose``: the tool point and the whole tool rotation (6 components);
- ``position``: the tool point only (3);
- ``axis``: the tool point and one tool axis (``axis`` = "x", "y" or "z") along the target's same axis,
  the roll about it free (5): pointing, drilling, welding, most grasps;
- ``orientation``: the tool rotation only (3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.geometry import pose_errors
from kinelab.ik.words import AXES, TASKS

__all__ = ["AXES", "COMPONENTS", "POSE", "TASKS", "Task", "short_arm_note"]
COMPONENTS = {"pose": 6, "position": 3, "axis": 5, "orientation": 3}


def short_arm_note(name: str, joints: int, task: str) -> str | None:
    """Why an arm of ``joints`` joints misses task ``task`` in general, and the tasks that fit it (None: it has
    joints enough)."""
    if joints >= COMPONENTS[task]:
        return None
    fits = [t for t in ("axis", "position") if COMPONENTS[t] <= joints] or ["position"]
    return (f"{name} has {joints} joints and can meet at most {joints} of the {COMPONENTS[task]} components of task "
            f"{task!r}; try task={fits[0]!r}" + (f" or task={fits[1]!r}" if len(fits) > 1 else ""))


@dataclass(frozen=True)
class Task:
    """A checked task: its name and, for ``axis``, the tool axis (0, 1, 2 for x, y, z; −1 otherwise)."""

    name: str = "pose"
    axis: int = -1

    @classmethod
    def of(cls, task: str = "pose", axis: str = "z") -> Task:
        """The task named, refusing unknown names and axes with the valid ones.

        Raises:
            OptionError: an unknown task or axis.
        """
        if task == "pose" and axis == "z":
            return POSE
        if not isinstance(task, str) or task not in TASKS:
            raise OptionError("task", task, f"one of {', '.join(TASKS)}")
        if not isinstance(axis, str) or axis not in AXES:  # refused for every task: a typo is never ignored
            raise OptionError("axis", axis, "'x', 'y' or 'z' (the tool axis to align)")
        if task == "pose":
            return POSE
        return cls(task, AXES.index(axis) if task == "axis" else -1)

    @property
    def position(self) -> bool:
        """The task constrains the tool point."""
        return self.name != "orientation"

    @property
    def rotation(self) -> bool:
        """The task constrains the tool's rotation (all of it, or one axis)."""
        return self.name != "position"

    @property
    def dimension(self) -> int:
        """How many components of the tool's pose the task constrains (6, 3 or 5)."""
        return COMPONENTS[self.name]

    @property
    def rows(self) -> list[int]:
        """The rows of a [linear; angular] Jacobian the task constrains (task "axis": all six, a superset)."""
        return [0, 1, 2] if self.name == "position" else [3, 4, 5] if self.name == "orientation" else list(range(6))

    @property
    def constrained(self) -> str:
        """What the task constrains, in words (for results and messages)."""
        return {"pose": "position and rotation", "position": "position", "orientation": "rotation",
                "axis": f"position and the tool {AXES[self.axis]} axis"}[self.name]

    def errors(self, oMtarget: pin.SE3, oMtool: pin.SE3) -> tuple[float, float]:
        """(position error [m], rotation error [rad]) measured by Pinocchio's FK: the rotation error is the
        angle of R*ᵀR, or for ``axis`` the angle between the tool axis and the target's."""
        dp = oMtarget.translation - oMtool.translation
        if self.axis < 0:
            err = oMtarget.actInv(oMtool)
            return math.hypot(*err.translation.tolist()), math.hypot(*pin.log3(err.rotation).tolist())
        u, v = oMtool.rotation[:, self.axis], oMtarget.rotation[:, self.axis]
        return float(np.linalg.norm(dp)), math.atan2(float(np.linalg.norm(np.cross(u, v))), float(u @ v))

    def errors_batch(self, H_target: np.ndarray, H_tool: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`errors` for (B, 4, 4) stacks of homogeneous matrices."""
        if self.axis < 0:
            return pose_errors(H_target, H_tool)
        u, v = H_tool[:, :3, self.axis], H_target[:, :3, self.axis]
        dp = np.linalg.norm(H_target[:, :3, 3] - H_tool[:, :3, 3], axis=1)
        return dp, np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("bi,bi->b", u, v))

    def met_batch(self, dp: np.ndarray, dr: np.ndarray, tol_pos: float, tol_rot: float) -> np.ndarray:
        """:meth:`met` per row."""
        return (~np.bool_(self.position) | (dp <= tol_pos)) & (~np.bool_(self.rotation) | (dr <= tol_rot))

    def met(self, dp: float, dr: float, tol_pos: float, tol_rot: float) -> bool:
        """Both constrained components within tolerance."""
        return (not self.position or dp <= tol_pos) and (not self.rotation or dr <= tol_rot)


POSE = Task()
