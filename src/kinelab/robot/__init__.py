"""The robot: a model file (or an in-memory ``pin.Model``) reduced to its base → tool chain.

- :mod:`~kinelab.robot.build`: every decision of a build (file, xacro, MJCF, SRDF, mimic, lock, re-root).
- :mod:`~kinelab.robot.model`: :class:`Robot` (model, joint space, kinematics) and :func:`load`.
- :mod:`~kinelab.robot.joints`: the joint records; :mod:`~kinelab.robot.catalog`: the registered names.
- :mod:`~kinelab.robot.meshes`: mesh paths for the viewer (kinematics never read meshes).
"""

from typing import TYPE_CHECKING

from kinelab.lazy import loader

# the model (and with it Pinocchio) loads on first use: the catalog's names alone need neither
__getattr__ = loader(__name__, globals(), {name: ("kinelab.robot.model", name)
                                           for name in ("LIMIT_SLACK", "Joint", "Mimic", "Robot", "load")})

if TYPE_CHECKING:
    from kinelab.robot.model import LIMIT_SLACK, Joint, Mimic, Robot, load

__all__ = ["LIMIT_SLACK", "Joint", "Mimic", "Robot", "load"]
