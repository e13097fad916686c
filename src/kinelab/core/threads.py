"""How many threads kinelab's compiled batches use: every core this process may run on, unless the environment
variable ``KINELAB_THREADS`` or :func:`set_count` says fewer (a cluster's worker runs one, its cluster giving the
parallelism). Answers never depend on it: each row of a batch is solved alone."""

from __future__ import annotations

import os

from kinelab.errors import OptionError
from kinelab.values import is_whole

_COUNT: list[int] = []


def available() -> int:
    """The cores this process may run on (its CPU affinity where the system tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def count() -> int:
    """The threads a compiled batch runs on now (≥ 1)."""
    if _COUNT:
        return _COUNT[-1]
    told = os.environ.get("KINELAB_THREADS", "").strip()
    if told.isdigit() and int(told) >= 1:
        return min(int(told), available())
    return available()


MAX_THREADS = 64  # threads a batch may be given beyond the cores (OpenMP ends the process when it cannot start one)


def set_count(threads: int | None) -> None:
    """Run compiled batches on ``threads`` threads from now on in this process (None: back to the default).

    Raises:
        OptionError: ``threads`` is not a positive integer.
    """
    if threads is None:
        _COUNT.clear()
        return
    most = max(MAX_THREADS, available())
    if not is_whole(threads, 1, most):
        raise OptionError("threads", threads, f"an integer from 1 to {most} (this machine has {available()} cores)")
    _COUNT[:] = [threads]
