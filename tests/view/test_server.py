"""The viewer's server listens on 127.0.0.1 only and ends with the process that started it."""

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from helpers import interruptible

from kinelab.view.server import Server


def _non_loopback_addresses() -> list[str]:
    out = subprocess.run(["hostname", "-I"], capture_output=True, text=True, check=False).stdout.split()
    return [a for a in out if not a.startswith(("127.", "fe80")) and a != "::1"]


def _port(url: str) -> int:
    return int(url.split(":")[2].split("/")[0])


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    status = Path(f"/proc/{pid}/status")
    return not (status.exists() and "State:\tZ" in status.read_text())


def _wait_gone(pid: int, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if not _alive(pid):
            return True
        time.sleep(0.1)
    return False


def test_the_web_server_answers_on_loopback_and_refuses_every_other_address():
    server = Server()
    try:
        port = _port(server.web_url)
        assert server.web_url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(server.web_url, timeout=10) as reply:
            assert reply.status == 200
        others = _non_loopback_addresses()
        if not others:
            pytest.skip("this machine has no non-loopback IPv4 address to try")
        for address in others:
            with pytest.raises(OSError), socket.create_connection((address, port), timeout=3):
                pass
    finally:
        server.stop()
    assert _wait_gone(server.pid)


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(c) for c in path.read_text().split()] if path.exists() else []


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL])
def test_kinelab_view_takes_its_server_with_it(sig):
    proc = interruptible([sys.executable, "-m", "kinelab.cli", "view", "ur5"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONWARNINGS": "ignore"})
    try:
        line = proc.stdout.readline()
        assert "127.0.0.1" in line, line  # (reading stderr here would wait for a server that never ends)
        servers = _children(proc.pid)
        assert len(servers) == 1 and _alive(servers[0])
        proc.send_signal(sig)
        proc.wait(timeout=15)
        assert _wait_gone(servers[0]), f"the server outlived kinelab view after {sig.name}"
    finally:
        proc.kill()


def test_a_script_that_ends_takes_its_server_with_it():
    code = ("import kinelab\nfrom kinelab.view import Scene\ns = Scene(kinelab.load('ur5'))\n"
            "print(s.server.pid, flush=True)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "PYTHONWARNINGS": "ignore"})
    pid = int(out.stdout.split()[-1])
    assert _wait_gone(pid)
