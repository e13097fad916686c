"""Where a chain starts and how it is shown when the user gives no configuration: well conditioned, not the
stretched, singular all-zero pose (a UR5's middle of its limits is all zeros: flat on the floor, rank 5 of 6)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from kinelab.robot.space import spread_points

if TYPE_CHECKING:
    from kinelab.robot import Chain  # the package (chain.py imports this module)

NEAR_SINGULAR = 1e-2  # σ_min/σ_max below this: near a singular configuration (kinelab.analysis.singular's)
FLOOR_TOL = 1e-9  # [m] a frame this far below the base plane still counts as on it


def conditioning(robot: Chain, q: np.ndarray) -> float:
    """σ_min/σ_max of the tool Jacobian at q (local world-aligned, linear rows divided by the characteristic
    length; σ_min the min(n, 6)-th singular value): 0 at a singular configuration, 1 at an isotropic one."""
    J = robot.jacobian_local_world_aligned(q)
    J[:3] /= robot.characteristic_length()
    s = np.linalg.svd(J, compute_uv=False)
    return float(s[min(robot.n, 6) - 1] / s[0]) if s[0] > 0 else 0.0


def above_floor(robot: Chain, q: np.ndarray) -> bool:
    """Whether every frame of the chain (its links', joints' and tool's origins) is on or above the base frame's
    xy-plane at q: the floor the robot stands on, which a start pose must not put a link through."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.to_pin_q(q))
    return all(M.translation[2] >= -FLOOR_TOL for M in data.oMf)


def best_conditioned(robot: Chain) -> np.ndarray:
    """The best-conditioned of 64 evenly spread configurations in the middle half of each joint's range (largest
    :func:`conditioning`) among those with every frame above the floor (:func:`above_floor`; all of them where
    none is) [rad, m]: the display pose of a robot without a registered one."""
    lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    mid, half = (lo + hi) / 2, np.minimum((hi - lo) / 4, np.pi / 2)
    best, best_score = robot.neutral(), (False, -1.0)
    for u in spread_points(64, robot.n):
        q = mid + u * half
        score = (above_floor(robot, q), conditioning(robot, q))
        if score > best_score:
            best, best_score = q, score
    return best


def reference_of(robot: Chain) -> tuple[np.ndarray, str]:
    """:meth:`kinelab.Chain.reference_q`: the configuration a command starts from when given none [rad, m], and
    where it comes from in words."""
    if robot.srdf is not None:
        for name in ("home", "ready"):
            if name in robot.srdf.states:
                return robot.named_q(name), f"the SRDF's {name!r} configuration"
    lower, upper = robot.sample_bounds
    middle = 0.5 * (lower + upper)
    if conditioning(robot, middle) >= NEAR_SINGULAR and above_floor(robot, middle):
        return middle, "the middle of the joint limits"
    display = robot.display_q()
    where = " above the floor" if above_floor(robot, display) else ""
    return display, (f"a well-conditioned configuration{where} (the middle of the joint limits is near a singular "
                     "one, or puts a link below the base)")
