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

from typing import TYPE_CHECKING

from kinelab.errors import TargetError
from kinelab.lazy import loader

__getattr__ = loader(__name__, globals(), {
    "solve": ("kinelab.ik.api", "solve"),
    "solve_all": ("kinelab.ik.api", "solve_all"),
    "solve_batch": ("kinelab.ik.api", "solve_batch"),
    "track": ("kinelab.ik.api", "track"),
    "register": ("kinelab.ik.registry", "register"),
    "Diagnostics": ("kinelab.ik.result", "Diagnostics"),
    "IKResult": ("kinelab.ik.result", "IKResult"),
    "Status": ("kinelab.ik.result", "Status"),
    "target_from_xyz_quat_wxyz": ("kinelab.ik.targets", "from_xyz_quat_wxyz"),
    "target_from_xyz_rpy": ("kinelab.ik.targets", "from_xyz_rpy"),
})

if TYPE_CHECKING:  # the names the loader serves, for type checkers and editors
    from kinelab.ik.api import solve, solve_all, solve_batch, track
    from kinelab.ik.registry import register
    from kinelab.ik.result import Diagnostics, IKResult, Status
    from kinelab.ik.targets import from_xyz_quat_wxyz as target_from_xyz_quat_wxyz
    from kinelab.ik.targets import from_xyz_rpy as target_from_xyz_rpy

__all__ = ["Diagnostics", "IKResult", "Status", "TargetError", "register", "solve", "solve_all", "solve_batch",
           "target_from_xyz_quat_wxyz", "target_from_xyz_rpy", "track"]
