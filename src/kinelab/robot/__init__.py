"""The robot: a model file (or an in-memory ``pin.Model``) reduced to its base → tool chain.

- :mod:`~kinelab.robot.build`: every decision of a build (file, xacro, MJCF, SRDF, mimic, lock, re-root).
- :mod:`~kinelab.robot.model`: :class:`Robot` (model, joint space, kinematics) and :func:`load`.
- :mod:`~kinelab.robot.joints`: the joint records; :mod:`~kinelab.robot.catalog`: the registered names.
- :mod:`~kinelab.robot.meshes`: mesh paths for the viewer (kinematics never read meshes).
"""

from kinelab.robot.model import LIMIT_SLACK, Joint, Mimic, Robot, load

__all__ = ["LIMIT_SLACK", "Joint", "Mimic", "Robot", "load"]
