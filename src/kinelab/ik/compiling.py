"""Saying so when the kernels compile: the first use of a compiled path after an install (or an update of
kinelab or numba) compiles its numba kernels for this machine, which takes from seconds to a minute; every
later run loads the cached machine code in about a second. The first call of each path says once, before it
starts, that it compiles and about how long (a :class:`CompileNotice`, which the command line prints as one
line); ``kinelab warmup`` compiles every path ahead of time.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable
from typing import Any

# [s] each path's first compilation on the 2-core development machine, numba's own start included (a process
# that compiles two paths pays that start once): what the notice says it takes "about"
SECONDS = {"FRDM": 60, "the monitored FRDM loop": 55, "the FRDM batch": 90, "the path follower": 75,
           "the biquaternion solver": 35, "the closed form": 15, "the closed form's batch": 5, "the verdict": 10,
           "the prepared solver's input check": 5}


class CompileNotice(UserWarning):
    """kinelab compiles a path's kernels now (once per machine and version); the message says about how long."""


_SAID: set[str] = set()  # the paths looked at in this process (announced or found cached)


def announce(path: str, kernels: Iterable[Any]) -> None:
    """Warn once per process that ``path`` compiles, if any of its numba ``kernels`` has no cached machine code.
    The cache is looked at on the path's first call only (reading its index costs tens of microseconds).

    Args:
        path: the path's name, a key of :data:`SECONDS`.
        kernels: its numba dispatchers (the entry points its first call compiles).
    """
    if path in _SAID:
        return
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
