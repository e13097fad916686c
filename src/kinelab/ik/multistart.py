"""Seeded restarts run inside a compiled kernel, a chunk at a time so that the clock is looked at."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np


def seed_state(seed: int | None) -> np.ndarray:
    """A non-zero 64-bit state for a kernel's xorshift generator (splitmix64 of the seed; None: fresh entropy)."""
    mask = (1 << 64) - 1
    entropy = np.random.SeedSequence().entropy if seed is None else seed
    x = int(entropy) & mask  # type: ignore[arg-type]
    x = (x + 0x9E3779B97F4A7C15) & mask
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & mask
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & mask
    return np.array([(x ^ (x >> 31)) | 1], dtype=np.uint64)


def run_in_chunks(chunk: Callable[[int], int], attempts: int, stats: np.ndarray, deadline: float,
                  converged: int) -> int:
    """Call ``chunk(attempts_left)`` (a kernel run that adds its attempts to stats[0]) until it returns
    ``converged``, the attempts are spent or the deadline passes; returns the last code."""
    code = -1
    while attempts > 0:
        before = stats[0]
        code = chunk(attempts)
        attempts -= int(stats[0] - before)
        if code == converged or time.perf_counter() > deadline:
            break
    return code
