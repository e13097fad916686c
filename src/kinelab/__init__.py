"""kinelab: kinematics of serial arms and mobile manipulators, checked against Pinocchio.

The public API: :func:`load` a robot, :func:`solve` IK for a target (built with
:func:`target_from_xyz_rpy` or :func:`target_from_xyz_quat_wxyz`), :func:`track` a path, and the
errors every call raises on bad input (all :class:`KinelabError`).
"""

from importlib.metadata import PackageNotFoundError, version

from kinelab.errors import (
    BiquaternionError,
    ChainError,
    ConfigurationError,
    DescriptionError,
    FrameNotFoundError,
    JointLimitError,
    JointNotFoundError,
    KinelabError,
    OptionError,
    RobotNotFoundError,
    SolverNotFoundError,
    SRDFError,
    TargetError,
    URDFError,
)
from kinelab.ik.api import solve, solve_all, solve_batch, track
from kinelab.ik.batch import BatchIKResult
from kinelab.ik.frdm.options import FRDMOptions
from kinelab.ik.prepared import IK
from kinelab.ik.result import Diagnostics, IKResult, Status, TrackResult
from kinelab.ik.targets import from_xyz_quat_wxyz as target_from_xyz_quat_wxyz
from kinelab.ik.targets import from_xyz_rpy as target_from_xyz_rpy
from kinelab.robot import Joint, Robot, load
from kinelab.robot.catalog import names as robots

try:
    __version__ = version("kinelab")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"

__all__ = [
    "BatchIKResult",
    "BiquaternionError",
    "ChainError",
    "ConfigurationError",
    "DescriptionError",
    "Diagnostics",
    "FRDMOptions",
    "FrameNotFoundError",
    "IK",
    "IKResult",
    "Joint",
    "JointLimitError",
    "JointNotFoundError",
    "KinelabError",
    "OptionError",
    "Robot",
    "RobotNotFoundError",
    "SolverNotFoundError",
    "SRDFError",
    "Status",
    "TargetError",
    "TrackResult",
    "URDFError",
    "__version__",
    "load",
    "robots",
    "solve",
    "solve_all",
    "solve_batch",
    "target_from_xyz_quat_wxyz",
    "target_from_xyz_rpy",
    "track",
]
