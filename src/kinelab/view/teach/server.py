"""The teach page's server: one process, on 127.0.0.1 only, serving the page, meshcat's viewer script and the
session's actions as small JSON requests (a thread per request, one action at a time).

Requests: ``GET /`` the page; ``GET /state?since=N`` the scene commands after N and the readings; ``POST /q``
``{"q": [...]}``, ``/target`` ``{"matrix": [16 numbers, rows first]}``, ``/branch`` ``{"step": ±1}``, ``/snap``,
``/collisions`` ``{"on": bool}``. Each answers ``{"seq", "commands" (base64 msgpack), "readout"}`` and, when the
request was refused, ``"error"`` naming why (HTTP 400).
"""

from __future__ import annotations

import base64
import html
import json
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlparse

from kinelab.errors import KinelabError
from kinelab.view.caption import tab_title
from kinelab.view.teach.session import TeachSession, pose_from_matrix

LOOPBACK = "127.0.0.1"
MAX_BODY = 1 << 16  # [bytes] an action's JSON is a few hundred


class _Quiet(ThreadingHTTPServer):
    """An HTTP server that says nothing when a browser goes away mid-answer (a reload while the scene loads)."""

    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        import sys

        if not isinstance(sys.exc_info()[1], ConnectionError):
            super().handle_error(request, client_address)


class TeachServer:
    """The session served on 127.0.0.1 (``port`` 0: a free one); ``url`` is the page."""

    def __init__(self, session: TeachSession, port: int = 0):
        self.session = session
        self.lock = session.lock  # a request's action and the reply it reads are one step
        self.files = {"/": _page(session).encode("utf-8"), "/meshcat.js": _meshcat_script(),
                      "/teach.js": resources.files(__package__).joinpath("teach.js").read_bytes()}
        try:
            self.httpd = _Quiet((LOOPBACK, port), _handler(self))
        except OSError as exc:
            raise KinelabError(f"cannot serve the teach page on {LOOPBACK}:{port}: {exc.strerror or exc}; give "
                               "another --port, or 0 for a free one") from None
        self.thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{LOOPBACK}:{self.httpd.server_address[1]}/"

    def start(self) -> TeachServer:
        """Serve in a background thread (a notebook's way); returns self."""
        self.thread = threading.Thread(target=self.httpd.serve_forever, name="kinelab-teach", daemon=True)
        self.thread.start()
        return self

    def serve_forever(self) -> None:
        """Serve in this thread until interrupted (the command line's way)."""
        self.httpd.serve_forever()

    def close(self) -> None:
        """Stop serving and free the port (idempotent)."""
        if self.thread is not None:
            self.httpd.shutdown()
            self.thread = None
        self.httpd.server_close()

    def reply(self, since: int, error: str = "") -> dict[str, Any]:
        """What every request answers: the commands after ``since``, the readings, the error if any."""
        seq, packed = self.session.window.since(since)
        out: dict[str, Any] = {"seq": seq, "commands": [base64.b64encode(p).decode("ascii") for p in packed],
                               "readout": self.session.readout()}
        if error:
            out["error"] = error
        return out

    def act(self, action: str, body: dict[str, Any]) -> None:
        """Run one action of the page on the session.

        Raises:
            KinelabError: an unknown action or a value the session refuses (named).
        """
        s = self.session
        if action == "q":
            s.set_q(body.get("q"))
        elif action == "target":
            s.set_target(pose_from_matrix(body.get("matrix")))
        elif action == "branch":
            step = body.get("step", 1)
            if step not in (1, -1) or isinstance(step, bool):
                raise KinelabError(f"a branch step is 1 (next) or -1 (previous), not {step!r}")
            s.step_branch(step)
        elif action == "snap":
            s.snap_target()
        elif action == "collisions":
            if not isinstance(body.get("on"), bool):
                raise KinelabError(f"collisions are switched by on: true or false, not {body.get('on')!r}")
            s.set_collisions(body["on"])
        else:
            raise KinelabError(f"unknown action {action!r}: q, target, branch, snap or collisions")


def _handler(server: TeachServer) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def log_message(self, format: str, *args: Any) -> None:  # quiet: the terminal shows the address only
            return

        def do_GET(self) -> None:  # noqa: N802 (http.server's name)
            url = urlparse(self.path)
            if url.path == "/state":
                since = _int(parse_qs(url.query).get("since", ["0"])[0])
                with server.lock:
                    self._send(200, json.dumps(server.reply(since)).encode("utf-8"), "application/json")
            elif url.path in server.files:
                kind = "text/html; charset=utf-8" if url.path == "/" else "text/javascript; charset=utf-8"
                self._send(200, server.files[url.path], kind)
            else:
                self._send(404, b"not found", "text/plain")

        def do_POST(self) -> None:  # noqa: N802
            length = _int(self.headers.get("Content-Length", "0"))
            try:
                body = json.loads(self.rfile.read(min(length, MAX_BODY)) or b"{}")
                if not isinstance(body, dict):
                    raise ValueError("not an object")
            except ValueError:
                self._send(400, b'{"error": "the request is not a JSON object"}', "application/json")
                return
            with server.lock:
                code, error = 200, ""
                try:
                    server.act(urlparse(self.path).path.strip("/"), body)
                except KinelabError as exc:
                    code, error = 400, str(exc)
                reply = server.reply(_int(body.get("since", 0)), error)
            self._send(code, json.dumps(reply).encode("utf-8"), "application/json")

        def _send(self, code: int, data: bytes, kind: str) -> None:
            self.send_response(code)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(data)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(data)

    return Handler


def _int(text: Any) -> int:
    try:
        return max(0, int(text))
    except (TypeError, ValueError):
        return 0


def _page(session: TeachSession) -> str:
    """The page with its title (robot and view) and the robot's joints for the sliders."""
    robot = session.robot
    joints = [{"name": j.name, "kind": j.kind, "lower": j.lower, "upper": j.upper} for j in robot.joints]
    legend = (f"Tool frame: x red, y green, z blue; target: the longer triad with the gold ball. Blue ellipsoid: the "
              f"tool point's velocities for unit joint speeds (J_v's singular values), 1 m/rad drawn as "
              f"{session.scale:.3g} m (fixed at the start). "
              f"σ_min and manipulability of the Jacobian with its linear rows divided by L = "
              f"{robot.characteristic_length():.3g} m (dimensionless). Start: {session.start}."
              + (f" Obstacles: {session.scene.legend['obstacles']}." if "obstacles" in session.scene.legend else ""))
    config = {"q": session.q.tolist(), "joints": joints, "heading": f"kinelab teach — {robot.name}", "legend": legend}
    text = resources.files(__package__).joinpath("teach.html").read_text(encoding="utf-8")
    return (text.replace("__TITLE__", html.escape(tab_title(robot.name, "teach")))
            .replace("__CONFIG__", json.dumps(config).replace("</", "<\\/")))


def _meshcat_script() -> bytes:
    import meshcat

    return (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_bytes()
