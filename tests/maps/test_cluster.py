"""The same map in this process and on a local Dask cluster of 1 and 2 worker processes, a worker killed
mid-run, and an unreachable scheduler."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import kinelab
from kinelab import KinelabError, maps

pytest.importorskip("dask.distributed")
from kinelab.maps import cluster  # noqa: E402

SPEC = maps.MapSpec(voxel=0.2, orientations=4, restarts=3, chunk_voxels=32)
NAMES = ("reachability", "manipulability", "sigma_ratio")


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


@pytest.fixture(scope="module")
def in_process(ur5):
    return maps.reachability(ur5, SPEC)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_local_cluster_computes_the_identical_map(ur5, in_process, workers):
    client = cluster.client_for(None, workers)
    try:
        on_dask = maps.reachability(ur5, SPEC, client=client)
    finally:
        client.close()
        client.cluster.close()
    for name in NAMES:
        np.testing.assert_array_equal(on_dask.array(name), in_process.array(name))


def test_a_worker_killed_mid_run_loses_no_chunk_and_counts_none_twice(ur5, in_process, tmp_path):
    client = cluster.client_for(None, 2)
    pids = list(client.run(os.getpid).values())
    written: list[int] = []
    killed_at: list[int] = []

    def kill_when_started():
        while len(written) < 3:
            time.sleep(0.01)
        os.kill(pids[0], signal.SIGKILL)
        killed_at.append(len(written))

    target = maps.store.open_map(tmp_path / "m.zarr", ur5, SPEC, maps.grid.voxel_centres(ur5, SPEC.voxel))
    original = target.write

    def write(index, values):
        assert not target.done[index]  # counted once
        written.append(index)
        original(index, values)

    target.write = write
    killer = threading.Thread(target=kill_when_started, daemon=True)
    killer.start()
    try:
        cluster.run_chunks(client, ur5, SPEC, maps.grid.voxel_centres(ur5, SPEC.voxel), list(range(target.chunks)),
                           target)
    finally:
        client.close()
        client.cluster.close()
    assert killed_at and killed_at[0] < target.chunks - 5  # the worker died with chunks still to run
    assert sorted(written) == list(range(target.chunks))  # none lost
    for name in NAMES:
        np.testing.assert_array_equal(target.array(name), in_process.array(name))


def test_an_unreachable_scheduler_is_named_within_seconds():
    t0 = time.perf_counter()
    with pytest.raises(KinelabError, match="cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'"):
        cluster.client_for("tcp://127.0.0.1:9", None)
    assert time.perf_counter() - t0 < 30
