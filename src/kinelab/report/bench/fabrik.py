"""FABRIK (Aristidou & Lasenby, 2011) as a benchmark reference: the yardstick the FRDM paper names.

Position only, compiled like kinelab's own kernels so that a comparison is of methods, not of languages.
The chain's key points are the joint origins and the tool point (docs/methods.md §1.2's vector model).
One iteration is the paper's two passes:

- forward reaching: the tool point is put on the target and each key point, from the tip back, on the
  way towards its previous position at its fixed distance from the next, keeping its offset along the
  joint axis the next point turns about (the original places it on the straight line; with the offset
  the arms with shoulder and wrist offsets need two to four times fewer iterations);
- backward reaching, from the fixed base, with the joint constraints applied joint by joint as the
  paper's §5 does: joint k turns about its own axis (a hinge, not the original's ball joint), or slides
  along it, to bring the key points downstream of it nearest, in least squares, to where the forward
  pass put them, and is then clipped into its limits.

Iterations stop when the tool point is within the tolerance, or after ten iterations that gain less than
a thousandth of the best error (a stall: the adapter restarts from a seeded random configuration). The
joint limits are honoured, by the clipping; nothing else is (no self-collision, no rotation target).
"""

from __future__ import annotations

import itertools
import time

import numpy as np
from numba import njit

from kinelab.ik.chain import CONTINUOUS, PRISMATIC, chain_fk, chain_model
from kinelab.report.bench.protocol import TOL_POS, Case, SolveFn
from kinelab.robot import Robot

MAX_ITERATIONS = 500  # per attempt; a converging run needs tens to a few hundred, a stall ends it sooner
PROGRESS, PATIENCE = 1e-3, 10  # a stall: ten iterations without gaining a thousandth of the best error
SAME_POINT = 1e-9  # [m] a key point nearer a joint's axis than this does not move when the joint turns


@njit(cache=True)
def forward_reach(points, axes, target, reached):
    """``reached`` ← the forward pass: the last point on ``target``, each earlier one (joint k's origin) on the
    way back towards its old position, at its old distance from the next and with its old offset along
    joint k's axis as the chain stands (the next point turns about that axis: the offset is invariant)."""
    m = points.shape[0] - 1
    reached[m] = target
    for k in range(m - 1, -1, -1):
        seg = points[k + 1] - points[k]
        e = axes[k]
        axial = np.dot(seg, e)
        radial = np.sqrt(max(np.dot(seg, seg) - axial * axial, 0.0))
        d = points[k] - reached[k + 1]
        d = d - e * np.dot(d, e)
        dist = np.sqrt(np.dot(d, d))
        reached[k] = reached[k + 1] - axial * e
        if dist > SAME_POINT:
            reached[k] += d * (radial / dist)


@njit(cache=True)
def _turn(k, e, o, p, reached, kind):
    """Joint k's displacement (about or along its axis e[k] through o[k]) that brings the key points downstream
    of it (origins o[k+1:], tool point p) nearest, in least squares, to where the forward pass put them."""
    n = o.shape[0]
    sin_part = cos_part = slide = 0.0
    for j in range(k + 1, n + 1):
        current = o[j] if j < n else p
        if kind == PRISMATIC:
            slide += np.dot(e[k], reached[j] - current)
            continue
        v = current - o[k]
        d = reached[j] - o[k]
        v = v - e[k] * np.dot(e[k], v)
        d = d - e[k] * np.dot(e[k], d)
        sin_part += np.dot(e[k], np.cross(v, d))
        cos_part += np.dot(v, d)
    if kind == PRISMATIC:
        return slide / (n - k)
    if sin_part * sin_part + cos_part * cos_part < SAME_POINT ** 4:
        return 0.0  # every downstream point lies on the axis: turning the joint moves none of them
    return np.arctan2(sin_part, cos_part)


@njit(cache=True)
def _clip(value, kind, lower, upper):
    if kind == CONTINUOUS:
        return np.arctan2(np.sin(value), np.cos(value))
    if kind != PRISMATIC and (value < lower or value > upper):
        shifted = value + 2.0 * np.pi * np.ceil((lower - value) / (2.0 * np.pi))
        if shifted <= upper:
            return shifted
    return min(max(value, lower), upper)


@njit(cache=True)
def attempt(ch, lower, upper, target, q, tol, max_iterations):
    """FABRIK from q (changed in place) towards the tool point ``target`` [m]; returns (iterations, error [m])."""
    n = q.shape[0]
    e, o, R = np.empty((n, 3)), np.empty((n, 3)), np.empty((3, 3))
    p = np.empty(3)
    points, reached = np.empty((n + 1, 3)), np.empty((n + 1, 3))
    chain_fk(ch, q, e, o, p, R)
    error = best = np.sqrt(np.sum((p - target) ** 2))
    q_best, since, it = q.copy(), 0, 0
    if error <= tol:
        return 0, error
    for it in range(max_iterations):
        points[:n] = o
        points[n] = p
        forward_reach(points, e, target, reached)
        for k in range(n):
            q[k] = _clip(q[k] + _turn(k, e, o, p, reached, ch.kind[k]), ch.kind[k], lower[k], upper[k])
            chain_fk(ch, q, e, o, p, R)
        error = np.sqrt(np.sum((p - target) ** 2))
        if error <= tol:
            return it + 1, error
        if error < best * (1.0 - PROGRESS):
            best, since = error, 0
            q_best[:] = q
        else:
            since += 1
            if since == PATIENCE:
                break
    if error > best:
        q[:] = q_best
    return it + 1, min(best, error)


def prepare(robot: Robot, budget: float, max_attempts: int | None = None) -> SolveFn:
    """The bench adapter: FABRIK attempts from the case's start, then from seeded random starts, until one
    reaches the target point within TOL_POS, the budget [s] is spent or ``max_attempts`` have run (None: no
    count; a test bounds the attempts, not the time, so that its verdict does not depend on the machine's load)."""
    model = chain_model(robot)
    ch, lower, upper = model.chain, model.lower, model.upper
    attempt(ch, lower, upper, np.zeros(3), robot.random_q(0), TOL_POS, 1)  # compile outside the budget

    def run(case: Case, seed: int) -> tuple:
        t_end = time.perf_counter() + budget
        rng = np.random.default_rng(seed)
        q, target, total = case.q_start.astype(float), np.ascontiguousarray(case.oMtarget.translation), 0
        for tries in itertools.count(1):
            iterations, error = attempt(ch, lower, upper, target, q, TOL_POS * 0.5, MAX_ITERATIONS)
            total += iterations
            if error <= TOL_POS * 0.5 or time.perf_counter() > t_end or tries == max_attempts:
                break
            q = robot.random_q(rng)
        return q, total

    return run
