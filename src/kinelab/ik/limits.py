"""Joint-limit arithmetic shared by the solvers: wrap revolute joints by 2π into their limits, then clip."""

from __future__ import annotations

import numpy as np

from kinelab.geometry import TWO_PI, turns_into, wrap_to_pi
from kinelab.robot import Chain


class PinLimits:
    """Bounded scalar joints of a robot, indexed in Pinocchio's q, for fast projection inside loops."""

    def __init__(self, robot: Chain):
        bounded = [j for j in robot.joints if j.kind != "continuous"]
        self.idx = np.array([j.idx_q for j in bounded], dtype=int)
        self.lower = np.array([j.lower for j in bounded])
        self.upper = np.array([j.upper for j in bounded])
        self.revolute = np.array([j.kind == "revolute" for j in bounded], dtype=bool)

    def project(self, q_pin: np.ndarray) -> np.ndarray:
        """Wrap revolute joints by multiples of 2π towards their limits, then clip everything (in place)."""
        if self.idx.size:
            q_pin[self.idx] = wrap_and_clip(q_pin[self.idx], self.lower, self.upper, self.revolute)
        return q_pin


def wrap_and_clip(x: np.ndarray, lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Bring values into [lower, upper]: revolute ones first by ±2πk (same pose), then clip."""
    return np.clip(turns_into(x, lower, upper, where=revolute), lower, upper)


def inside_limits(q: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                  slack: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows of revolute angles q (m, n) [rad] turned by whole turns into [lower, upper] where they can be, and those
    within ``slack`` [rad] of it clipped: (the kept rows, clipped; which rows were kept (m,))."""
    x = turns_into(q, np.broadcast_to(lower, q.shape), np.broadcast_to(upper, q.shape))
    keep = np.asarray(((x >= lower - slack) & (x <= upper + slack)).all(axis=1))
    return np.clip(x[keep], lower, upper), keep


def nearest_inside(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, ref: np.ndarray | None,
                   slack: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows of revolute angles q (m, n) [rad], each angle's copy nearest ``ref`` (None: nearest 0), then
    :func:`inside_limits`."""
    base = np.zeros(q.shape[-1]) if ref is None else ref
    return inside_limits(q + TWO_PI * np.round((base - q) / TWO_PI), lower, upper, slack)


def wrap_q(robot: Chain, q: np.ndarray) -> np.ndarray:
    """q with each out-of-limit revolute joint shifted by a multiple of 2π into its limits, where one
    exists (the pose is unchanged); other values are returned as they are."""
    q = np.asarray(q, dtype=float)
    revolute = np.array([k == "revolute" for k in robot.joint_kinds])
    outside = revolute & ((q < robot.lower) | (q > robot.upper))
    lowest = q + TWO_PI * np.ceil((robot.lower - q) / TWO_PI)  # the first turn of q at or above the lower limit
    return np.where(outside & (lowest <= robot.upper), lowest, q)


def turned_verdict(robot: Chain, H_target: np.ndarray, q: np.ndarray,
                   axis: int = -1) -> tuple[np.ndarray, float, float, bool]:
    """The judge's word on an answer q (n floats, C-contiguous) against H_target (4 × 4, base frame), on the answer
    turned into the limits: (q or :func:`wrap_q`'s turn of it, position error [m], rotation error [rad], within the
    limits). Only an answer outside its limits is turned (and judged again): the usual call pays nothing."""
    dp, dr, within = robot.verdict(H_target, q, axis)
    if within:
        return q, dp, dr, within
    turned = wrap_q(robot, q)
    if np.array_equal(turned, q):
        return q, dp, dr, within
    turned = np.ascontiguousarray(turned)
    dp, dr, within = robot.verdict(H_target, turned, axis)
    return turned, dp, dr, within


def distance(robot: Chain, q: np.ndarray, ref: np.ndarray) -> float:
    """max |q_i − ref_i| over the joints [rad or m], revolute and continuous joints modulo 2π."""
    return float(distances(robot, q, np.asarray(ref, dtype=float)[None, :])[0])


def distances(robot: Chain, q: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """:func:`distance` from q to each row of ``refs`` (k × n), in one pass [rad or m]."""
    d = np.asarray(q, dtype=float)[None, :] - np.asarray(refs, dtype=float)
    revolute = np.array([k != "prismatic" for k in robot.joint_kinds])
    d[:, revolute] = wrap_to_pi(d[:, revolute])
    found: np.ndarray = np.max(np.abs(d), axis=1)
    return found
