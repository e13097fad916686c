"""A singularity map: σ_min/σ_max and rank over joint-space samples (seeded uniform, or a stratified grid),
by the engine ``kinelab singular --sweep`` uses (:func:`kinelab.analysis.families.sigma_ratio_batch`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinelab.analysis import families
from kinelab.analysis.singular import RANK_RTOL
from kinelab.errors import KinelabError
from kinelab.ik.request import check_seed
from kinelab.robot import Chain


@dataclass(frozen=True)
class SingularityMap:
    """Samples and their conditioning. ``q`` (S, n) [rad or m]; ``sigma_ratio`` (S,) σ_min/σ_max of the
    scaled Jacobian; ``rank_deficient`` (S,) below the rank threshold."""

    q: np.ndarray
    sigma_ratio: np.ndarray

    @property
    def rank_deficient(self) -> np.ndarray:
        """Per sample: the scaled Jacobian lost rank."""
        return self.sigma_ratio <= RANK_RTOL


def singularity(robot: Chain, samples: int = 5000, seed: int = 0, method: str = "random",
                progress: bool | None = None) -> SingularityMap:
    """σ_min/σ_max over ``samples`` configurations within the limits.

    Raises:
        KinelabError: no sample, a sweep too large for memory, or an unknown method.
    """
    check_seed(seed)
    families.check_sweep_size(robot, samples)
    if method not in ("random", "grid"):
        raise KinelabError(f"unknown sampling {method!r}; use 'random' or 'grid'")
    rng = np.random.default_rng(seed)
    lower, upper, _ = families.sweep_limits(robot)
    qs = rng.uniform(lower, upper, size=(samples, robot.n)) if method == "random" else families.grid(robot, samples,
                                                                                                      rng)
    return SingularityMap(qs, families.sigma_ratio_batch(robot, qs, progress=progress))
