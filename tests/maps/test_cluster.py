"""The same map in this process and on a local Dask cluster of 1 and 2 worker processes, a worker killed
mid-run, and an unreachable scheduler."""

import contextlib
import os
import signal
import socket
import struct
import threading
import time

import numpy as np
import pytest
from helpers import no_hang

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
        assert client.scheduler.address.startswith("tls://127.0.0.1:")  # temporary TLS credentials, loopback
        http = client.cluster.scheduler.http_server  # no HTTP server left listening
        assert all(sock.fileno() == -1 for sock in http._sockets.values())
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
    with no_hang(30), pytest.raises(KinelabError, match="cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'"):
        cluster.client_for("tcp://127.0.0.1:9", None)


@pytest.mark.parametrize("address", ["", "abc", "tcp://", "tcp://host", "http://127.0.0.1:80", "127.0.0.1:0",
                                     "tcp://127.0.0.1:70000", "tcp://a b:1"])
def test_a_malformed_scheduler_address_is_refused_with_the_form_expected(address):
    with pytest.raises(KinelabError, match="give tcp://HOST:PORT"):
        cluster.client_for(address, None)


def test_a_bare_host_and_port_is_taken_as_tcp():
    assert cluster.check_address("127.0.0.1:8786") == "tcp://127.0.0.1:8786"
    assert cluster.check_address("tls://[::1]:8786") == "tls://[::1]:8786"


def _stranger(reply: bytes):
    """A loopback server that accepts and answers ``reply`` (or keeps silent), as a web server on the port would."""
    server = socket.create_server(("127.0.0.1", 0))

    def serve():
        with contextlib.suppress(OSError):
            conn, _ = server.accept()
            with conn:
                if reply:
                    conn.sendall(reply)
                time.sleep(8)

    threading.Thread(target=serve, daemon=True).start()
    return server


@pytest.mark.parametrize("reply", [b"", b"HTTP/1.1 400 Bad Request\r\n\r\n", struct.pack("<Q", 3 << 60)])
def test_a_stranger_on_the_port_is_named_within_seconds_and_allocates_nothing(reply):
    server = _stranger(reply)
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    with no_hang(int(cluster.CONNECT_TIMEOUT) + 10), pytest.raises(KinelabError, match="not as a Dask scheduler"):
        cluster.client_for(address, None)  # it gives up at its time-out: no hang
    server.close()
