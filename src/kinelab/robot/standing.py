"""``kinelab.standing(robot)``: where a whole robot stands (:meth:`kinelab.robot.tree.Robot.standing`)."""

from __future__ import annotations

import numpy as np

from kinelab.errors import ChainError
from kinelab.robot.tree import Robot


def standing(robot: Robot) -> np.ndarray:
    """The robot's standing configuration: its SRDF's "half_sitting" (else neutral), its loops closed, a free-flyer
    robot's lowest foot on the floor (z = 0) [m, rad; Pinocchio's q].

    Raises:
        ChainError: not a whole robot (a chain has its own start: ``chain.display_pose``).
    """
    if not isinstance(robot, Robot):
        raise ChainError(f"standing takes a whole robot (kinelab.load('talos')), got {type(robot).__name__}")
    return robot.standing()
