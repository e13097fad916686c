"""A map's chunks on a Dask cluster (the optional extra ``kinelab[cluster]``).

Each chunk is a task: a pure function of the robot's recipe (how to load it, and its model file's
SHA-256), the spec and the chunk index, so a task that a lost worker leaves is simply run again elsewhere
and gives the same values. The client writes each chunk as it arrives, so memory stays bounded by the
chunks in flight and an interrupted run resumes like an in-process one.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from kinelab.errors import KinelabError
from kinelab.maps.store import model_sha256
from kinelab.robot import Robot

INSTALL_HINT = "pip install 'kinelab[cluster]' (dask.distributed)"
CONNECT_TIMEOUT = 5.0  # [s] to reach a scheduler before giving up
_ROBOTS: dict[tuple, Robot] = {}  # per worker process: robots already loaded, by recipe


def recipe(robot: Robot) -> dict:
    """How a worker loads the same robot: its registered name or model file, tool and base, and the hash the
    worker's copy must have."""
    from kinelab.robot import catalog

    source = robot.name if robot.name in catalog.names() else str(Path(robot.source).resolve())
    return {"source": source, "tool": robot.tool, "base": robot.base,
            "sha256": model_sha256(robot)}


def _worker_robot(how: dict) -> Robot:
    from kinelab.robot import load

    key = (how["source"], how["tool"], how["base"], how["sha256"])
    if key not in _ROBOTS:
        robot = load(how["source"], tool=how["tool"], base=how["base"])
        found = model_sha256(robot)
        if found != how["sha256"]:
            raise KinelabError(f"worker {os.getpid()} has another {how['source']} (SHA-256 {found[:12]}…, the client's "
                               f"{how['sha256'][:12]}…)")
        _ROBOTS[key] = robot
    return _ROBOTS[key]


def chunk_task(how: dict, spec: Any, centres: np.ndarray, index: int) -> tuple[int, dict]:
    """One chunk on a worker: (index, values). One numba thread per task: the cluster gives the parallelism."""
    import numba

    from kinelab.maps.chunk import compute_chunk

    numba.set_num_threads(1)
    return index, compute_chunk(_worker_robot(how), spec, centres, index)


def client_for(scheduler: str | None, workers: int | None) -> Any:
    """A Dask client: to the scheduler at ``scheduler``, or to a local cluster of ``workers`` processes.

    Raises:
        KinelabError: dask.distributed missing (install hint), or a scheduler not reached within
            CONNECT_TIMEOUT seconds (its address named).
    """
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise KinelabError(f"running a map on Dask needs dask.distributed: {INSTALL_HINT}") from None
    if scheduler is not None:
        try:
            return Client(scheduler, timeout=f"{CONNECT_TIMEOUT}s")
        except (OSError, TimeoutError) as exc:
            raise KinelabError(f"cannot reach the Dask scheduler at {scheduler!r} within {CONNECT_TIMEOUT:g} s "
                               f"({type(exc).__name__}); nothing was written") from None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None)
    return Client(cluster)


def run_chunks(client: Any, robot: Robot, spec: Any, centres: np.ndarray, todo: list[int], target: Any,
               progress: bool = False) -> None:
    """Submit the chunks ``todo`` and write each into ``target`` as it arrives."""
    from dask.distributed import as_completed
    from tqdm import tqdm

    how = recipe(robot)
    scattered = client.scatter(centres, broadcast=True)
    futures = [client.submit(chunk_task, how, spec, scattered, c, key=f"kinelab-map-{how['sha256'][:8]}-{c}")
               for c in todo]
    with tqdm(total=len(todo), desc="map (dask)", disable=not progress, unit="chunk") as bar:
        for future in as_completed(futures):
            index, values = future.result()
            target.write(index, values)
            bar.update()
