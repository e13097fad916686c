"""The fingerprints of the compiled core's sources: what the build records and the import checks.

This module imports nothing of kinelab's, so that ``setup.py`` can load it by path while building (when neither
kinelab nor its dependencies are importable). The import checks the CRC-32 (``zlib``, already loaded by every
Python): it guards against a forgotten rebuild, not against tampering; the SHA-256 names the build in reports.
"""

from __future__ import annotations

import zlib
from pathlib import Path


def _sources(folder: Path) -> list[Path]:
    """The folder's Cython sources (``.pyx``, ``.pxd``, ``.pxi``) in name order."""
    return sorted([*folder.glob("*.pyx"), *folder.glob("*.pxd"), *folder.glob("*.pxi")])


def source_sha256(folder: Path) -> str:
    """SHA-256 over the folder's Cython sources in name order, each with its name (hex)."""
    import hashlib  # only the build and the reports ask for the SHA: start-up, which checks the CRC, skips OpenSSL

    h = hashlib.sha256()
    for path in _sources(folder):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    return h.hexdigest()


def source_crc32(folder: Path) -> str:
    """CRC-32 over the same bytes as :func:`source_sha256` (8 hex digits)."""
    crc = 0
    for path in _sources(folder):
        crc = zlib.crc32(path.name.encode() + b"\0" + path.read_bytes(), crc)
    return f"{crc:08x}"
