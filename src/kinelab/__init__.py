"""kinelab: kinematics of serial arms and mobile manipulators, checked against Pinocchio."""

from kinelab.catalog import names as robots
from kinelab.errors import (
    ChainError,
    ConfigurationError,
    FrameNotFoundError,
    JointLimitError,
    JointNotFoundError,
    KinelabError,
    RobotNotFoundError,
    URDFError,
)
from kinelab.robot import Joint, Robot, load

__version__ = "0.1.0"

__all__ = [
    "ChainError",
    "ConfigurationError",
    "FrameNotFoundError",
    "Joint",
    "JointLimitError",
    "JointNotFoundError",
    "KinelabError",
    "Robot",
    "RobotNotFoundError",
    "URDFError",
    "load",
    "robots",
]
