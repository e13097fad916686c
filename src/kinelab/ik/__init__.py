"""Inverse kinematics: :func:`solve` for every solver, the targets, the result.

- :mod:`~kinelab.ik.solve`: the entry point (restarts, budget, Pinocchio's verdict).
- :mod:`~kinelab.ik.preferred`: the public ``solve`` (one answer, or the branch nearest ``prefer``).
- :mod:`~kinelab.ik.targets`, :mod:`~kinelab.ik.result`: what goes in and what comes out.
- :mod:`~kinelab.ik.chain`: the compiled chain FK, joint codes and RNG every kernel shares.
- :mod:`~kinelab.ik.multistart`: seeded restarts run in compiled chunks.
- :mod:`~kinelab.ik.dls`: the Pinocchio damped-least-squares reference.
- :mod:`~kinelab.ik.frdm` (paper 000) and :mod:`~kinelab.ik.biquat` (paper 001).
"""

from kinelab.errors import TargetError
from kinelab.ik.preferred import solve
from kinelab.ik.result import IKResult, Status
from kinelab.ik.solve import register
from kinelab.ik.targets import from_xyz_quat_wxyz as target_from_xyz_quat_wxyz
from kinelab.ik.targets import from_xyz_rpy as target_from_xyz_rpy

__all__ = ["IKResult", "Status", "TargetError", "register", "solve", "target_from_xyz_quat_wxyz",
           "target_from_xyz_rpy"]
