"""kinelab: kinematics of serial arms and mobile manipulators, checked against Pinocchio.

The public API: :func:`load` a robot, :func:`solve` IK for a target (built with
:func:`target_from_xyz_rpy` or :func:`target_from_xyz_quat_wxyz`), :func:`track` a path, and the
errors every call raises on bad input (all :class:`KinelabError`).
"""

from typing import TYPE_CHECKING

from kinelab.errors import (
    AssemblyError,
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
from kinelab.lazy import loader

# the robot (and with it Pinocchio) and the solvers load on first use (kinelab.lazy): ``kinelab --help`` and
# ``kinelab robots`` need neither
_LAZY = {
    "load": ("kinelab.wholebody.ready", "load"),  # an arm's solvers readied (kinelab.robot.load: the robot alone)
    "Robot": ("kinelab.robot.tree", "Robot"),
    "Chain": ("kinelab.robot.chain", "Chain"),
    "Joint": ("kinelab.robot.joints", "Joint"),
    "robots": ("kinelab.robot.catalog", "names"),
    "solve": ("kinelab.wholebody.api", "solve"),
    "step": ("kinelab.wholebody.problem", "step"),
    "WholeBody": ("kinelab.wholebody.problem", "WholeBody"),
    "FrameTask": ("kinelab.wholebody.tasks", "FrameTask"),
    "RelativeFrameTask": ("kinelab.wholebody.tasks", "RelativeFrameTask"),
    "ComTask": ("kinelab.wholebody.tasks", "ComTask"),
    "PostureTask": ("kinelab.wholebody.tasks", "PostureTask"),
    "CouplingTask": ("kinelab.wholebody.constraints", "CouplingTask"),
    "Closure": ("kinelab.robot.closures", "Closure"),
    "standing": ("kinelab.robot.standing", "standing"),
    "DampingTask": ("kinelab.wholebody.tasks", "DampingTask"),
    "Limits": ("kinelab.wholebody.limits", "Limits"),
    "StepOptions": ("kinelab.wholebody.step", "StepOptions"),
    "StepResult": ("kinelab.wholebody.step", "StepResult"),
    "WholeBodyResult": ("kinelab.wholebody.solve", "WholeBodyResult"),
    "solve_all": ("kinelab.ik.api", "solve_all"),
    "solve_all_batch": ("kinelab.ik.api", "solve_all_batch"),
    "BranchBatch": ("kinelab.ik.analytic.batch", "BranchBatch"),
    "solve_batch": ("kinelab.ik.api", "solve_batch"),
    "solve_batch_on_cluster": ("kinelab.maps.batch", "solve_batch_on_cluster"),
    "BatchSpec": ("kinelab.maps.batch", "BatchSpec"),
    "track": ("kinelab.wholebody.api", "track"),
    "BatchIKResult": ("kinelab.ik.batch", "BatchIKResult"),
    "Branches": ("kinelab.ik.result", "Branches"),
    "FRDMOptions": ("kinelab.ik.frdm.options", "FRDMOptions"),
    "IK": ("kinelab.ik.prepared", "IK"),
    "SEW": ("kinelab.ik.analytic.sew", "SEW"),
    "sew_angle": ("kinelab.ik.analytic.sew", "sew_angle"),
    "Diagnostics": ("kinelab.ik.result", "Diagnostics"),
    "FRDMDiagnostics": ("kinelab.ik.result", "FRDMDiagnostics"),
    "BiquatDiagnostics": ("kinelab.ik.result", "BiquatDiagnostics"),
    "IKResult": ("kinelab.ik.result", "IKResult"),
    "Status": ("kinelab.ik.result", "Status"),
    "TrackResult": ("kinelab.ik.result", "TrackResult"),
    "target_from_xyz_quat_wxyz": ("kinelab.ik.targets", "from_xyz_quat_wxyz"),
    "target_from_xyz_rpy": ("kinelab.ik.targets", "from_xyz_rpy"),
    "Collisions": ("kinelab.collision.model", "Collisions"),
    "Environment": ("kinelab.collision.obstacles", "Environment"),
    "Obstacle": ("kinelab.collision.obstacles", "Obstacle"),
    "__version__": ("kinelab.lazy", "package_version"),  # importlib.metadata costs 60 ms: read when asked for
}


__getattr__ = loader(__name__, globals(), _LAZY)

if TYPE_CHECKING:  # the names the lazy table serves, for type checkers and editors
    from kinelab.collision.model import Collisions
    from kinelab.collision.obstacles import Environment, Obstacle
    from kinelab.ik.analytic.batch import BranchBatch
    from kinelab.ik.analytic.sew import SEW, sew_angle
    from kinelab.ik.api import solve_all, solve_all_batch, solve_batch
    from kinelab.ik.batch import BatchIKResult
    from kinelab.ik.frdm.options import FRDMOptions
    from kinelab.ik.prepared import IK
    from kinelab.ik.result import (
        BiquatDiagnostics,
        Branches,
        Diagnostics,
        FRDMDiagnostics,
        IKResult,
        Status,
        TrackResult,
    )
    from kinelab.ik.targets import from_xyz_quat_wxyz as target_from_xyz_quat_wxyz
    from kinelab.ik.targets import from_xyz_rpy as target_from_xyz_rpy
    from kinelab.maps.batch import BatchSpec, solve_batch_on_cluster
    from kinelab.robot.catalog import names as robots
    from kinelab.robot.chain import Chain
    from kinelab.robot.closures import Closure
    from kinelab.robot.joints import Joint
    from kinelab.robot.standing import standing
    from kinelab.robot.tree import Robot
    from kinelab.wholebody.api import solve, track
    from kinelab.wholebody.constraints import CouplingTask
    from kinelab.wholebody.limits import Limits
    from kinelab.wholebody.problem import WholeBody, step
    from kinelab.wholebody.ready import load
    from kinelab.wholebody.solve import WholeBodyResult
    from kinelab.wholebody.step import StepOptions, StepResult
    from kinelab.wholebody.tasks import ComTask, DampingTask, FrameTask, PostureTask, RelativeFrameTask


__all__ = [
    "AssemblyError",
    "BatchIKResult",
    "Closure",
    "ComTask",
    "CouplingTask",
    "DampingTask",
    "FrameTask",
    "Limits",
    "PostureTask",
    "RelativeFrameTask",
    "StepOptions",
    "StepResult",
    "WholeBody",
    "WholeBodyResult",
    "step",
    "BatchSpec",
    "BiquatDiagnostics",
    "BiquaternionError",
    "BranchBatch",
    "Branches",
    "Chain",
    "ChainError",
    "Collisions",
    "ConfigurationError",
    "DescriptionError",
    "Diagnostics",
    "Environment",
    "FRDMDiagnostics",
    "FRDMOptions",
    "FrameNotFoundError",
    "IK",
    "IKResult",
    "Joint",
    "JointLimitError",
    "JointNotFoundError",
    "KinelabError",
    "Obstacle",
    "OptionError",
    "Robot",
    "RobotNotFoundError",
    "SolverNotFoundError",
    "SEW",
    "SRDFError",
    "Status",
    "TargetError",
    "TrackResult",
    "URDFError",
    "__version__",
    "load",
    "robots",
    "sew_angle",
    "solve",
    "solve_all",
    "solve_all_batch",
    "solve_batch",
    "solve_batch_on_cluster",
    "standing",
    "target_from_xyz_quat_wxyz",
    "target_from_xyz_rpy",
    "track",
]
