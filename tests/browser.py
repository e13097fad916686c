"""Browser helpers for the view tests: headless Chromium screenshots, pixel differences, scene contents."""

from __future__ import annotations

import base64
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import umsgpack
from PIL import Image

from kinelab.view import Scene


def scene_paths(html: str) -> set[str]:
    """The meshcat node paths a static page sets objects on (decoded from its embedded commands)."""
    paths = set()
    for blob in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", html):
        cmd = umsgpack.unpackb(base64.b64decode(blob))
        if isinstance(cmd, dict) and cmd.get("type") == "set_object":
            paths.add(cmd.get("path", ""))
    return paths


# headless, software WebGL, a profile of its own, no network but loopback (the browser tests' every Chromium)
HEADLESS = ("--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
            "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run")


def find_chromium() -> str | None:
    """Path of a Chromium executable on PATH (Debian's ``chromium``), or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def screenshot(url_or_path: str | Path, png: str | Path, size: tuple[int, int] = (640, 480),
               wait_ms: int = 8000, chromium: str | None = None) -> Path:
    """Render a page in headless Chromium (software WebGL, no network but loopback) and save a PNG."""
    chromium = chromium or find_chromium()
    if chromium is None:
        raise FileNotFoundError("no chromium on PATH (Debian: apt-get install chromium)")
    target = str(url_or_path)
    if "://" not in target:
        target = Path(target).resolve().as_uri()
    png = Path(png).resolve()
    with tempfile.TemporaryDirectory(prefix="kinelab-chromium-") as profile:
        cmd = [chromium, *HEADLESS, "--disable-gpu", "--disable-quic", f"--user-data-dir={profile}",
               f"--window-size={size[0]},{size[1]}", f"--virtual-time-budget={wait_ms}", f"--screenshot={png}",
               target]
        subprocess.run(cmd, capture_output=True, timeout=120, check=False)
    if not png.exists():
        raise RuntimeError(f"chromium wrote no screenshot of {target}")
    return png


def changed_share(png_a: str | Path, png_b: str | Path, threshold: int = 24) -> float:
    """Share of pixels whose colour differs by more than ``threshold`` (0–255, any channel) between two PNGs."""
    a = np.asarray(Image.open(png_a).convert("RGB"), dtype=int)
    b = np.asarray(Image.open(png_b).convert("RGB"), dtype=int)
    if a.shape != b.shape:
        raise ValueError(f"screenshots differ in size: {a.shape} and {b.shape}")
    return float(np.mean(np.max(np.abs(a - b), axis=2) > threshold))


def without_robot_html(scene: Scene) -> str:
    """The same page (camera, frames, grid) with the robot's geometry removed: the reference picture."""
    scene.viewer[scene.root].delete()
    html = scene.static_html()
    scene.pinviz.loadViewerModel(rootNodeName=scene.root)
    return html


def changed_box(png_a: str | Path, png_b: str | Path, threshold: int = 24) -> tuple[int, int, int, int] | None:
    """(top, bottom, left, right) pixel rows and columns of the pixels that differ between two PNGs (None if none)."""
    a = np.asarray(Image.open(png_a).convert("RGB"), dtype=int)
    b = np.asarray(Image.open(png_b).convert("RGB"), dtype=int)
    mask = np.max(np.abs(a - b), axis=2) > threshold
    if not mask.any():
        return None
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return int(rows[0]), int(rows[-1]), int(cols[0]), int(cols[-1])


def grey_rows(png: str | Path) -> np.ndarray:
    """Per pixel row, how many pixels are grey (the floor grid's lines) rather than the blue background."""
    a = np.asarray(Image.open(png).convert("RGB"), dtype=int)
    r, g, b = a[..., 0], a[..., 1], a[..., 2]
    grey = (np.abs(r - g) < 30) & (np.abs(g - b) < 30) & (r > 90)
    return grey.sum(axis=1)
