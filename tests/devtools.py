"""A headless Chromium driven over the DevTools protocol, for tests that use a page as a person would: move a
slider, drag with the mouse, read what the page shows, take a screenshot.

Plain CDP over one WebSocket (tornado's client, which meshcat brings): ``Runtime.evaluate``,
``Input.dispatchMouseEvent``, ``Page.captureScreenshot``. The browser runs with software WebGL, a profile of its
own and no network but loopback, and is killed when the block ends.
"""

from __future__ import annotations

import asyncio
import base64
import contextlib
import itertools
import json
import re
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from browser import HEADLESS, find_chromium

START_TIMEOUT = 60.0  # [s]


class Page:
    """One page of a headless Chromium, driven through the DevTools protocol (all calls block)."""

    def __init__(self, ws_url: str):
        from tornado.websocket import websocket_connect

        async def connect() -> Any:
            return await websocket_connect(ws_url, max_message_size=1 << 28)

        self.loop = asyncio.new_event_loop()
        self.ws = self.loop.run_until_complete(connect())
        self.ids = itertools.count(1)

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """Send one command and wait for its answer (events in between are skipped)."""
        key = next(self.ids)
        return dict(self.loop.run_until_complete(self._call(key, method, params)))

    async def _call(self, key: int, method: str, params: dict[str, Any]) -> dict[str, Any]:
        await self.ws.write_message(json.dumps({"id": key, "method": method, "params": params}))
        while True:
            text = await asyncio.wait_for(self.ws.read_message(), 60)
            if text is None:
                raise RuntimeError("the browser closed the DevTools connection")
            message = json.loads(text)
            if message.get("id") == key:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return dict(message.get("result", {}))

    def eval(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (promises awaited)."""
        out = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in out:
            raise RuntimeError(f"{expression}: {out['exceptionDetails'].get('exception', {}).get('description')}")
        return out["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 30.0) -> Any:
        """Poll a JavaScript expression until it is truthy; its value."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.eval(expression)
            if value:
                return value
            time.sleep(0.05)
        raise TimeoutError(f"the page never made {expression!r} true within {timeout} s")

    def mouse(self, kind: str, x: float, y: float, buttons: int = 1, modifiers: int = 0) -> None:
        """A mouse event at (x, y) CSS pixels: kind "mousePressed", "mouseMoved" or "mouseReleased"."""
        self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", buttons=buttons,
                  clickCount=1 if kind != "mouseMoved" else 0, modifiers=modifiers)

    def drag(self, start: tuple[float, float], end: tuple[float, float], steps: int = 12, modifiers: int = 0,
             pause: float = 0.03) -> None:
        """Press at ``start``, move to ``end`` in ``steps`` steps (a pause each, as a hand moves), release."""
        self.mouse("mousePressed", *start, modifiers=modifiers)
        for k in range(1, steps + 1):
            f = k / steps
            self.mouse("mouseMoved", start[0] + f * (end[0] - start[0]), start[1] + f * (end[1] - start[1]),
                       modifiers=modifiers)
            time.sleep(pause)
        self.mouse("mouseReleased", *end, buttons=0, modifiers=modifiers)

    def screenshot(self, path: str | Path) -> Path:
        """Save what the page shows as a PNG."""
        data = self.call("Page.captureScreenshot", format="png")["data"]
        Path(path).write_bytes(base64.b64decode(data))
        return Path(path)

    def close(self) -> None:
        self.ws.close()
        self.loop.close()


@contextlib.contextmanager
def open_page(url: str, size: tuple[int, int] = (1280, 900)) -> Iterator[Page]:
    """A headless Chromium showing ``url``, its page driven through DevTools; the browser ends with the block."""
    chromium = find_chromium()
    if chromium is None:
        raise FileNotFoundError("no chromium on PATH (Debian: apt-get install chromium)")
    with tempfile.TemporaryDirectory(prefix="kinelab-devtools-", ignore_cleanup_errors=True) as profile:
        proc = subprocess.Popen(
            [chromium, *HEADLESS, "--remote-debugging-address=127.0.0.1", "--remote-debugging-port=0",
             f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}", url],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        page = None
        try:
            page = Page(_page_socket(proc))
            yield page
        finally:
            if page is not None:
                page.close()
            proc.kill()
            proc.wait()
            if proc.stderr is not None:
                proc.stderr.close()


def _page_socket(proc: subprocess.Popen[str]) -> str:
    """The DevTools WebSocket of the browser's first page (read from where the browser says it listens)."""
    assert proc.stderr is not None
    deadline = time.monotonic() + START_TIMEOUT
    port = None
    while port is None and time.monotonic() < deadline:
        line = proc.stderr.readline()
        if not line and proc.poll() is not None:
            raise RuntimeError(f"chromium ended (exit code {proc.returncode}) before listening")
        found = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
        port = int(found.group(1)) if found else None
    if port is None:
        raise TimeoutError("chromium did not say where DevTools listens")
    while time.monotonic() < deadline:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as reply:
            pages = [t for t in json.load(reply) if t.get("type") == "page"]
        if pages:
            return str(pages[0]["webSocketDebuggerUrl"])
        time.sleep(0.1)
    raise TimeoutError("chromium opened no page")
