"""The meshcat server kinelab starts: meshcat's own ZMQ/WebSocket bridge, bound to 127.0.0.1 only, in a
child process that ends with the process that started it.

meshcat's stock server binds its web server to every interface (tornado's ``listen`` without an address)
and starts in a session of its own, so it outlives a ``kill`` of its parent. kinelab runs the same bridge
with the web server on the loopback address, in the parent's process group (Ctrl-C in a terminal reaches
both), and with the Linux parent-death signal set, so a SIGTERM or SIGKILL of the parent ends it too.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import tornado.web
from meshcat.servers import zmqserver

from kinelab.view.caption import titled

LOOPBACK = "127.0.0.1"
START_TIMEOUT = 30.0  # [s] for the child to report its URLs
PR_SET_PDEATHSIG = 1


class ServerError(RuntimeError):
    """The meshcat server process did not start."""


class Server:
    """A loopback meshcat server in a child process; ``zmq_url`` and ``web_url`` say where it listens."""

    def __init__(self, title: str = "kinelab") -> None:
        env = {**os.environ, "KINELAB_PARENT_PID": str(os.getpid()), "KINELAB_TAB_TITLE": title}
        self.proc = subprocess.Popen([sys.executable, "-u", "-m", "kinelab.view.server"], stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, env=env)
        atexit.register(self.stop)
        self.zmq_url = self._read_line("zmq_url=")
        self.web_url = self._read_line("web_url=")

    @property
    def pid(self) -> int:
        """The server's process id."""
        return self.proc.pid

    def _read_line(self, prefix: str) -> str:
        deadline = time.monotonic() + START_TIMEOUT
        assert self.proc.stdout is not None
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline().decode("utf-8").strip()
            if line.startswith(prefix):
                return line[len(prefix):]
            if not line and self.proc.poll() is not None:
                break
        self.stop()
        raise ServerError(f"the meshcat server did not start (exit code {self.proc.poll()})")

    def stop(self) -> None:
        """End the server process (idempotent)."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self.proc.stdout is not None:
            self.proc.stdout.close()


def _die_with_parent() -> None:
    """Ask Linux to send SIGTERM when the parent dies; exit now if it already has."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    parent = int(os.environ.get("KINELAB_PARENT_PID", "0"))
    if parent and os.getppid() != parent:
        sys.exit(0)


def _loopback_bridge() -> Any:
    class LoopbackBridge(zmqserver.ZMQWebSocketBridge):
        """meshcat's bridge with its web server listening on 127.0.0.1 only."""

        def make_app(self) -> Any:
            app = super().make_app()
            app.add_handlers(r".*$", [(r"/static/(?:index\.html)?", _titled_index())])  # ahead of the files
            listen = app.listen

            def loopback_listen(port: int, **kwargs: object) -> Any:
                return listen(port, address=LOOPBACK, **kwargs)

            app.listen = loopback_listen
            return app

    return LoopbackBridge(host=LOOPBACK)


def _titled_index() -> Any:
    """A handler for the viewer's page with the tab titled by ``KINELAB_TAB_TITLE`` (meshcat's says "MeshCat")."""
    page = titled((Path(zmqserver.VIEWER_ROOT) / zmqserver.VIEWER_HTML).read_text(encoding="utf-8"),
                  os.environ.get("KINELAB_TAB_TITLE", "kinelab"))

    class TitledIndex(tornado.web.RequestHandler):
        def get(self) -> None:
            self.set_header("Cache-Control", "no-store")
            self.write(page)

    return TitledIndex


def main() -> None:
    """Run the server (the child's entry point) until SIGTERM, SIGINT or the parent's death."""
    _die_with_parent()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    bridge = _loopback_bridge()
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        bridge.run()


if __name__ == "__main__":
    main()
