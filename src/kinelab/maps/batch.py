"""A batch of targets over a Dask cluster (the extra ``kinelab[cluster]``): a million targets in chunks, written
to a Zarr store as they arrive, resumable, each row what the in-process :func:`kinelab.solve_batch` gives it.

Chunk c holds rows c·K … (c + 1)·K − 1 and is solved by ``solve_batch`` on the chunk's targets with the base
seed ``seed + c·K``: row b uses seed + b, as in one in-process call (whose answers do not depend on the thread
count), so the rows are the in-process batch's, bit for bit. No time budget (one would make a row depend on the
machine's load). A chunk's rows are written before its ``done`` flag, so a run stopped anywhere (Ctrl-C, a
killed client) leaves every flagged chunk whole; running the same call again computes only the chunks not
flagged. The store keeps what identifies the run (the model file's and the targets' SHA-256, the seed, the
tolerances, the chunk size) and refuses to continue another run's.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinelab.core import threads
from kinelab.errors import KinelabError, OptionError
from kinelab.files import as_path
from kinelab.geometry import stack_homogeneous
from kinelab.ik.api import solve_batch
from kinelab.ik.batch import BatchIKResult
from kinelab.ik.targets import as_target_arrays
from kinelab.maps.cluster import client_for, recipe, worker_robot
from kinelab.maps.store import _zarr, model_sha256
from kinelab.progress import bar
from kinelab.robot import Chain
from kinelab.typing import Targets
from kinelab.values import is_real, is_whole

CHUNK = 10_000  # targets per task: ~0.3 s of a panda worker, 1.3 MB of targets sent
FIELDS = {"q": "f8", "success": "?", "status_code": "i1", "position_error": "f8", "rotation_error": "f8",
          "iterations": "i8", "restarts": "i8"}


@dataclass(frozen=True)
class BatchSpec:
    """What every chunk is solved with: the base seed, the tolerances [m, rad], the restarts per row and the
    chunk size (targets per task)."""

    seed: int = 0
    tol_pos: float = 1e-6
    tol_rot: float = 1e-6
    max_restarts: int = 1000
    chunk: int = CHUNK

    def __post_init__(self) -> None:
        """Checks the fields.

        Raises:
            OptionError: a field out of range, named.
        """
        for name, low in (("seed", 0), ("max_restarts", 0), ("chunk", 1)):
            value = getattr(self, name)
            if not is_whole(value, low):
                raise OptionError(name, value, f"an integer ≥ {low}")
        for name in ("tol_pos", "tol_rot"):
            value = getattr(self, name)
            if not is_real(value, 0, above=True):
                raise OptionError(name, value, "a positive finite tolerance")


@dataclass(frozen=True)
class ClusterRun:
    """A finished (or resumed) cluster batch: every row, the chunks this call computed, those it found done."""

    result: BatchIKResult
    computed: tuple[int, ...]
    resumed: int


def chunk_task(how: dict, spec: BatchSpec, targets: np.ndarray, index: int) -> tuple[int, dict[str, np.ndarray]]:
    """Chunk ``index`` on a worker: (index, its rows' arrays). One kernel thread: the cluster gives the parallelism
    (the rows do not depend on it)."""
    threads.set_count(1)
    res = solve_batch(worker_robot(how), targets, seed=spec.seed + index * spec.chunk, tol_pos=spec.tol_pos,
                      tol_rot=spec.tol_rot, max_restarts=spec.max_restarts)
    return index, {name: getattr(res, name) for name in FIELDS}


def targets_sha256(H: np.ndarray) -> str:
    """SHA-256 of the targets (B, 4, 4), little-endian float64."""
    return hashlib.sha256(np.ascontiguousarray(H, dtype="<f8").tobytes()).hexdigest()


def _open(out: str | Path, robot: Chain, H: np.ndarray, spec: BatchSpec) -> Any:
    """The store at ``out``: new, or the unfinished one of this very run.

    Raises:
        KinelabError: zarr missing, ``out`` not writable, or holding another run (the differing item named).
    """
    zarr, path = _zarr(), as_path(out, "the batch's out", KinelabError)
    meta = {"robot": robot.name, "source_sha256": model_sha256(robot), "targets_sha256": targets_sha256(H),
            "targets": int(len(H)), "joints": int(robot.n), **asdict(spec)}
    if path.exists():
        try:
            group = zarr.open_group(str(path), mode="r+")
        except (KeyError, ValueError, OSError, zarr.errors.GroupNotFoundError):
            raise KinelabError(f"{path} exists and is not a kinelab batch store: give another out") from None
        found = dict(group.attrs)
        for key, value in meta.items():
            if found.get(key) != value:
                raise KinelabError(f"{path} holds another batch ({key}: {found.get(key)!r}, this one {value!r}); "
                                   "give another out, or the same robot, targets and settings to resume it")
        return group
    try:
        group = zarr.open_group(str(path), mode="w")
    except (KeyError, OSError) as err:
        raise KinelabError(f"cannot write the batch to {path}: {getattr(err, 'strerror', None) or err}") from None
    group.attrs.update(meta)
    for name, dtype in FIELDS.items():
        shape = (len(H), robot.n) if name == "q" else (len(H),)
        group.create_dataset(name, shape=shape, chunks=(spec.chunk, *shape[1:]), dtype=dtype,
                             fill_value=np.nan if dtype == "f8" else 0)
    group.create_dataset("done", shape=(-(-len(H) // spec.chunk),), chunks=(1,), dtype=bool, fill_value=False)
    return group


def solve_batch_on_cluster(robot: Chain, targets: Targets, out: str | Path, spec: BatchSpec | None = None,
                           client: Any = None, scheduler: str | None = None, workers: int | None = None,
                           progress: bool | None = None) -> ClusterRun:
    """Solve every target on a Dask cluster (FRDM's compiled batch on each worker), writing to ``out``.

    Args:
        robot: the robot (loaded from a file or by name: the workers load the same file, checked by its hash).
        targets: (B, 4, 4) oMtarget (base frame) or a sequence of ``pin.SE3``.
        out: a Zarr directory: created, or the unfinished store of this same run, resumed.
        spec: seed, tolerances, restarts and chunk size (default :class:`BatchSpec`).
        client: a Dask client to use (else one is made, as kinelab's maps make it, and closed at the end).
        scheduler: the address of a running Dask scheduler (``tcp://`` or ``tls://``), or None: a local cluster.
        workers: the local cluster's worker processes (None: one per core).
        progress: show a bar (None: when interactive).

    Returns:
        The :class:`ClusterRun`: every row (``result``, as :func:`kinelab.solve_batch` with ``seed`` gives it),
        the chunks computed by this call and how many were already done.

    Raises:
        KinelabError: the cluster extra missing (with the install hint), ``out`` unusable or another run's.
        TargetError, OptionError: bad targets or settings, named.
    """
    spec = spec or BatchSpec()
    t0 = time.perf_counter()
    H = stack_homogeneous(*as_target_arrays(targets))
    group = _open(out, robot, H, spec)
    done = np.asarray(group["done"][:])
    todo = [int(c) for c in np.flatnonzero(~done)]
    own = client is None and bool(todo)
    client = client_for(scheduler, workers) if own else client
    try:
        if todo:
            _run(client, robot, H, spec, group, todo, len(done) - len(todo), progress)
    finally:
        if own:
            client.close()
            client.cluster.close()
    arrays = {name: np.asarray(group[name][:]) for name in FIELDS}
    result = BatchIKResult(**arrays, seed=spec.seed, wall_time=time.perf_counter() - t0, solver="frdm",
                           mode=f"frdm (compiled batch on a Dask cluster, {spec.chunk} targets a task)",
                           judge=robot.fk_certificate.judge)
    return ClusterRun(result, tuple(todo), len(done) - len(todo))


def _run(client: Any, robot: Chain, H: np.ndarray, spec: BatchSpec, group: Any, todo: list[int], resumed: int,
         progress: bool | None) -> None:
    """Submit the chunks ``todo``; write each one's rows, then its flag, as it arrives."""
    from dask.distributed import as_completed

    how, K = recipe(robot), spec.chunk
    futures = [client.submit(chunk_task, how, spec, H[c * K:(c + 1) * K], c, key=f"kinelab-batch-{c}-{time.time_ns()}")
               for c in todo]
    with bar(total=len(todo) + resumed, initial=resumed, progress=progress, unit="chunk",
             desc=f"batch (dask; resumed: {resumed} chunks already done)" if resumed else "batch (dask)") as shown:
        for future in as_completed(futures):
            index, values = future.result()
            rows = slice(index * K, index * K + len(values["success"]))
            for name, value in values.items():
                group[name][rows] = value
            group["done"][index] = True
            shown.update()
