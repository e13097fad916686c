"""The compiled path follower's Python side: checks, the kernel call, Pinocchio's verdict per sample."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from kinelab.core import _follow
from kinelab.geometry import stack_homogeneous
from kinelab.ik.chain import chain_model
from kinelab.ik.codes import CONVERGED, status_of
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm.options import ORDERS, FRDMOptions
from kinelab.ik.limits import wrap_q
from kinelab.ik.multistart import seed_state
from kinelab.ik.request import verdict_reserve
from kinelab.ik.result import SingularEvent, Status, TrackResult
from kinelab.ik.targets import TargetArrays
from kinelab.ik.tasks import POSE, Task
from kinelab.robot import Chain

REST_WEIGHT = 0.01  # objective units (the weighted pose error is ~1 at a chain length's distance)
REST_SWEEPS = 10  # sweeps of the first phase of a sample
LM_ITERATIONS = 20  # Levenberg–Marquardt steps of the polish (mode "frdm+lm")
CENTRE_PULL = 0.01  # share of the way from the previous answer to mid-range taken as the rest configuration


Run = Callable[[TargetArrays, np.ndarray, "np.ndarray | None"], TrackResult]
"""The follower with a path's settings fixed: (targets, start, toward) → its path (:func:`follow`'s ``toward``)."""


def follow(robot: Chain, targets: TargetArrays, q0: np.ndarray, tol_pos: float, tol_rot: float, max_sweeps: int,
           rest_weight: float | None, opts: FRDMOptions, task: Task = POSE, seed: int | None = None,
           time_budget: float | None = None, t_start: float | None = None,
           toward: np.ndarray | None = None, pace: float = 0.0) -> TrackResult:
    """Solve every sample of a path in the compiled follower; each answer judged by Pinocchio.

    Args:
        robot: the robot.
        targets: oMtarget per sample, checked (:func:`~kinelab.ik.targets.as_target_arrays`).
        q0: checked start configuration [rad or m].
        tol_pos: per-sample position tolerance [m].
        tol_rot: per-sample rotation tolerance [rad].
        max_sweeps: sweep cap of each phase of a sample.
        rest_weight: weight of the rest term (None: :data:`REST_WEIGHT` on arms with more than six joints).
        opts: FRDM options (order, weights, stall window).
        task: the components judged (FRDM's mode in ``opts`` is the same task).
        seed: seed of the recovery's restarts (None: fresh entropy).
        time_budget: wall-clock budget [s] of the whole path (None: none); the samples not started when it runs
            out are left unsolved (NaN, status ``time_budget``).
        t_start: the ``time.perf_counter()`` value the budget counts from (None: now).
        toward: (N, n) per sample, the configuration [rad or m] a redundant arm's self-motion is drawn towards in
            place of the push from its limits (None, or a NaN row: the push); :mod:`kinelab.ik.frdm.rejoin`.
        pace: the path's typical joint step [rad or m]: a redundant arm's null-space term may always move a joint
            this far a sample (0: only half the task's own step); :func:`path_pace`.

    Returns:
        A :class:`~kinelab.ik.frdm.tracking.TrackResult` with mode "frdm (compiled follower)". Continuous
        joints are not wrapped: the rows are a continuous path, as a controller wants them.
    """
    rest_weight = effective_rest_weight(robot, rest_weight)
    points, rotations = targets
    cm = chain_model(robot)
    count = points.shape[0]
    Q, codes, sweeps = np.empty((count, robot.n)), np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
    order = ORDERS[opts.order if opts.order != "mixed" else "tip2base"]
    t0 = time.perf_counter()
    deadline = _deadline(time_budget, t0 if t_start is None else t_start, count)
    _follow.follow(Q, np.array(q0, dtype=float), cm.chain, _objective(cm, opts, tol_pos, tol_rot),
                   np.ascontiguousarray(points, dtype=float), np.ascontiguousarray(rotations, dtype=float),
                   opts.settings(), order, int(max_sweeps), float(rest_weight), REST_SWEEPS, _centre(cm, q0),
                   CENTRE_PULL, LM_ITERATIONS if opts.polish else 0, seed_state(seed), deadline, codes, sweeps,
                   None if toward is None else np.ascontiguousarray(toward, dtype=float), float(pace))
    dp, dr, ok = judged_path(robot, Q, points, rotations, task, tol_pos, tol_rot)
    per_sample = (time.perf_counter() - t0) / count  # the kernel and Pinocchio's check of every answer
    return TrackResult(Q, dp, dr, _statuses(ok, codes), sweeps, np.full(count, per_sample), _stall_events(codes), [],
                       mode=opts.label + ("+lm" if opts.polish else "") + " (compiled follower)")


PILOT_STRIDE = 10  # the pilot pass that measures a path's pace solves one sample in this many


def path_pace(targets: TargetArrays, q0: np.ndarray, run: Run) -> float:
    """A path's typical joint step [rad or m]: the median joint step of a pilot pass of the follower (``run``: targets,
    start, toward → its path) over one sample in :data:`PILOT_STRIDE`, divided by the stride; 0 for a path too short
    to measure or a pilot that meets no sample. A redundant arm's self-motion may turn this far a sample wherever the
    path itself slows down (:func:`follow`'s ``pace``)."""
    points, rotations = targets
    if points.shape[0] < 2 * PILOT_STRIDE:
        return 0.0
    pilot = TargetArrays(np.ascontiguousarray(points[::PILOT_STRIDE]), np.ascontiguousarray(rotations[::PILOT_STRIDE]))
    path = run(pilot, q0, None)
    met = steps_from(q0, path.q)[path.status_code == Status.CONVERGED.code]
    return float(np.median(met)) / PILOT_STRIDE if met.size else 0.0


def steps_from(q0: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """(K,) each row's largest joint step [rad or m] from the row before (q0 before the first); NaN rows give NaN."""
    steps: np.ndarray = np.abs(np.diff(np.vstack([np.asarray(q0, dtype=float)[None, :], Q]), axis=0)).max(axis=1)
    return steps


def effective_rest_weight(robot: Chain, rest_weight: float | None) -> float:
    """The rest term's weight on this robot: the one given, or :data:`REST_WEIGHT` beyond six joints (else 0). A
    weight above 0 is what makes the follower treat the arm as redundant (its null-space term, the rejoin)."""
    if rest_weight is None:
        return REST_WEIGHT if robot.n > 6 else 0.0
    return float(rest_weight)


def _deadline(time_budget: float | None, t_start: float, count: int) -> float:
    """When the kernel stops: early enough to leave time for the verdict on every sample (≈ 2 µs each, cold)."""
    if time_budget is None:
        return float(np.inf)
    return t_start + float(time_budget) - verdict_reserve(float(time_budget)) - 2e-6 * count


def _statuses(ok: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """Each sample's Status code: converged where the judge confirmed it, else why the kernel stopped (a kernel
    that converged where the judge did not agree: max_iterations)."""
    out = np.full(codes.shape[0], Status.CONVERGED.code, dtype=np.int8)
    failed = ~ok
    for code in np.unique(codes[failed]):
        status = Status.MAX_ITERATIONS if code == CONVERGED else status_of(int(code))
        out[failed & (codes == code)] = status.code
    return out


def _stall_events(codes: np.ndarray) -> list[SingularEvent]:
    """One undiagnosed stall event per sample at which the follower's monitor fired."""
    return [SingularEvent("stall", "not diagnosed (compiled follower)", sample=int(k))
            for k in np.flatnonzero((codes == kernel.STALL_STEP) | (codes == kernel.STALL_WINDOW))]


def _centre(cm: Any, q0: np.ndarray) -> np.ndarray:
    """The middle of each bounded joint's limits (q0's value for an unbounded joint) [rad or m]."""
    bounded = np.isfinite(cm.lower) & np.isfinite(cm.upper)
    middle = (np.where(bounded, cm.lower, 0.0) + np.where(bounded, cm.upper, 0.0)) / 2
    centre: np.ndarray = np.where(bounded, middle, q0)
    return centre


def _objective(cm: Any, opts: FRDMOptions, tol_pos: float, tol_rot: float) -> Any:
    """The follower's objective shared by every sample (the target set per sample by the kernel)."""
    lower, upper = (cm.lower, cm.upper) if opts.use_limits else (np.full(cm.n, -np.inf), np.full(cm.n, np.inf))
    return kernel.Objective(lower, upper, np.ones(cm.n, dtype=np.bool_), np.zeros(3), np.eye(3),
                            opts.position_weight(cm.length), opts.axis_weights(), float(tol_pos), float(tol_rot),
                            opts.mode != "orientation", opts.mode != "position", kernel.no_rest(cm.n), 0.0, -1)


def judged_path(robot: Chain, Q: np.ndarray, points: np.ndarray, rotations: np.ndarray, task: Task, tol_pos: float,
            tol_rot: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The judge's word on every sample the follower started (the others are NaN rows): position errors [m],
    rotation errors [rad], and whether the task's components are met within the limits. A joint past a limit by
    whole turns (``use_limits=False``) is turned back into Q first, in place: the same pose."""
    count = Q.shape[0]
    started = np.isfinite(Q).all(axis=1)
    dp, dr = np.full(count, np.nan), np.full(count, np.nan)
    ok = started.copy()
    if started.any():
        Q[started] = wrap_q(robot, Q[started])
        dp[started], dr[started] = task.errors_batch(stack_homogeneous(points[started], rotations[started]),
                                                     robot.fk_batch(Q[started]))
        ok[started] = task.met_batch(dp[started], dr[started], tol_pos, tol_rot) & \
            robot.within_limits_batch(Q[started])
    return dp, dr, ok


