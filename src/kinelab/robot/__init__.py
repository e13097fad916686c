"""The robot: the whole model of a file (:class:`Robot`), and the chains cut from it (:class:`Chain`).

- :mod:`~kinelab.robot.build`: every decision of a build (file, xacro, MJCF, SRDF, mimic, lock, re-root).
- :mod:`~kinelab.robot.tree`: :class:`Robot`, the whole model (frames, FK, Jacobians, centre of mass).
- :mod:`~kinelab.robot.space`: its joint space (q ↔ limits, sampling, integrate and difference).
- :mod:`~kinelab.robot.chain`: :class:`Chain`, a base → tool view with one number per joint.
- :mod:`~kinelab.robot.loading`: :func:`load`, a registered name or a file → a chain or the whole robot.
- :mod:`~kinelab.robot.joints`: the joint records; :mod:`~kinelab.robot.catalog`: the registered names.
- :mod:`~kinelab.robot.meshes`: mesh paths for the viewer (kinematics never read meshes).
"""

from typing import TYPE_CHECKING

from kinelab.lazy import loader

# the models (and with them Pinocchio) load on first use: the catalog's names alone need neither
__getattr__ = loader(__name__, globals(), {
    "LIMIT_SLACK": ("kinelab.robot.space", "LIMIT_SLACK"), "Joint": ("kinelab.robot.joints", "Joint"),
    "Mimic": ("kinelab.robot.joints", "Mimic"), "Chain": ("kinelab.robot.chain", "Chain"),
    "Robot": ("kinelab.robot.tree", "Robot"), "load": ("kinelab.robot.loading", "load")})

if TYPE_CHECKING:
    from kinelab.robot.chain import Chain
    from kinelab.robot.joints import Joint, Mimic
    from kinelab.robot.loading import load
    from kinelab.robot.space import LIMIT_SLACK
    from kinelab.robot.tree import Robot

__all__ = ["LIMIT_SLACK", "Chain", "Joint", "Mimic", "Robot", "load"]
