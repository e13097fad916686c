"""Inverse kinematics: the public entry points, the targets, the results.

- :mod:`~kinelab.ik.api`: :func:`solve`, :func:`solve_batch`, :func:`solve_all`, :func:`track` (one keyword-only
  vocabulary).
- :mod:`~kinelab.ik.request`: the validated request every entry point builds; :mod:`~kinelab.ik.registry`:
  the solvers by name.
- :mod:`~kinelab.ik.driver`: one solve (restarts, budget, Pinocchio's verdict); :mod:`~kinelab.ik.batch`,
  :mod:`~kinelab.ik.branches`: many targets, every branch.
- :mod:`~kinelab.ik.targets`, :mod:`~kinelab.ik.result`: what goes in and what comes out.
- :mod:`~kinelab.ik.chain`: the compiled chain FK, joint codes and RNG every kernel shares.
- :mod:`~kinelab.ik.multistart`: seeded restarts run in compiled chunks.
- :mod:`~kinelab.ik.dls`: the Pinocchio damped-least-squares reference.
- :mod:`~kinelab.ik.frdm` (paper 000) and :mod:`~kinelab.ik.biquat` (paper 001).
"""

from kinelab.errors import TargetError
from kinelab.ik.api import solve, solve_all, solve_batch, track
from kinelab.ik.registry import register
from kinelab.ik.result import Diagnostics, IKResult, Status
from kinelab.ik.targets import from_xyz_quat_wxyz as target_from_xyz_quat_wxyz
from kinelab.ik.targets import from_xyz_rpy as target_from_xyz_rpy

__all__ = ["Diagnostics", "IKResult", "Status", "TargetError", "register", "solve", "solve_all", "solve_batch",
           "target_from_xyz_quat_wxyz", "target_from_xyz_rpy", "track"]
