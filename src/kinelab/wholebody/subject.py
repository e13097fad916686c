"""What a whole-body problem is posed on: a whole robot, or a chain (its own joints, the rest held as the chain holds
them), seen as the whole robot of the chain's reduced model."""

from __future__ import annotations

from typing import Any

from kinelab.errors import ChainError
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot


def as_robot(robot: Any, what: str = "a whole-body problem") -> Robot:
    """The robot a whole-body step or solve works on: a :class:`Robot` as it is; a :class:`Chain` as the robot of its
    own reduced model (q: Pinocchio's q of that model — the chain's one number per joint where no joint is
    continuous; frames: the chain's, its tool among them; hands: its tool), made once per chain.

    Raises:
        ChainError: anything else (named).
    """
    if isinstance(robot, Robot):
        return robot
    if isinstance(robot, Chain):
        return robot.derived("whole-body robot", _chain_robot)
    raise ChainError(f"{what} takes a whole robot (kinelab.load('talos'), or load(path, whole=True)) or a chain "
                     f"(kinelab.load('panda')), got {type(robot).__name__}")


def _chain_robot(chain: Chain) -> Robot:
    robot = Robot(chain.model, name=chain.name, srdf=chain.srdf,
                  geometry=lambda kind: chain.visual_model(kind=kind))
    robot.hands = (chain.tool,)
    return robot
