"""Singularities of any chain: SVD rank, manipulability, lost directions, sweeps and families.

Units. A tool twist mixes m/s and rad/s, so the singular values of a raw Jacobian depend on the unit of
length. kinelab divides the linear rows by the chain's characteristic length L (the mean spacing of its
joint origins, :meth:`Chain.characteristic_length`): the scaled Jacobian maps joint rates to
(v/L, ω), both in 1/s, and its singular values, condition number and manipulability are
dimensionless (for revolute chains; a prismatic column carries 1/L). The rank is the number of singular
values above ``RANK_RTOL``·σ_max. The rank itself does not depend on L or on the frame: only the
directions reported do.

Frame. Directions are given in the base frame at the tool point (LOCAL_WORLD_ALIGNED): a lost direction
is a tool twist (v [unit vector share], ω) that no joint motion produces; a null motion is a joint
velocity that moves nothing.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from kinelab.errors import OptionError
from kinelab.robot import Chain
from kinelab.robot.poses import NEAR_SINGULAR as NEAR_SINGULAR  # σ_min/σ_max below: near-singular (one threshold)
from kinelab.typing import Configuration


def sigma_words(ratio: float) -> str:
    """σ_min/σ_max in the words every page and message uses, by the one threshold NEAR_SINGULAR."""
    return "near-singular" if ratio < NEAR_SINGULAR else "away from a singular configuration"


RANK_RTOL = 1e-6  # singular values below RANK_RTOL × σ_max count as zero


@dataclass
class Analysis:
    """The singularity picture of a robot at q (see the module docstring for units and frames)."""

    q: np.ndarray
    singular_values: np.ndarray
    rank: int
    full_rank: int
    manipulability: float  # Yoshikawa √det(J Jᵀ) (n ≥ 6) or √det(Jᵀ J) (n < 6), scaled J
    condition: float  # σ_max/σ_min (inf when singular)
    length: float  # L [m]
    lost_directions: list[LostDirection] = field(default_factory=list)
    null_motions: list[np.ndarray] = field(default_factory=list)

    @property
    def singular(self) -> bool:
        """True when the rank is below the full rank."""
        return self.rank < self.full_rank

    @property
    def sigma_ratio(self) -> float:
        """σ_min/σ_max of the scaled Jacobian, σ_min the full rank's last singular value (0 when singular)."""
        top = float(self.singular_values[0]) if len(self.singular_values) else 0.0
        return float(self.singular_values[self.full_rank - 1]) / top if top > 0 else 0.0

    @property
    def near_singular(self) -> bool:
        """σ_min/σ_max below NEAR_SINGULAR: what every page and message calls near-singular."""
        return self.sigma_ratio < NEAR_SINGULAR

    def to_dict(self) -> dict:
        """The JSON form (``kinelab singular --json``)."""
        return {
            "q": self.q.tolist(),
            "singular_values": self.singular_values.tolist(),
            "rank": self.rank,
            "full_rank": self.full_rank,
            "singular": self.singular,
            "sigma_ratio": self.sigma_ratio,
            "near_singular": self.near_singular,
            "manipulability": self.manipulability,
            "condition": self.condition if np.isfinite(self.condition) else None,
            "characteristic_length_m": self.length,
            "lost_directions": [d.to_dict() for d in self.lost_directions],
            "null_motions": [m.tolist() for m in self.null_motions],
        }


def scaled_jacobian(robot: Chain, q, length: float | None = None) -> np.ndarray:
    """6 × n LOCAL_WORLD_ALIGNED tool Jacobian with the linear rows divided by L."""
    L = length or robot.characteristic_length()
    J = robot.jacobian_local_world_aligned(q)
    J[:3] /= L
    return J


def conditioning_batch(J: np.ndarray, length: float) -> tuple[np.ndarray, np.ndarray]:
    """(manipulability, σ_min/σ_max) of a stack of (B, 6, n) LOCAL_WORLD_ALIGNED Jacobians once their linear
    rows are divided by ``length`` [m] (a copy is scaled): the product of the min(6, n) largest singular values
    (Yoshikawa's measure) and the ratio of the last of them to the first."""
    scaled = J.copy()
    scaled[:, :3] /= length
    s = np.linalg.svd(scaled, compute_uv=False)
    full = min(6, J.shape[2])
    return np.prod(s[:, :full], axis=1), s[:, full - 1] / s[:, 0]


def _rank(s: np.ndarray) -> int:
    return int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0


@dataclass(frozen=True)
class LostDirection:
    """A tool twist no joint motion produces (base axes at the tool point, scaled: (v/L, ω)).

    Attributes:
        twist: the unit scaled twist (6 numbers).
        translation_share: |v/L|² (0..1); rotation_share: |ω|² (the two add up to 1).
        translation_axis: unit direction of the translation part, if it is not negligible.
        rotation_axis: unit axis of the rotation part, if it is not negligible.
        sigma: the singular value of the direction (0 at an exact singularity).
    """

    twist: tuple[float, ...]
    translation_share: float
    rotation_share: float
    translation_axis: tuple[float, float, float] | None = None
    rotation_axis: tuple[float, float, float] | None = None
    sigma: float | None = None

    def to_dict(self) -> dict:
        """The JSON form (the documented fields; the axes only where present)."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items() if v is not None}


def describe_direction(u: np.ndarray, sigma: float | None = None) -> LostDirection:
    """A unit scaled twist (v/L, ω) in words: how much is translation, along which axis, rotation about which."""
    lin, ang = u[:3], u[3:]
    axes: list[tuple[float, float, float] | None] = []
    for part in (lin, ang):
        norm = np.linalg.norm(part)
        axes.append(tuple((part / norm).tolist()) if norm > 1e-6 else None)
    return LostDirection(tuple(u.tolist()), float(lin @ lin), float(ang @ ang), axes[0], axes[1], sigma)


LENGTHS = (1e-6, 1e6)  # [m] the scale lengths analyze accepts


def checked_length(length: object) -> float:
    """``length`` [m] as a float within :data:`LENGTHS`.

    Raises:
        OptionError: anything else (named, with the bounds).
    """
    ok = isinstance(length, int | float | np.number) and not isinstance(length, bool) \
        and LENGTHS[0] <= float(length) <= LENGTHS[1]  # NaN fails both comparisons
    if not ok:
        raise OptionError("length", length, f"a length in [{LENGTHS[0]:g}, {LENGTHS[1]:g}] m, or None (the robot's "
                          "characteristic length)")
    return float(length)  # type: ignore[arg-type]


def analyze(robot: Chain, q: Configuration, length: float | None = None) -> Analysis:
    """SVD of the scaled tool Jacobian at q: rank, σ, manipulability, condition, lost and null directions.

    Args:
        robot: the robot.
        q: the configuration [rad or m].
        length: the length [m] the Jacobian's linear rows are divided by (None: the robot's characteristic length),
            within [1e-6, 1e6] m: beyond those the rows of one kind swamp the other's in double precision.

    Raises:
        ConfigurationError: a bad q. OptionError: a length that is not a number within those bounds.
    """
    q = robot.check_q(q)
    L = robot.characteristic_length() if length is None else checked_length(length)
    J = scaled_jacobian(robot, q, L)
    U, s, Vt = np.linalg.svd(J)
    full = min(6, robot.n)
    rank = _rank(s)
    JJ = J @ J.T if robot.n >= 6 else J.T @ J
    manip = float(np.sqrt(max(np.linalg.det(JJ), 0.0)))
    condition = float(s[0] / s[full - 1]) if s[full - 1] > RANK_RTOL * s[0] else float("inf")
    # an arm with fewer than six joints has 6 − n directions it can never produce (σ = 0 by construction)
    lost = [describe_direction(U[:, i], float(s[i]) if i < s.size else 0.0) for i in range(rank, 6)]
    null = [Vt[i] for i in range(rank, robot.n)]
    return Analysis(q, s, rank, full, manip, condition, L, lost, null)
