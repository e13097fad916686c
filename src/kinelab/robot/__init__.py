"""The robot: a URDF loaded into Pinocchio and reduced to its base → tool chain.

- :mod:`~kinelab.robot.model`: :class:`Robot` and :func:`load`.
- :mod:`~kinelab.robot.catalog`: the registered robot names.
- :mod:`~kinelab.robot.meshes`: mesh paths for the viewer (kinematics never read meshes).
"""

from kinelab.robot.model import LIMIT_SLACK, Joint, Robot, load

__all__ = ["LIMIT_SLACK", "Joint", "Robot", "load"]
