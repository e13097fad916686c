"""The fingerprint of the compiled core's sources: what the build records and the import checks.

This module imports nothing of kinelab's, so that ``setup.py`` can load it by path while building (when neither
kinelab nor its dependencies are importable).
"""

from __future__ import annotations

import hashlib
from pathlib import Path


def source_sha256(folder: Path) -> str:
    """SHA-256 over the folder's Cython sources (``.pyx``, ``.pxd``, ``.pxi``), in name order, each with its name."""
    h = hashlib.sha256()
    for path in sorted([*folder.glob("*.pyx"), *folder.glob("*.pxd"), *folder.glob("*.pxi")]):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    return h.hexdigest()
