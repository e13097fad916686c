"""The types of what kinelab's public calls take, named once (for readers, editors and type checkers).

Each alias says what a call accepts (a solver's options object is :data:`kinelab.ik.registry.SolverOptions`); the
call itself checks what it is given and raises a named :class:`~kinelab.errors.KinelabError` for anything else (a
wrong shape, NaN, a rotation that is not one), so a value outside these types gets an error, never a wrong answer.
Units: m and rad; poses in the chain's base frame. This layer sits above ``collision`` and ``dq`` (whose classes it
names) and below ``ik``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal, TypeAlias

from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy as np
    import pinocchio as pin

    from kinelab.collision.model import Collisions
    from kinelab.collision.obstacles import Environment
    from kinelab.dq import DualQuat

Configuration: TypeAlias = ArrayLike
"""A configuration: one value per joint of the chain [rad or m], in the order of ``robot.joint_names``."""

Target: TypeAlias = "pin.SE3 | DualQuat | ArrayLike"
"""One target: oMtarget as a ``pin.SE3`` or a unit :class:`~kinelab.dq.DualQuat` (base frame), or for task
"position" a point (three numbers [m])."""

Targets: TypeAlias = "Sequence[pin.SE3] | Sequence[DualQuat] | np.ndarray"
"""Many targets: a sequence of ``pin.SE3`` (or unit DualQuat), or an (N, 4, 4) array of homogeneous matrices."""

CollisionSpec: TypeAlias = "Literal['self'] | Environment | Collisions | None"
"""What a solve keeps clear of: None (nothing checked), "self" (the robot's own links), an
:class:`~kinelab.collision.Environment` of obstacles, or :class:`~kinelab.collision.Collisions` (both, a margin)."""

__all__ = ["CollisionSpec", "Configuration", "Target", "Targets"]
