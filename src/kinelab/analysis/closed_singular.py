"""Singularities of a closed chain, by SVD as a serial arm's (:mod:`kinelab.analysis.singular`), in Gosselin and
Angeles' two types.

On the loops, the velocities obey ``J_a v_a + J_p v_p = 0`` (the closure Jacobian split into the actuated joints'
columns and the passive joints'), and the output — an output frame's position — moves by ``ẋ = X_a v_a + X_p v_p``.

- **Type II (parallel)**: ``J_p`` loses rank: with the motors held, the passive joints (and with them the output)
  can still move, or cannot follow — the mechanism gains or loses a freedom the motors do not control. Measured
  by ``σ_II``, the ``r``-th singular value of ``J_p`` where ``r`` is its rank at a regular configuration (idle
  motions, a forearm's spin, do not count: they move neither loop nor output).
- **Type I (serial)**: the motors' map to the output, ``G = X_a − X_p J_p⁺ J_a``, loses rank: the output cannot
  move along some direction whatever the motors do (a leg stretched out, a four-bar's rocker at its dead point).
  Measured by ``σ_I``, the smallest singular value of ``G`` (rows: the output's components that move).

Both are 0 at a singular configuration and grow away from it; lengths in m, angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from kinelab.errors import OptionError
from kinelab.robot.assembly import actuated_indices, passive_indices

if TYPE_CHECKING:
    from kinelab.robot.tree import Robot

SINGULAR = 1e-6  # [m/rad or dimensionless] a σ at or below this is singular
RANK_SAMPLES = 20  # random assemblies the regular ranks are taken from


@dataclass(frozen=True)
class ClosedSingularity:
    """The two measures at one assembled configuration (see the module's docstring).

    Attributes:
        sigma_serial: σ_I [m/rad for a position output]; sigma_parallel: σ_II (of the closure Jacobian's passive
            columns, [m/rad, or 1 for rotation rows]).
        kind: "type I", "type II", "both" or "regular" (each σ against :data:`SINGULAR`).
    """

    sigma_serial: float
    sigma_parallel: float

    @property
    def kind(self) -> str:
        """Which type the configuration is singular of."""
        serial, parallel = self.sigma_serial <= SINGULAR, self.sigma_parallel <= SINGULAR
        return "both" if serial and parallel else "type I" if serial else "type II" if parallel else "regular"


def regular_ranks(robot: Robot, output: str) -> tuple[int, int]:
    """(rank of J_p, rank of the output's moving rows) at regular configurations: the largest over RANK_SAMPLES
    seeded assemblies (a singular one only lowers a rank)."""
    key = f"closed ranks {output}"
    return robot.derived(key, lambda r: _ranks(r, output))


def _ranks(robot: Robot, output: str) -> tuple[int, int]:
    rng = np.random.default_rng(0)
    home = robot.standing()
    actuated = actuated_indices(robot)
    ranks = (0, 0)
    for _ in range(RANK_SAMPLES):
        q = home.copy()
        q[actuated[0]] = robot.random_q(rng)[actuated[0]]
        try:
            q = robot.assemble(q)
        except Exception:  # noqa: BLE001 - an AssemblyError: no assembly there, another sample
            continue
        Jp, G = _maps(robot, q, output)
        ranks = (max(ranks[0], _rank(Jp)), max(ranks[1], _rank(G)))
    return ranks


def analyze(robot: Robot, q: np.ndarray, output: str) -> ClosedSingularity:
    """σ_I and σ_II at an assembled q, the output frame's position the output.

    Raises:
        OptionError: a robot without loops or without actuated joints.
    """
    if not robot.closures or not robot.actuated:
        raise OptionError("robot", robot.name, "a robot with loops and actuated joints declared")
    rank_p, rank_out = regular_ranks(robot, output)
    Jp, G = _maps(robot, q, output)
    sp = np.linalg.svd(Jp, compute_uv=False)
    sg = np.linalg.svd(G, compute_uv=False)
    parallel = float(sp[rank_p - 1]) if 0 < rank_p <= sp.size else 0.0
    serial = float(sg[rank_out - 1]) if 0 < rank_out <= sg.size else 0.0
    return ClosedSingularity(serial, parallel)


def _maps(robot: Robot, q: np.ndarray, output: str) -> tuple[np.ndarray, np.ndarray]:
    """(J_p, G) at q: the closure Jacobian's passive columns, and the motors' map to the output's position."""
    Jp = robot.closure_jacobian(q)[:, passive_indices(robot, robot.actuated)]
    return Jp, robot.actuated_jacobian(q, output)[:3]


def _rank(M: np.ndarray) -> int:
    s = np.linalg.svd(M, compute_uv=False)
    return int((s > 1e-8 * max(1.0, float(s[0]) if s.size else 1.0)).sum())
