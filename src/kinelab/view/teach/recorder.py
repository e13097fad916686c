"""A meshcat window that records its commands instead of sending them: the teach page's scene.

meshcat's ``Visualizer`` talks to a window; this one keeps each command packed (msgpack, as meshcat's bridge sends
them), the latest per node and kind, numbered in the order they were given, so that a page catching up gets only
what changed since the number it last saw, and a page loading afresh gets the whole scene in order.
"""

from __future__ import annotations

import threading
from typing import Any

import umsgpack


class RecordingWindow:
    """Where a ``meshcat.Visualizer(window=...)`` sends its commands: kept packed, the latest per (kind, node)."""

    web_url = ""  # no server: the teach page serves the scene itself

    def __init__(self) -> None:
        self._latest: dict[tuple[str, str, str], tuple[int, bytes]] = {}
        self._count = 0
        self._lock = threading.Lock()

    @property
    def seq(self) -> int:
        """The number of the last command given (0: none yet)."""
        return self._count

    def send(self, command: Any) -> None:
        """Keep the command (a meshcat command object); a later one of its kind on its node replaces it; a delete
        forgets every earlier command on the node and under it."""
        data = command.lower()
        path, kind = data.get("path", ""), data["type"]
        with self._lock:
            self._count += 1
            if kind == "delete":
                below = path.rstrip("/") + "/"
                self._latest = {k: v for k, v in self._latest.items() if k[1] != path and not k[1].startswith(below)}
            key = (kind, path, str(data.get("property", "")))
            self._latest.pop(key, None)  # re-inserted at the end: replayed after what it follows
            self._latest[key] = (self._count, umsgpack.packb(data))

    def since(self, seq: int) -> tuple[int, list[bytes]]:
        """(the last number, the packed commands numbered after ``seq`` in order); ``seq`` 0 gives the scene."""
        with self._lock:
            fresh = [packed for number, packed in self._latest.values() if number > seq]
            return self._count, fresh
