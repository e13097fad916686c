"""The teach page's server: one process, on 127.0.0.1 only, serving the page, meshcat's viewer script and the
session's actions as small JSON requests (a thread per request, one action at a time).

Requests: ``GET /`` the page; ``GET /state?since=N`` the scene commands after N and the readings; ``POST /q``
``{"q": [...]}``, ``/target`` ``{"matrix": [16 numbers, rows first]}``, ``/branch`` ``{"step": ±1}``, ``/snap``,
``/collisions`` ``{"on": bool}``. Each answers ``{"seq", "commands" (base64 msgpack), "readout"}`` and, when the
request was refused, ``"error"`` naming why in at most 200 characters (HTTP 400; 403 for a request that is not the
page's own: another Host or Origin, or two Host headers; 415 for a POST that is not JSON). Replies are strict JSON
(a non-finite reading is null). The session is never left broken by a request. A connection that sends nothing for
2 s is closed, and every connection within 10 s.
"""

from __future__ import annotations

import base64
import contextlib
import html
import json
import math
import socket
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import parse_qs, urlparse

import meshcat

from kinelab.errors import KinelabError
from kinelab.view.caption import tab_title
from kinelab.view.teach.session import TeachSession, pose_from_matrix
from kinelab.view.teach.whole import WholeTeachSession

if TYPE_CHECKING:
    from email.message import Message
    from io import BufferedIOBase

LOOPBACK = "127.0.0.1"
MAX_BODY = 1 << 16  # [bytes] an action's JSON is a few hundred
TIMEOUT = 2.0  # [s] a connection that sends nothing (or half a request) for this long is closed
DEADLINE = 10.0  # [s] a connection's whole life: one trickling a byte at a time is closed all the same
BACKLOG = 512  # connections the system queues while the server is busy: a browser's bursts fit
MAX_CONNECTIONS = 256  # connections served at once (a thread each); more wait in the backlog
MAX_REASON = 200  # [characters] of a refusal's reason


class _Quiet(ThreadingHTTPServer):
    """An HTTP server on loopback that serves a bounded number of connections at once (the others wait their turn,
    a 503 after :data:`TIMEOUT`), and says nothing when a browser goes away mid-answer (a reload while the scene
    loads) or a connection times out."""

    daemon_threads = True
    request_queue_size = BACKLOG

    def __init__(self, address: tuple[str, int], handler: type[BaseHTTPRequestHandler]):
        self.closing = threading.Event()  # before the bind: a port in use calls server_close at once
        super().__init__(address, handler)
        self.slots = threading.BoundedSemaphore(MAX_CONNECTIONS)
        self.deadlines: dict[Any, float] = {}  # each open connection → when it is closed whatever it does
        self.watched = threading.Lock()
        threading.Thread(target=self._reap, name="teach deadlines", daemon=True).start()

    def watch(self, connection: Any) -> None:
        """Close ``connection`` at its deadline (:data:`DEADLINE` from now) unless it is forgotten first."""
        with self.watched:
            self.deadlines[connection] = time.monotonic() + DEADLINE

    def forget(self, connection: Any) -> None:
        """The connection ended on its own."""
        with self.watched:
            self.deadlines.pop(connection, None)

    def _reap(self) -> None:
        """One thread for every connection's deadline (a timer each would double the threads)."""
        while not self.closing.wait(0.25):
            now = time.monotonic()
            with self.watched:
                late = [c for c, t in self.deadlines.items() if t <= now]
                for c in late:
                    del self.deadlines[c]
            for c in late:
                _close(c)

    def server_close(self) -> None:
        self.closing.set()
        super().server_close()

    def process_request(self, request: Any, client_address: Any) -> None:
        if not self.slots.acquire(timeout=TIMEOUT):  # every slot held by connections that will time out
            with contextlib.suppress(OSError):
                request.sendall(b"HTTP/1.1 503 Service Unavailable\r\nContent-Length: 0\r\n\r\n")
            self.shutdown_request(request)
            return
        super().process_request(request, client_address)

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.slots.release()

    def handle_error(self, request: Any, client_address: Any) -> None:
        if not isinstance(sys.exc_info()[1], ConnectionError | TimeoutError):
            super().handle_error(request, client_address)


class RequestError(KinelabError):
    """A request the teach server refuses: its HTTP code and a short reason."""

    def __init__(self, code: int, reason: str):
        self.code = code
        super().__init__(short(reason))


def short(text: str) -> str:
    """A reason cut to :data:`MAX_REASON` characters."""
    return text if len(text) <= MAX_REASON else text[: MAX_REASON - 1] + "…"


class TeachServer:
    """The session served on 127.0.0.1 (``port`` 0: a free one); ``url`` is the page.

    It answers its own page only: a request whose ``Host`` is not a loopback name with this port (DNS rebinding),
    or whose ``Origin`` is another page's, is refused (403); a POST must carry JSON.
    """

    def __init__(self, session: TeachSession | WholeTeachSession, port: int = 0):
        self.session = session
        self.lock = session.lock  # a request's action and the reply it reads are one step
        self.files = {"/": _page(session).encode("utf-8"), "/meshcat.js": _meshcat_script(),
                      "/teach.js": resources.files(__package__).joinpath("teach.js").read_bytes()}
        try:
            self.httpd = _Quiet((LOOPBACK, port), _handler(self))
        except OSError as exc:
            raise KinelabError(f"cannot serve the teach page on {LOOPBACK}:{port}: {exc.strerror or exc}; give "
                               "another --port, or 0 for a free one") from None
        self.port = int(self.httpd.server_address[1])
        self.hosts = {f"{name}:{self.port}" for name in (LOOPBACK, "localhost")}
        self.origins = {f"http://{host}" for host in self.hosts}
        self.thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{LOOPBACK}:{self.port}/"

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

    def check_origin(self, headers: Message) -> None:
        """Refuse a request that is not the page's own.

        Raises:
            RequestError: 403 for a Host other than 127.0.0.1 or localhost with this port, or another Origin; 400 for
                two Host headers.
        """
        if len(headers.get_all("Host") or ()) > 1:  # which one a proxy or the browser meant is not ours to guess
            raise RequestError(400, "a request names one Host")
        host, origin = headers.get("Host"), headers.get("Origin")
        if host not in self.hosts:
            raise RequestError(403, f"this server answers its own page only (Host {host!r} is not {self.url})")
        if origin is not None and origin not in self.origins:
            raise RequestError(403, f"this server answers its own page only (a request from {origin!r})")

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
            s.set_q(_numbers(body.get("q"), f"q is a list of {len(s.q)} numbers (rad or m)"))
        elif action == "target":
            s.set_target(pose_from_matrix(_numbers(body.get("matrix"), "a target is 16 numbers: a 4 × 4 homogeneous "
                                                                       "matrix, rows first")), body.get("index", 0))
        elif action == "branch":
            s.step_branch(body.get("step", 1))
        elif action == "snap":
            s.snap_target()
        elif action == "collisions":
            s.set_collisions(body.get("on"))
        else:
            raise KinelabError(f"unknown action {short(repr(action))}: q, target, branch, snap or collisions")


def _numbers(values: Any, valid: str) -> list[float]:
    """A JSON list of numbers (not booleans) as floats.

    Raises:
        KinelabError: anything else (``valid`` says what is).
    """
    if not isinstance(values, list) or not all(isinstance(v, int | float) and not isinstance(v, bool)
                                               for v in values):
        raise KinelabError(valid)
    try:
        return [float(v) for v in values]
    except OverflowError:
        raise KinelabError(f"{valid}; a number was too large for a float") from None


def read_json(rfile: BufferedIOBase, length_header: str | None) -> dict[str, Any]:
    """The request's body: a JSON object of at most :data:`MAX_BODY` bytes.

    Raises:
        RequestError: 400 (411, 413) for a missing or bad length, a body too large, or anything but a JSON object.
    """
    try:
        length = int(length_header or "")
    except ValueError:
        raise RequestError(411, "a POST says its Content-Length") from None
    if not 0 <= length <= MAX_BODY:
        raise RequestError(413, f"a request's body is at most {MAX_BODY} bytes")
    try:
        body = json.loads(rfile.read(length) or b"{}")
    except (ValueError, RecursionError):  # RecursionError: thousands of nested brackets
        raise RequestError(400, "the request is not a JSON object") from None
    if not isinstance(body, dict):
        raise RequestError(400, "the request is not a JSON object")
    return body


class _Handler(BaseHTTPRequestHandler):
    """The teach page's requests, answered for ``server_of`` (a subclass per server sets it)."""

    server_of: TeachServer
    timeout = TIMEOUT  # a half-sent request holds its thread this long, not for ever

    def setup(self) -> None:
        super().setup()
        self.server_of.httpd.watch(self.connection)

    def finish(self) -> None:
        self.server_of.httpd.forget(self.connection)
        super().finish()

    def log_message(self, format: str, *args: Any) -> None:  # quiet: the terminal shows the address only
        return

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        url = urlparse(self.path)
        try:
            self.server_of.check_origin(self.headers)
        except RequestError as exc:
            self._send_json(exc.code, {"error": str(exc)})
            return
        if url.path == "/state":
            since = _int(parse_qs(url.query).get("since", ["0"])[0])
            with self.server_of.lock:
                self._send_json(200, self.server_of.reply(since))
        elif url.path in self.server_of.files:
            kind = "text/html; charset=utf-8" if url.path == "/" else "text/javascript; charset=utf-8"
            self._send(200, self.server_of.files[url.path], kind)
        else:
            self._send(404, b"not found", "text/plain")

    def do_POST(self) -> None:  # noqa: N802
        try:
            self.server_of.check_origin(self.headers)
            if self.headers.get_content_type() != "application/json":
                raise RequestError(415, "the actions take JSON (Content-Type: application/json)")
            body = read_json(self.rfile, self.headers.get("Content-Length"))
        except RequestError as exc:
            self._send_json(exc.code, {"error": str(exc)})
            return
        with self.server_of.lock:
            code, error = 200, ""
            try:
                self.server_of.act(urlparse(self.path).path.strip("/"), body)
            except KinelabError as exc:
                code, error = 400, short(str(exc))
            reply = self.server_of.reply(_int(body.get("since", 0)), error)
        self._send_json(code, reply)

    def _send_json(self, code: int, value: dict[str, Any]) -> None:
        self._send(code, json.dumps(strict(value), allow_nan=False).encode("utf-8"), "application/json")

    def _send(self, code: int, data: bytes, kind: str) -> None:
        self.send_response(code)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        self.wfile.write(data)


def _handler(server: TeachServer) -> type[BaseHTTPRequestHandler]:
    """The request handler class of one teach server."""
    return type("Handler", (_Handler,), {"server_of": server})


def _close(connection: Any) -> None:
    """End a connection past its deadline (its thread's blocked read then returns)."""
    with contextlib.suppress(OSError):
        connection.shutdown(socket.SHUT_RDWR)


def strict(value: Any) -> Any:
    """``value`` with every NaN or infinity as None: JSON has no such numbers (Python's ``Infinity`` is not JSON)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: strict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [strict(v) for v in value]
    return value


def _int(text: Any) -> int:
    try:
        return max(0, int(text))
    except (TypeError, ValueError, OverflowError):
        return 0


def _page(session: TeachSession | WholeTeachSession) -> str:
    """The page with its title (robot and view) and the robot's joints for the sliders."""
    robot = session.robot
    config = session.page_config()
    text = resources.files(__package__).joinpath("teach.html").read_text(encoding="utf-8")
    return (text.replace("__TITLE__", html.escape(tab_title(robot.name, "teach")))
            .replace("__CONFIG__", json.dumps(config).replace("<", "\\u003c")))  # no tag can end the script


def _meshcat_script() -> bytes:
    return (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_bytes()
