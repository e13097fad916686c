"""One chunk of a reachability map: a pure function of (robot, spec, chunk index), and the map's spec.

In every voxel the map asks for K tool poses (the voxel's centre, K orientations spread over SO(3), or K
tool-axis directions for task "axis") and keeps per voxel the reachability index (the share of the K poses
reached), the best manipulability among the answers and the smallest σ_min/σ_max. Where the arm has a
closed form (:mod:`kinelab.ik.analytic`) and the task is "pose", every branch of every pose is computed
(:func:`~kinelab.ik.analytic.batch.all_branches_batch`), the voxel also keeps the mean number of branches
within the limits, and a pose's σ ratio is its best branch's; elsewhere :func:`kinelab.solve_batch` finds one
answer per pose (the branch count is then unknown: NaN). Every answer is checked by Pinocchio. A chunk's
seeds are fixed by its index and no wall-clock budget cuts it, so the map is the same whatever runs it and in
whatever order.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass

import numpy as np

from kinelab.analysis.singular import conditioning_batch
from kinelab.collision.model import CollisionModel, Collisions, collision_model
from kinelab.errors import KinelabError
from kinelab.ik.analytic.batch import BranchBatch, all_branches_batch
from kinelab.ik.analytic.classify import classify
from kinelab.ik.api import solve_batch
from kinelab.ik.request import check_seed
from kinelab.maps import grid
from kinelab.robot import Chain
from kinelab.values import is_real, is_whole

METHODS = ("auto", "numeric")
MAX_TARGETS = 2_000_000  # a map asking for more needs force=True (about an hour per million on one core)


MAX_ORIENTATIONS = 4096  # target orientations per voxel (a map's targets are voxels × this)


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
        method: "auto" (every branch in closed form where the arm has one and the task is "pose", else the
            numeric batch) or "numeric" (the FRDM batch everywhere).
        collisions: None, or what answers must not collide with (:class:`kinelab.Collisions`): a pose counts
            as reached only through a clear answer — any clear branch in closed form; the batch's one answer
            otherwise (a pose whose answer collides counts as unreached even if another branch is clear).
    """

    voxel: float = 0.1
    orientations: int = 16
    task: str = "pose"
    tol_pos: float = 1e-6
    tol_rot: float = 1e-6
    restarts: int = 20
    seed: int = 0
    chunk_voxels: int = 64
    method: str = "auto"
    collisions: Collisions | None = None

    def check(self) -> None:
        """Raises KinelabError naming a bad field and what is valid."""
        if not is_whole(self.orientations, 1, MAX_ORIENTATIONS):
            raise KinelabError(f"orientations must be an integer ≥ 1 and at most {MAX_ORIENTATIONS}, got "
                               f"{self.orientations!r}")
        if self.task not in ("pose", "axis"):
            raise KinelabError(f"a reachability map takes task 'pose' or 'axis', got {self.task!r}")
        if not is_whole(self.chunk_voxels, 1):
            raise KinelabError(f"chunk_voxels must be an integer ≥ 1, got {self.chunk_voxels!r}")
        if not is_real(self.voxel, 0, above=True):
            raise KinelabError(f"the voxel side must be a positive length in metres, got {self.voxel!r}")
        if self.collisions is not None and not isinstance(self.collisions, Collisions):
            raise KinelabError(f"a map's collisions is a kinelab.Collisions or None, got {self.collisions!r}")
        if self.method not in METHODS:
            raise KinelabError(f"a reachability map's method is one of {', '.join(METHODS)}, got {self.method!r}")
        check_seed(self.seed)
        check_seed(self.restarts, "restarts")

    def closed_form(self, robot: Chain) -> bool:
        """True when this map of ``robot`` is computed with every branch in closed form."""
        return self.method == "auto" and self.task == "pose" and classify(robot).arm is not None

    def to_dict(self) -> dict:
        """The JSON form stored with the map (tuples as lists, as the store gives them back)."""
        return dict(json.loads(json.dumps(asdict(self), default=_plain)))


def _plain(value: object) -> object:
    """A numpy number as the Python number JSON takes (a seed given as np.int64, say)."""
    if isinstance(value, np.integer | np.floating | np.bool_):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not stored with a map")


def targets_of(centres: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """(V·K, 4, 4) homogeneous targets: every rotation at every centre (voxel-major)."""
    V, K = len(centres), len(rotations)
    H = np.zeros((V * K, 4, 4))
    H[:, :3, :3] = np.tile(rotations, (V, 1, 1))
    H[:, :3, 3] = np.repeat(centres, K, axis=0)
    H[:, 3, 3] = 1.0
    return H


def compute_chunk(robot: Chain, spec: MapSpec, centres: np.ndarray, index: int) -> dict[str, np.ndarray]:
    """The map's values for chunk ``index`` (voxels index·chunk_voxels onwards): reachability (share of the
    orientations reached), best manipulability (Yoshikawa, of the Jacobian with linear rows / L; 0 where
    nothing is reached), smallest σ_min/σ_max (1 where nothing is reached) and the mean number of branches per
    orientation (closed form only; NaN otherwise)."""
    lo = index * spec.chunk_voxels
    chunk = centres[lo:lo + spec.chunk_voxels]
    R = grid.axis_rotations(spec.orientations) if spec.task == "axis" else grid.rotations(spec.orientations)
    targets = targets_of(chunk, R)
    if spec.closed_form(robot):
        return _every_branch(robot, spec, targets, len(chunk))
    res = solve_batch(robot, targets, seed=spec.seed + lo * spec.orientations, task=spec.task,
                      tol_pos=spec.tol_pos, tol_rot=spec.tol_rot, max_restarts=spec.restarts)
    if spec.collisions is not None:
        model = collision_model(robot, spec.collisions)
        res.success[res.success] = [model.colliding_pair(q) is None for q in res.q[res.success]]
    ok = res.success.reshape(len(chunk), spec.orientations)
    manip = np.zeros(len(chunk) * spec.orientations)
    ratio = np.ones(len(chunk) * spec.orientations)
    if res.success.any():
        J = robot.jacobian_batch(res.q[res.success], frame="local_world_aligned")
        manip[res.success], ratio[res.success] = conditioning_batch(J, robot.characteristic_length())
    return {"reachability": ok.mean(axis=1), "manipulability": manip.reshape(ok.shape).max(axis=1),
            "sigma_ratio": ratio.reshape(ok.shape).min(axis=1), "branches": np.full(len(chunk), np.nan)}


def _every_branch(robot: Chain, spec: MapSpec, targets: np.ndarray, voxels: int) -> dict[str, np.ndarray]:
    """The chunk's values from every branch of every pose: a pose is reached when it has a branch, its
    manipulability and σ ratio are its best branch's."""
    batch = all_branches_batch(robot, targets, tol_pos=spec.tol_pos, tol_rot=spec.tol_rot)
    if spec.collisions is not None:
        _drop_colliding(batch, collision_model(robot, spec.collisions))
    pose, row = np.nonzero(~np.isnan(batch.q[:, :, 0]))
    manip, ratio = np.zeros(len(targets)), np.zeros(len(targets))
    if len(pose):
        J = robot.jacobian_batch(batch.q[pose, row], frame="local_world_aligned")
        m, r = conditioning_batch(J, robot.characteristic_length())
        np.maximum.at(manip, pose, m)
        np.maximum.at(ratio, pose, r)
    ok = (batch.count > 0).reshape(voxels, spec.orientations)
    ratio[batch.count == 0] = 1.0  # an unreached pose does not lower the voxel's smallest ratio
    return {"reachability": ok.mean(axis=1), "manipulability": manip.reshape(ok.shape).max(axis=1),
            "sigma_ratio": ratio.reshape(ok.shape).min(axis=1),
            "branches": batch.count.reshape(ok.shape).mean(axis=1).astype(float)}




def _drop_colliding(batch: BranchBatch, model: CollisionModel) -> None:
    """Set the branches that collide to NaN and recount each pose's clear branches (in place)."""
    for b, r in zip(*np.nonzero(~np.isnan(batch.q[:, :, 0])), strict=True):
        if model.colliding_pair(batch.q[b, r]) is not None:
            batch.q[b, r] = np.nan
    batch.count[:] = (~np.isnan(batch.q[:, :, 0])).sum(axis=1)
