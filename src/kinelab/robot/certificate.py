"""The judge of kinelab's answers: the compiled chain FK, certified equal to Pinocchio's on each robot.

A Chain's chain (base → tool, joints in series) is packed into plain arrays and run through the compiled FK of
:mod:`kinelab.core` (built when kinelab is installed). Before it judges anything, it is compared with Pinocchio's
FK on that robot at fixed configurations: evenly spread ones over the joints' ranges and, for every joint, its lower
and its upper limit. It is *certified* when every tool pose agrees within :data:`TOLERANCE` (m, and rad of the
rotation between them); the certificate is kept on the Chain (``robot.fk_certificate``). A chain that is not a
plain series of 1-DoF joints (a mimic joint) or that fails the comparison is judged by Pinocchio's FK, and its
certificate says why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from kinelab import lazy
from kinelab.robot.space import spread_points

if TYPE_CHECKING:
    from kinelab.core import _chain
else:
    _chain = lazy.module("kinelab.core._chain", globals())

Chain = Any  # a kinelab.Chain (the model module imports this one, so the type is not imported back)

TOLERANCE = 1e-12  # [m] and [rad]: the compiled FK and Pinocchio's agree to rounding (measured: ≤ 6e-15 on ERA)
RANDOM_CONFIGURATIONS = 64  # spread ones, and two per joint at its limits


@dataclass(frozen=True)
class ChainArrays:
    """A serial chain as the compiled FK reads it (frames and units as in :mod:`kinelab.core._chain`)."""

    placement_R: np.ndarray  # (n, 3, 3) joint i's frame in joint i−1's, at q = 0
    placement_t: np.ndarray  # (n, 3) [m]
    axis: np.ndarray  # (n, 3) unit joint axes in the joints' own frames
    kind: np.ndarray  # (n,) int64: 1 prismatic, 0 revolute or continuous
    tool_R: np.ndarray  # (3, 3) the tool frame in the last joint's frame
    tool_t: np.ndarray  # (3,) [m]

    def fk_batch(self, Q: np.ndarray) -> np.ndarray:
        """oMtool of every row of Q (B × n, rad or m, already checked): (B, 4, 4)."""
        out = np.empty((Q.shape[0], 4, 4))
        _chain.fk_batch(self.placement_R, self.placement_t, self.axis, self.kind, self.tool_R, self.tool_t,
                        np.ascontiguousarray(Q, dtype=float), out)
        return out

    def jacobian_batch(self, Q: np.ndarray) -> np.ndarray:
        """The tool Jacobian of every row of Q (B × n, already checked), base axes at the tool origin
        (LOCAL_WORLD_ALIGNED), rows [v; ω]: (B, 6, n)."""
        out = np.empty((Q.shape[0], 6, self.kind.shape[0]))
        _chain.jacobian_batch(self.placement_R, self.placement_t, self.axis, self.kind, self.tool_R, self.tool_t,
                              np.ascontiguousarray(Q, dtype=float), out)
        return out

    def null_drift(self, prev: np.ndarray, Q: np.ndarray, dx: np.ndarray, rows: tuple[int, ...]
                   ) -> tuple[np.ndarray, np.ndarray]:
        """(drift (K, n), own (K,)) of :func:`kinelab.core._chain.null_drift`: each sample's joint motion along the
        task's null space at prev[k] and the least-norm step its target motion dx[k] asks for [rad or m]."""
        drift, own = np.empty(Q.shape), np.empty(Q.shape[0])
        _chain.null_drift(self.placement_R, self.placement_t, self.axis, self.kind, self.tool_R, self.tool_t,
                          np.ascontiguousarray(prev, dtype=float), np.ascontiguousarray(Q, dtype=float),
                          np.ascontiguousarray(dx, dtype=float), np.asarray(rows, dtype=np.int64), drift, own)
        return drift, own

    def judge(self) -> Any:
        """The compiled verdict on one answer over these arrays (:class:`kinelab.core._chain.Judge`)."""
        return _chain.Judge(self.placement_R, self.placement_t, self.axis, self.kind, self.tool_R, self.tool_t)


@dataclass(frozen=True)
class FKCertificate:
    """How a robot's answers are judged: the compiled FK when ``certified``, else Pinocchio's FK.

    Attributes:
        certified: the compiled FK agreed with Pinocchio's within TOLERANCE at every configuration.
        configurations: how many were compared (0 when the chain cannot be packed).
        max_position_error: the largest tool position difference [m].
        max_rotation_error: the largest tool rotation difference [rad].
        reason: why it is not certified ("" when it is).
    """

    certified: bool
    configurations: int
    max_position_error: float
    max_rotation_error: float
    reason: str = ""

    @property
    def judge(self) -> str:
        """"compiled FK (certified)" or "Pinocchio FK"."""
        return "compiled FK (certified)" if self.certified else "Pinocchio FK"

    def __str__(self) -> str:
        if self.certified:
            return (f"compiled FK, certified against Pinocchio's at {self.configurations} configurations (largest "
                    f"difference {self.max_position_error:.1e} m, {self.max_rotation_error:.1e} rad)")
        return f"Pinocchio FK (the compiled FK is not certified: {self.reason})"


def chain_arrays(robot: Chain) -> ChainArrays | str:
    """The robot's chain as arrays, or the reason it is not a plain series of 1-DoF joints."""
    why = _not_packable(robot)
    if why:
        return why
    model = robot.model
    tool = model.frames[robot.tool_frame_id]
    joints = range(1, model.njoints)
    packed = (np.array([model.jointPlacements[j].rotation for j in joints]).reshape(-1, 3, 3),
              np.array([model.jointPlacements[j].translation for j in joints]).reshape(-1, 3),
              np.array([j.axis_local for j in robot.joints], dtype=float).reshape(-1, 3),
              np.array([k == "prismatic" for k in robot.joint_kinds], dtype=np.int64),
              np.array(tool.placement.rotation), np.array(tool.placement.translation))
    return ChainArrays(*(np.ascontiguousarray(a) for a in packed))  # the compiled FK reads rows in C order


def _not_packable(robot: Chain) -> str:
    """Why the robot's chain is not a plain series of 1-DoF joints ending at the tool ("" when it is)."""
    model = robot.model
    if robot.mimics:
        return f"joint {next(iter(robot.mimics))!r} mimics another (coupled joints)"
    if robot.nq != robot.n + robot.joint_kinds.count("continuous"):  # a continuous joint is (cos, sin) in Pinocchio
        return "a joint with more than one coordinate"
    if any(model.parents[j] != j - 1 for j in range(1, model.njoints)):
        return "the joints are not in series"
    if model.frames[robot.tool_frame_id].parentJoint != model.njoints - 1:
        return f"the tool frame {robot.tool!r} is not carried by the last joint"
    return ""


def certify(robot: Chain) -> FKCertificate:
    """Compare the compiled FK with Pinocchio's on ``robot`` (see the module docstring).

    Returns:
        The certificate; never raises for a chain it cannot pack (the certificate says why).
    """
    arrays = chain_arrays(robot)
    if isinstance(arrays, str):
        return FKCertificate(False, 0, math.nan, math.nan, arrays)
    Q = _configurations(robot)
    compiled = arrays.fk_batch(Q)
    dp, dr = 0.0, 0.0
    for q, H in zip(Q, compiled, strict=True):
        reference = robot.fk(q)
        dp = max(dp, float(np.linalg.norm(H[:3, 3] - reference.translation)))
        dr = max(dr, float(np.linalg.norm(H[:3, :3] - reference.rotation) / math.sqrt(2.0)))  # ≈ the angle
    if not (dp <= TOLERANCE and dr <= TOLERANCE):
        return FKCertificate(False, len(Q), dp, dr, f"it differs from Pinocchio's by {dp:.1e} m, {dr:.1e} rad")
    return FKCertificate(True, len(Q), dp, dr)


def _configurations(robot: Chain) -> np.ndarray:
    """Evenly spread configurations over the sampling bounds, then each joint at its lower and its upper limit (the
    others spread)."""
    lower, upper = robot.sample_bounds
    mid, half = lower / 2 + upper / 2, upper / 2 - lower / 2  # halves first: ±1e308 m limits do not overflow
    Q = mid + spread_points(RANDOM_CONFIGURATIONS + 2 * robot.n, robot.n) * half
    for i in range(robot.n):
        Q[RANDOM_CONFIGURATIONS + 2 * i, i] = lower[i]
        Q[RANDOM_CONFIGURATIONS + 2 * i + 1, i] = upper[i]
    return Q
