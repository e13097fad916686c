"""A redundant arm's jump undone: the path followed back from where the follower jumped to, then forward again
with the self-motion drawn towards that backward path, so that the arm arrives there without jumping.

On an arm with more joints than its task, the answers to one target form a self-motion, and the limits cut it
into arcs. Following a path, the follower stays on the arc it started on; an arc can shrink to nothing while
another, which the path's own configurations lie on, lives on, and the follower must then jump to it (the trust
issues' Panda path: joint 1 runs into its limit at sample 1,449 of 2,000). The arc it jumps to is a live one, so
the path followed back from there stays on it; where that backward path meets the start's self-motion the arm can
move over to it within the limits, and the forward pass drawn towards it does so a little each sample (no faster
than the push from the limits moves it). The rejoined path is kept only if it meets at least as many samples as
the first and jumps fewer times.
"""

from __future__ import annotations

import numpy as np

from kinelab.ik.frdm.follower import Run
from kinelab.ik.result import Status, TrackResult
from kinelab.ik.targets import TargetArrays

MAX_REJOINS = 4  # jumps undone on one path, each a backward and a forward pass of the compiled follower


def rejoined(targets: TargetArrays, q0: np.ndarray, followed: TrackResult, jump_limit: float | None,
             run: Run) -> TrackResult:
    """The path with each jump undone where a backward pass allows it (see the module's docstring).

    Args:
        targets: the path's targets (points [m], rotations), base frame.
        q0: the configuration before the first sample [rad or m].
        followed: the follower's path from q0.
        jump_limit: the largest joint step [rad or m] that is not a jump (None: no jumps, the path as it is).
        run: the follower with the path's settings: (targets, start, toward) → its path, ``toward`` the (N, n)
            configurations its null-space term draws towards (NaN rows: none).

    Returns:
        ``followed`` or a rejoined path that meets at least as many samples and jumps fewer times.
    """
    if jump_limit is None:
        return followed
    for _ in range(MAX_REJOINS):
        k = first_jump(followed, q0, jump_limit)
        if k is None:
            return followed
        again = _rejoin(targets, q0, followed, k, jump_limit, run)
        if again is None or not _better(again, followed, q0, jump_limit):
            return followed
        followed = again
    return followed


def first_jump(path: TrackResult, q0: np.ndarray, jump_limit: float) -> int | None:
    """The first met sample reached by a joint step above ``jump_limit`` [rad or m] from the last met sample before
    it (q0 before the first), or None."""
    jumps = jumped(path, q0, jump_limit)
    return int(jumps[0]) if jumps.size else None


def jumped(path: TrackResult, q0: np.ndarray, jump_limit: float) -> np.ndarray:
    """The met samples reached by a joint step above ``jump_limit`` [rad or m] from the last met sample before each
    (q0 before the first): a missed sample is skipped, as a controller holds where it was."""
    met = np.flatnonzero(path.status_code == Status.CONVERGED.code)
    if met.size == 0:
        return met
    before = np.vstack([q0[None, :], path.q[met[:-1]]])
    return met[np.abs(path.q[met] - before).max(axis=1) > jump_limit]


def _rejoin(targets: TargetArrays, q0: np.ndarray, followed: TrackResult, k: int, jump_limit: float,
            run: Run) -> TrackResult | None:
    """The forward pass drawn towards the path followed back from sample k's answer, or None when that backward
    path misses a sample or jumps itself."""
    points, rotations = targets
    back_targets = TargetArrays(np.ascontiguousarray(points[k::-1]), np.ascontiguousarray(rotations[k::-1]))
    back = run(back_targets, followed.q[k], None)
    if not np.all(back.status_code == Status.CONVERGED.code) or jumped(back, followed.q[k], jump_limit).size:
        return None
    toward = np.full_like(followed.q, np.nan)
    toward[: k + 1] = back.q[::-1]
    return run(targets, q0, toward)


def _better(again: TrackResult, followed: TrackResult, q0: np.ndarray, jump_limit: float) -> bool:
    met = Status.CONVERGED.code
    return bool(np.sum(again.status_code == met) >= np.sum(followed.status_code == met)
                and jumped(again, q0, jump_limit).size < jumped(followed, q0, jump_limit).size)
