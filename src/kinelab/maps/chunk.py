"""One chunk of a reachability map: a pure function of (robot, spec, chunk index), and the map's spec.

In every voxel the map asks for K tool poses (the voxel's centre, K orientations spread over SO(3), or K
tool-axis directions for task "axis"), solves them with :func:`kinelab.solve_batch` (every answer checked
by Pinocchio), and keeps per voxel the reachability index (the share of the K poses reached), the best
manipulability among the answers and the smallest σ_min/σ_max. A chunk's seeds are fixed by its index and
no wall-clock budget cuts it, so the map is the same whatever runs it and in whatever order.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from kinelab.analysis.singular import conditioning_batch
from kinelab.errors import KinelabError
from kinelab.ik.api import solve_batch
from kinelab.ik.request import check_seed
from kinelab.maps import grid
from kinelab.robot import Robot

MAX_TARGETS = 2_000_000  # a map asking for more needs force=True (about an hour per million on one core)


@dataclass(frozen=True)
class MapSpec:
    """What a reachability map computes (stored with it; a resumed run must ask for the same).

    Attributes:
        voxel: voxel side [m].
        orientations: target orientations per voxel (tool-axis directions for task "axis").
        task: "pose" or "axis" (the tool z axis; the roll free).
        tol_pos: [m]; tol_rot: [rad].
        restarts: random restarts per target after its first attempt.
        seed: base seed; chunk c's targets use seed + c · chunk_voxels · orientations + row.
        chunk_voxels: voxels per chunk (the unit of work and of storage).
    """

    voxel: float = 0.1
    orientations: int = 16
    task: str = "pose"
    tol_pos: float = 1e-6
    tol_rot: float = 1e-6
    restarts: int = 20
    seed: int = 0
    chunk_voxels: int = 64

    def check(self) -> None:
        """Raises KinelabError naming a bad field and what is valid."""
        if isinstance(self.orientations, bool) or not (isinstance(self.orientations, int) and self.orientations >= 1):
            raise KinelabError(f"orientations must be an integer ≥ 1, got {self.orientations!r}")
        if self.task not in ("pose", "axis"):
            raise KinelabError(f"a reachability map takes task 'pose' or 'axis', got {self.task!r}")
        if isinstance(self.chunk_voxels, bool) or not (isinstance(self.chunk_voxels, int) and self.chunk_voxels >= 1):
            raise KinelabError(f"chunk_voxels must be an integer ≥ 1, got {self.chunk_voxels!r}")
        if isinstance(self.voxel, bool) or not (isinstance(self.voxel, int | float) and np.isfinite(self.voxel)
                                                and self.voxel > 0):
            raise KinelabError(f"the voxel side must be a positive length in metres, got {self.voxel!r}")
        check_seed(self.seed)
        check_seed(self.restarts, "restarts")

    def to_dict(self) -> dict:
        """The JSON form stored with the map."""
        return asdict(self)


def targets_of(centres: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """(V·K, 4, 4) homogeneous targets: every rotation at every centre (voxel-major)."""
    V, K = len(centres), len(rotations)
    H = np.zeros((V * K, 4, 4))
    H[:, :3, :3] = np.tile(rotations, (V, 1, 1))
    H[:, :3, 3] = np.repeat(centres, K, axis=0)
    H[:, 3, 3] = 1.0
    return H


def compute_chunk(robot: Robot, spec: MapSpec, centres: np.ndarray, index: int) -> dict[str, np.ndarray]:
    """The map's values for chunk ``index`` (voxels index·chunk_voxels onwards): reachability (share of the
    orientations reached), best manipulability (Yoshikawa, of the Jacobian with linear rows / L; 0 where
    nothing is reached) and smallest σ_min/σ_max (1 where nothing is reached)."""
    lo = index * spec.chunk_voxels
    chunk = centres[lo:lo + spec.chunk_voxels]
    R = grid.axis_rotations(spec.orientations) if spec.task == "axis" else grid.rotations(spec.orientations)
    res = solve_batch(robot, targets_of(chunk, R), seed=spec.seed + lo * spec.orientations, task=spec.task,
                      tol_pos=spec.tol_pos, tol_rot=spec.tol_rot, max_restarts=spec.restarts)
    ok = res.success.reshape(len(chunk), spec.orientations)
    manip = np.zeros(len(chunk) * spec.orientations)
    ratio = np.ones(len(chunk) * spec.orientations)
    if res.success.any():
        J = robot.jacobian_batch(res.q[res.success], frame="local_world_aligned")
        manip[res.success], ratio[res.success] = conditioning_batch(J, robot.characteristic_length())
    return {"reachability": ok.mean(axis=1), "manipulability": manip.reshape(ok.shape).max(axis=1),
            "sigma_ratio": ratio.reshape(ok.shape).min(axis=1)}


