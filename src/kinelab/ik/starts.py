"""A robot's start table: configurations spread over its joint space, indexed by their tool poses, so that a
target's first start is the stored configuration whose tool pose is nearest it.

A random start leaves the solver to cross the joint space before it converges; a start whose tool pose is
already near the target leaves it only the last steps. The table holds SIZE configurations drawn uniformly
within the limits from a fixed seed (the same table on every machine), their tool poses by the judge's FK, and
a k-d tree over (position / L, WEIGHT · R), L the robot's characteristic length and R the tool rotation's nine
entries (the Frobenius distance between rotations is 2√2·sin(θ/2) for a turn θ between them). It is built once
per Chain, on first use, in milliseconds; its cost and its effect per arm are in docs/bench/throughput-2026-12-04.md.
Nothing about an answer's judgement changes: a start is only where the solver begins.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from kinelab.robot import Chain

if TYPE_CHECKING:  # SciPy's spatial module costs 0.3 s to import: it loads when a table is first built
    from scipy.spatial import cKDTree

SIZE = 8192  # configurations in a table
SEED = 20261204  # the table's draws: the same table everywhere
WEIGHT = 0.5  # a rotation's entries against position / L in the look-up


@dataclass(frozen=True, eq=False)
class StartTable:
    """Configurations ``q`` (SIZE, n) [rad or m] and a tree over their tool poses' features."""

    q: np.ndarray
    tree: cKDTree
    length: float

    def features(self, H: np.ndarray) -> np.ndarray:
        """The look-up features of tool poses H (B, 4, 4), base frame: (B, 12)."""
        return np.hstack([H[:, :3, 3] / self.length, WEIGHT * H[:, :3, :3].reshape(len(H), 9)])

    def nearest(self, H: np.ndarray) -> np.ndarray:
        """The stored configuration (B, n) whose tool pose is nearest each target of H (B, 4, 4); a target far beyond
        the table (1e154 m: its squared distance overflows) gets the nearest to its direction."""
        _, index = self.tree.query(np.clip(self.features(H), -1e6, 1e6), k=1)
        return np.array(self.q[index], dtype=float)

    @property
    def nbytes(self) -> int:
        """The table's memory [bytes]: its configurations, their features and the tree's index."""
        return int(self.q.nbytes + self.tree.data.nbytes + self.tree.indices.nbytes)


def start_table(robot: Chain) -> StartTable:
    """The robot's start table, built on first use and kept on the Chain."""
    return robot.derived("start table", _build)


def _build(robot: Chain) -> StartTable:
    q = robot.random_qs(SIZE, np.random.default_rng(SEED))
    length = max(robot.characteristic_length(), 1e-3)
    H = robot.fk_batch(q)
    table = StartTable(q, cKDTree(np.zeros((1, 12))), length)
    return StartTable(q, cKDTree(table.features(H)), length)
