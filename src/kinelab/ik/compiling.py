"""Saying so when the kernels compile: the first use of a compiled path after an install (or an update of
kinelab or numba) compiles its numba kernels for this machine, which takes from seconds to a minute; every
later run loads the cached machine code in about a second. The first call of each path says once, before it
starts, that it compiles and about how long (a :class:`CompileNotice`, which the command line prints as one
line); ``kinelab warmup`` compiles every path ahead of time.

numba keys a cached kernel on its own source file only: a kernel whose file is unchanged keeps the machine code
it was compiled with even after a helper it calls (in another module) changed — a git pull into an editable
install could run old arithmetic silently. :func:`drop_stale_cache` removes kinelab's cached machine code
whenever the text of any module with numba kernels changed since it was written; the first announcement of
each process calls it.
"""

from __future__ import annotations

import hashlib
import warnings
from collections.abc import Iterable
from pathlib import Path
from typing import Any

# [s] each path's first compilation on the 2-core development machine, numba's own start included (a process
# that compiles two paths pays that start once): what the notice says it takes "about"
SECONDS = {"FRDM": 60, "the monitored FRDM loop": 55, "the FRDM batch": 90, "the path follower": 75,
           "the biquaternion solver": 35, "the closed form": 15, "the closed form's batch": 5, "the verdict": 10,
           "the prepared solver's input check": 5}


class CompileNotice(UserWarning):
    """kinelab compiles a path's kernels now (once per machine and version); the message says about how long."""


_SAID: set[str] = set()  # the paths looked at in this process (announced or found cached)
PACKAGE = Path(__file__).resolve().parents[1]
STAMP = "kinelab-kernels.sha1"


def drop_stale_cache(root: Path = PACKAGE) -> bool:
    """Remove the numba cache files (``__pycache__/*.nbi``, ``*.nbc``) under ``root`` when the modules with numba
    kernels there changed since the stamp ``__pycache__/kinelab-kernels.sha1`` was written, then write it.

    Args:
        root: the package folder (kinelab's own by default).

    Returns:
        True when cache files were removed. A read-only install changes nothing (numba then caches elsewhere,
        and an install replaces every file anyway).
    """
    digest = hashlib.sha1()
    for path in sorted(root.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text:
            digest.update(str(path.relative_to(root)).encode() + b"\0" + text)
    stamp = root / "__pycache__" / STAMP
    try:
        if stamp.read_text() == digest.hexdigest():
            return False
    except OSError:
        pass
    stale = [*root.glob("**/__pycache__/*.nbi"), *root.glob("**/__pycache__/*.nbc")]
    try:
        for cached in stale:
            cached.unlink()
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(digest.hexdigest())
    except OSError:
        return False
    return bool(stale)


def announce(path: str, kernels: Iterable[Any]) -> None:
    """Warn once per process that ``path`` compiles, if any of its numba ``kernels`` has no cached machine code.
    The cache is looked at on the path's first call only (reading its index costs tens of microseconds).

    Args:
        path: the path's name, a key of :data:`SECONDS`.
        kernels: its numba dispatchers (the entry points its first call compiles).
    """
    if path in _SAID:
        return
    if not _SAID:
        drop_stale_cache()
    _SAID.add(path)
    if all(_cached(k) for k in kernels):
        return
    warnings.warn(f"compiling {path} for this machine: about {SECONDS.get(path, 60)} s on 2 cores, once (later "
                  "runs load the cached code; `kinelab warmup` compiles every path ahead)", CompileNotice,
                  stacklevel=2)


def _cached(kernel: Any) -> bool:
    """True when numba holds cached machine code of this kernel's current source (its cache index lists an
    overload); True also when numba's cache cannot be read this way (better silent than wrong every run)."""
    try:
        return bool(kernel._cache._cache_file._load_index())
    except Exception:  # numba's private cache layout changed: say nothing rather than guess
        return True
