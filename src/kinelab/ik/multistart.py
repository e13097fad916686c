"""Seeded restarts run inside a compiled kernel, a chunk at a time so that the clock is looked at."""

from __future__ import annotations

import numpy as np

from kinelab.core._frdm import draw_configuration, windows_of
from kinelab.ik.chain import PRISMATIC, ChainModel


def seed_state(seed: int | None) -> np.ndarray:
    """A non-zero 64-bit state for a kernel's xorshift generator (splitmix64 of the seed; None: fresh entropy)."""
    mask = (1 << 64) - 1
    entropy = np.random.SeedSequence().entropy if seed is None else seed
    x = int(entropy) & mask  # type: ignore[arg-type]
    x = (x + 0x9E3779B97F4A7C15) & mask
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & mask
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & mask
    return np.array([(x ^ (x >> 31)) | 1], dtype=np.uint64)


def seed_states(seed: int, count: int) -> np.ndarray:
    """(count, 1) generator states, row b's equal to ``seed_state(seed + b)`` (splitmix64, vectorised)."""
    with np.errstate(over="ignore"):
        x = np.arange(count, dtype=np.uint64) + np.uint64(int(seed) % (1 << 64))  # int: a NumPy seed may be 2**64 - 1
        x = x + np.uint64(0x9E3779B97F4A7C15)
        x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        x = (x ^ (x >> np.uint64(31))) | np.uint64(1)
    return x.reshape(count, 1)


def first_start(q0: np.ndarray | None, kind: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                rng_state: np.ndarray) -> np.ndarray:
    """A kernel's first start: a copy of q0, or (q0 None) a configuration drawn from the kernel's generator,
    so that a solve without q0 and a batch row with the same seed start alike."""
    if q0 is not None:
        return np.array(q0, dtype=float)
    q = np.empty(kind.shape[0])
    draw_configuration(q, kind, lower, upper, rng_state)
    return q


def restart_windows(cm: ChainModel, q_start: np.ndarray, pstar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where restarts are drawn: the joint limits, except for a prismatic joint ahead of every rotary joint
    whose range exceeds twice the chain's length L (a mobile base's ±10 m platform, not a boom). There,
    within L of the value that carries the tool from where it is at the start to the target point along the
    joint's axis, clipped to the limits: a restart anywhere in the platform's box leaves the arm metres from
    a target it could reach.

    Args:
        cm: the chain.
        q_start: the first start [rad or m].
        pstar: the target point [m], base frame.

    Returns:
        (lower, upper) of the restarts [rad or m].
    """
    wide = wide_base(cm)
    if not wide.any():
        return cm.lower, cm.upper
    return windows_of(cm.chain, np.ascontiguousarray(q_start, dtype=float), np.ascontiguousarray(pstar, dtype=float),
                      cm.lower, cm.upper, wide.astype(np.uint8), float(cm.length))


def wide_base(cm: ChainModel) -> np.ndarray:
    """(n,) True at a prismatic joint ahead of every rotary joint whose range exceeds twice the chain's length:
    the joints whose restart window follows the target (:func:`restart_windows`)."""
    rotary = np.flatnonzero(cm.kind != PRISMATIC)
    before_arm = np.arange(cm.n) < (rotary[0] if rotary.size else cm.n)  # a base's joints come first
    wide: np.ndarray = (cm.kind == PRISMATIC) & (cm.upper - cm.lower > 2.0 * cm.length) & before_arm
    return wide


def clock_chunk(joint_steps: int, n: int) -> int:
    """Iterations of an n-joint kernel between two looks at the clock: the work of ``joint_steps`` single-joint
    steps, so that a budget is overrun by about the same time whatever the chain's length (at least 4)."""
    return max(4, joint_steps // max(1, n))
