"""A map's chunks on a Dask cluster (the optional extra ``kinelab[cluster]``).

Each chunk is a task: a pure function of the robot's recipe (how to load it, and its model file's
SHA-256), the spec and the chunk index, so a task that a lost worker leaves is simply run again elsewhere
and gives the same values. The client writes each chunk as it arrives, so memory stays bounded by the
chunks in flight and an interrupted run resumes like an in-process one.
"""

from __future__ import annotations

import contextlib
import os
import re
import socket
import struct
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kinelab.core import threads
from kinelab.errors import KinelabError
from kinelab.maps.chunk import compute_chunk
from kinelab.maps.store import ReachabilityMap, model_sha256
from kinelab.progress import bar
from kinelab.robot import Chain, catalog, load

if TYPE_CHECKING:
    from distributed import Client

    from kinelab.maps.chunk import MapSpec

INSTALL_HINT = "pip install 'kinelab[cluster]' (dask.distributed, cryptography)"
CONNECT_TIMEOUT = 5.0  # [s] to reach a scheduler before giving up
MAX_HANDSHAKE = 1 << 20  # [bytes] a Dask handshake is a few dozen bytes; a stranger's claim beyond this is refused
_ROBOTS: dict[tuple, Chain] = {}  # per worker process: robots already loaded, by recipe


def recipe(robot: Chain) -> dict:
    """How a worker loads the same robot: its registered name or model file, tool and base, and the hash the
    worker's copy must have."""
    if robot.source is None:
        raise KinelabError(f"{robot.name} was made from an in-memory model, which Dask workers cannot load: save "
                           "it as a URDF and load that, or run the map in this process")
    source = robot.name if robot.name in catalog.names() else str(Path(robot.source).resolve())
    return {"source": source, "tool": robot.tool, "base": robot.base, "xacro_args": robot.xacro_args,
            "trust_xacro": robot.trust_xacro, "sha256": model_sha256(robot)}


def worker_robot(how: dict) -> Chain:
    """The robot ``how`` (:func:`recipe`) names, loaded once per worker process and checked to be the client's."""
    key = (how["source"], how["tool"], how["base"], how["sha256"], how["trust_xacro"],
           tuple(sorted(how["xacro_args"].items())))
    if key not in _ROBOTS:
        # a xacro robot expands on the worker with the client's arguments and exactly the trust its user gave
        robot = load(how["source"], tool=how["tool"], base=how["base"], xacro_args=how["xacro_args"] or None,
                     trust_xacro=how["trust_xacro"])
        found = model_sha256(robot)
        if found != how["sha256"]:
            raise KinelabError(f"worker {os.getpid()} has another {how['source']} (SHA-256 {found[:12]}…, the client's "
                               f"{how['sha256'][:12]}…)")
        _ROBOTS[key] = robot
    return _ROBOTS[key]


def chunk_task(how: dict, spec: MapSpec, centres: np.ndarray, index: int) -> tuple[int, dict]:
    """One chunk on a worker: (index, values). One kernel thread per task: the cluster gives the parallelism."""
    threads.set_count(1)
    return index, compute_chunk(worker_robot(how), spec, centres, index)


def client_for(scheduler: str | None, workers: int | None) -> Any:
    """A Dask client: to the scheduler at ``scheduler``, or to a local cluster of ``workers`` processes.

    A scheduler's address is checked for its form, then a plain ``tcp://`` one for a Dask handshake (the
    scheduler speaks first: a short length-prefixed message) before Dask's client sees it, so a stranger on
    the port can neither hang the client nor make it allocate what its reply claims; the whole connection is
    bounded by CONNECT_TIMEOUT. The local cluster talks TLS with temporary credentials (only this process
    and its workers hold them) on 127.0.0.1, and its scheduler's HTTP server is stopped once it is up.

    Raises:
        KinelabError: dask.distributed (or cryptography, for TLS) missing (install hint), a malformed address,
            or a scheduler not reached, or not a Dask scheduler, within CONNECT_TIMEOUT seconds (named).
    """
    try:
        from dask.distributed import Client
    except ImportError:
        raise KinelabError(f"running a map on Dask needs dask.distributed: {INSTALL_HINT}") from None
    if scheduler is not None:
        address = check_address(scheduler)
        if address.startswith("tcp://"):
            _probe_handshake(address)
        return _bounded(lambda: Client(address, timeout=f"{CONNECT_TIMEOUT}s"), address)
    return _local_client(workers)


_ADDRESS = re.compile(r"^(?:(tcp|tls)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.-]+):(\d{1,5})$")


def check_address(scheduler: str) -> str:
    """``scheduler`` as a Dask address ``tcp://HOST:PORT`` (or ``tls://``); a bare HOST:PORT is taken as tcp.

    Raises:
        KinelabError: anything else, named with the form expected.
    """
    found = _ADDRESS.match(scheduler.strip()) if isinstance(scheduler, str) else None
    if found is None or not 0 < int(found.group(3)) < 65536:
        raise KinelabError(f"--scheduler {scheduler!r} is not a Dask scheduler address: give tcp://HOST:PORT or "
                           "tls://HOST:PORT (port 1-65535)")
    return f"{found.group(1) or 'tcp'}://{found.group(2)}:{found.group(3)}"


def _probe_handshake(address: str) -> None:
    """Connect and read the 8-byte length a Dask scheduler sends first; refuse silence or an absurd length."""
    host, port = address.removeprefix("tcp://").rsplit(":", 1)
    try:
        sock = socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT / 2)
    except OSError as exc:
        raise KinelabError(f"cannot reach the Dask scheduler at {address!r} within {CONNECT_TIMEOUT:g} s "
                           f"({type(exc).__name__}); nothing was written") from None
    head = b""
    with sock, contextlib.suppress(OSError):  # silence or a reset: no handshake, said below
        sock.settimeout(CONNECT_TIMEOUT / 2)
        while len(head) < 8:
            more = sock.recv(8 - len(head))
            if not more:
                break
            head += more
    length = struct.unpack("<Q", head)[0] if len(head) == 8 else 0
    if not 0 < length <= MAX_HANDSHAKE:
        raise KinelabError(f"{address!r} answers, but not as a Dask scheduler (no handshake within "
                           f"{CONNECT_TIMEOUT / 2:g} s); nothing was written")


def _bounded(connect: Callable[[], Any], address: str) -> Any:
    """``connect()`` in a helper thread, given up after CONNECT_TIMEOUT seconds (Dask's own timeout does not
    bound every step of its handshake)."""
    done: dict[str, Any] = {}

    def attempt() -> None:
        try:
            done["client"] = connect()
        except Exception as exc:  # noqa: BLE001 - reported below as one line
            done["error"] = exc

    thread = threading.Thread(target=attempt, daemon=True)
    thread.start()
    thread.join(CONNECT_TIMEOUT + 1.0)
    if "client" in done:
        return done["client"]
    why = type(done["error"]).__name__ if "error" in done else "no answer"
    raise KinelabError(f"cannot reach the Dask scheduler at {address!r} within {CONNECT_TIMEOUT:g} s ({why}); "
                       "nothing was written")


def cores() -> int:
    """The cores this process may run on (its CPU affinity where the system tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def _local_client(workers: int | None) -> Any:
    if workers is not None and not 1 <= workers <= cores():
        raise KinelabError(f"workers must be 1 to {cores()} (the cores here; a local cluster of more processes only "
                           f"adds their start-up), got {workers}")
    import dask
    from dask.distributed import Client, LocalCluster

    try:
        import cryptography  # noqa: F401 - Dask's temporary TLS credentials need it
    except ImportError:
        raise KinelabError(f"a local Dask cluster talks TLS, which needs cryptography: {INSTALL_HINT}") from None
    with dask.config.set({"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []}):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None, security=True)
    server = getattr(cluster.scheduler, "http_server", None)
    if server is not None:  # the scheduler runs in this process: its HTTP server serves nothing kinelab needs
        server.stop()
    return Client(cluster, security=cluster.security)


def run_chunks(client: Client, robot: Chain, spec: MapSpec, centres: np.ndarray, todo: list[int],
               target: ReachabilityMap, progress: bool | None = None) -> None:
    """Submit the chunks ``todo`` and write each into ``target`` as it arrives."""
    from dask.distributed import as_completed

    how = recipe(robot)
    scattered = client.scatter(centres, broadcast=True)
    futures = [client.submit(chunk_task, how, spec, scattered, c, key=f"kinelab-map-{how['sha256'][:8]}-{c}")
               for c in todo]
    resumed = target.chunks - len(todo)
    with bar(total=target.chunks, initial=resumed, progress=progress, unit="chunk",
             desc=f"map (dask; resumed: {resumed} chunks already written)" if resumed else "map (dask)") as shown:
        for future in as_completed(futures):
            index, values = future.result()
            target.write(index, values)
            shown.update()
