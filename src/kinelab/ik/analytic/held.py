"""Solver "analytic" on a 7R arm: the branch nearest the start with the swept end joint held where the start has it.

A 7R arm with a swept form (:mod:`kinelab.ik.analytic.redundancy`: the Panda, the xArm7, the ERA, ...) has a
closed form for its other six joints at every value θ of one end joint. This is the free-joint solve an IKFast
user knows: per target, θ is first the start's own value (no start: the middle of the joint's range), and the
answer is the six's branch nearest the start's other six angles (:class:`~kinelab.core._analytic.ClosedForm`, one
compiled call for every row on every core, on the arm with that joint locked at 0: :func:`held_robot`); a target
with no branch within the limits there is tried at SAMPLES values of the joint over its range, nearest the
start's first; a target with none at any of them goes to FRDM from its start (the mode says how many). Every row
is judged as every batch row is, by the whole arm's FK within all seven joints' limits.

It applies where the six's compiled roots meet the pose as they come (:func:`applies`: at CHECKS seeded poses of
the arm, at their own held value): a six in its class only within the classifier's tolerances (the xArm7's) has
roots that need finishing one by one, and is refused by name (FRDM, or ``solve_all(..., redundancy=K)``, serves it).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from kinelab.core import threads
from kinelab.core._analytic import ROW_NOT_STARTED
from kinelab.errors import OptionError
from kinelab.geometry import stack_homogeneous
from kinelab.ik.analytic.batch import batch_starts
from kinelab.ik.analytic.branches import arm_of, prepared_form
from kinelab.ik.analytic.classify import classify, general_class
from kinelab.ik.analytic.redundancy import SweptArm, has_swept_form, samples, swept_arm
from kinelab.ik.batch import BatchIKResult, fresh_seed, judged_rows, prepare, run_batch
from kinelab.ik.frdm.batch import Rows
from kinelab.ik.request import Request, make_request, verdict_reserve
from kinelab.ik.result import Diagnostics, IKResult, Status
from kinelab.ik.targets import as_target_arrays
from kinelab.robot import Chain
from kinelab.typing import Configuration, Target, Targets

SAMPLES = 32  # values of the held joint tried over its range when the start's own value has no branch
CHECKS = 32  # seeded poses at which the six's compiled roots must meet the pose as they come
CHECK_SEED = 20261204


def applies(robot: Chain) -> bool:
    """True for a 7R arm with no closed form of its own but one with an end joint held (its swept form) whose
    compiled roots meet the pose without a finish (see the module's docstring)."""
    return robot.n == 7 and classify(robot).arm is None and general_class(robot).arm is None \
        and has_swept_form(robot) and not robot.derived("held form refused", _refusal)


def refuse_7r(robot: Chain) -> None:
    """Refuse solver "analytic" on a 7R arm with no closed form of its own that this module cannot take either.

    Raises:
        OptionError: naming why (no swept form, or a six whose roots need finishing).
    """
    if robot.n == 7 and classify(robot).arm is None and general_class(robot).arm is None and not applies(robot):
        raise OptionError("solver", "analytic", f"a 6R chain in an analytic class, or a 7R arm whose six are in one "
                          f"with an end joint held (docs/analytic.md); {robot.name}: {refusal(robot)}")


def refusal(robot: Chain) -> str:
    """Why solver "analytic" does not take this 7R arm ("" when it does: :func:`applies`)."""
    if not has_swept_form(robot):
        return "no end joint whose holding leaves six joints in a closed form"
    return robot.derived("held form refused", _refusal)


def _refusal(robot: Chain) -> str:
    six = held_robot(robot)
    req = make_request("frdm", None, 1e-6, 1e-6, None, 0, "refuse", None, "pose", "z", None)
    form = prepared_form(six, req)
    if form is None:
        return f"the six's compiled FK is not certified ({six.fk_certificate.reason})"
    sw, keep = swept_arm(robot), np.arange(7) != swept_arm(robot).joint
    Q = robot.random_qs(CHECKS, np.random.default_rng(CHECK_SEED))
    q6, errors = np.full((CHECKS, 6), np.nan), np.full((CHECKS, 2), np.nan)
    count, near = np.zeros(CHECKS, dtype=np.int64), np.zeros(CHECKS, dtype=np.uint8)
    form.nearest_batch(sub_targets(sw, robot.fk_batch(Q), Q[:, sw.joint]), np.ascontiguousarray(Q[:, keep]), q6,
                       errors, count, near, 1)
    if near.any() or not count.all():
        return (f"holding {robot.joints[sw.joint].name}, the six's compiled roots fell short of 1e-6 at "
                f"{int(((near > 0) | (count == 0)).sum())} of {CHECKS} seeded poses (their class holds within "
                "the classifier's tolerances, not exactly): use solver='frdm', or solve_all(..., redundancy=K)")
    return ""


def held_robot(robot: Chain) -> Chain:
    """The arm with its swept joint locked at 0: six joints in a closed form, built once per Chain."""
    return robot.derived("held at the swept joint", _locked)


def _locked(robot: Chain) -> Chain:
    joint = robot.joints[swept_arm(robot).joint].name
    return Chain.from_model(robot.model, tool=robot.tool, base=robot.base, locked={joint: 0.0},
                            name=f"{robot.name} ({joint} held)")


def held_values(robot: Chain, starts: np.ndarray | None, count: int) -> np.ndarray:
    """(count, 1 + SAMPLES) values [rad] of the swept joint per row, in the order they are tried: the start's own
    (no start: the middle of its range), then the SAMPLES cell midpoints of its range nearest it first."""
    sw = swept_arm(robot)
    grid = samples(float(robot.lower[sw.joint]), float(robot.upper[sw.joint]), SAMPLES)
    own = np.full(count, samples(float(robot.lower[sw.joint]), float(robot.upper[sw.joint]), 1)[0]) \
        if starts is None else starts[:, sw.joint]
    order = np.argsort(np.abs(grid[None, :] - own[:, None]), axis=1, kind="stable")
    return np.hstack([own[:, None], grid[order]])


def sub_targets(sw: SweptArm, H: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(B, 4, 4) poses the six other joints must reach with the swept joint at ``theta`` (B,) [rad]: each H turned
    by −θ about the joint's line (:meth:`SweptArm.sub_target`, for every row at once)."""
    a, c, s = sw.axis, np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
    cross = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    back = np.tile(np.eye(4), (len(theta), 1, 1))
    back[:, :3, :3] = c * np.eye(3) - s * cross + (1.0 - c) * np.outer(a, a)  # Rodrigues' turn by −θ
    back[:, :3, 3] = sw.point - back[:, :3, :3] @ sw.point
    return np.ascontiguousarray(back @ H if sw.joint == 0 else H @ back)


def held_rows(robot: Chain, H: np.ndarray, starts: np.ndarray | None, req: Request,
              deadline: float = np.inf) -> tuple[np.ndarray, np.ndarray, bool]:
    """Each row's answer (B, 7) [rad] from the six's closed form at the first value of :func:`held_values` with a
    branch within the limits (NaN where none has one), how many values each row tried, and whether ``deadline``
    (``time.perf_counter``'s clock [s]) passed with rows left untried.

    Raises:
        OptionError: the six's compiled FK is not certified (no compiled closed form to call).
    """
    sw, six = swept_arm(robot), held_robot(robot)
    form = prepared_form(six, replace(req, time_budget=None))
    if form is None:
        arm_of(six, req)  # a six in no class is refused by name; else the compiled FK is what is missing
        raise OptionError("solver", "analytic", f"a certified compiled FK for {six.name} "
                          f"({six.fk_certificate.reason})")
    B, keep = len(H), np.arange(7) != sw.joint
    values, q, tried = held_values(robot, starts, B), np.full((B, 7), np.nan), np.zeros(B, dtype=np.int64)
    left, slowest, began = np.arange(B), 0.0, time.perf_counter()
    for k in range(values.shape[1]):
        theta = values[left, k]
        q6, errors = np.full((len(left), 6), np.nan), np.full((len(left), 2), np.nan)
        count, near = np.zeros(len(left), dtype=np.int64), np.zeros(len(left), dtype=np.uint8)
        refs = np.empty((0, 6)) if starts is None else np.ascontiguousarray(starts[left][:, keep])
        form.nearest_batch(sub_targets(sw, H[left], theta), refs, q6, errors, count, near, threads.count(), deadline)
        tried[left[near != ROW_NOT_STARTED]] += 1
        found = count > 0
        q[left[found]] = np.insert(q6[found], sw.joint, theta[found], axis=1)
        left = left[~found]
        if not left.size:
            break
        now = time.perf_counter()
        slowest, began = max(slowest, now - began), now
        if now + slowest > deadline:  # the next value, as slow as the slowest so far, would end past it
            return q, tried, True
    return q, tried, False


def nearest_held(robot: Chain, targets: Targets, q0: Configuration | None, req: Request) -> BatchIKResult:
    """Solver "analytic" for every target of a 7R arm (see the module's docstring): q0 None, one start for every
    row, or (B, 7) starts [rad]; the request's budget, when it has one, bounds the whole batch (rows left when it
    runs out: NaN, status ``time_budget``).

    Raises:
        TargetError, ConfigurationError: a bad target or start, its index named.
        OptionError: the task is not "pose", or the six held have no certified compiled FK.
    """
    prepare(robot, req)  # FRDM's model for the rows no held value solves: built once, before the clock starts
    t0 = time.perf_counter()
    points, rotations = as_target_arrays(targets)
    H = stack_homogeneous(points, rotations)
    arm_of(held_robot(robot), req)  # the task is "pose" (named otherwise)
    starts = batch_starts(robot, q0, len(H), req)
    deadline = np.inf if req.time_budget is None else t0 + req.time_budget - verdict_reserve(req.time_budget)
    q, tried, late = held_rows(robot, H, starts, req, deadline)
    held = ~np.isnan(q[:, 0])
    # the rows no held value solves are left to FRDM below: judged here as not yet run
    rows = Rows(q, np.where(held, Status.CONVERGED.code, Status.TIME_BUDGET.code).astype(np.int8),
                np.maximum(tried - 1, 0), np.zeros(len(H), dtype=np.int64))
    mode = f"analytic ({robot.joints[swept_arm(robot).joint].name} held at the start's value, else at one of " \
           f"{SAMPLES} samples; the other six in closed form)"
    res = judged_rows(robot, rows, points, rotations, req, 0, t0, mode)
    res.solver = "analytic"
    rest = np.flatnonzero(~held)
    if rest.size and not late and time.perf_counter() < deadline:
        _by_frdm(robot, res, H, starts, rest, req, deadline)
    elif rest.size:
        res.mode += f"; {rest.size} of {len(H)} rows left when the budget ran out"
    res.wall_time = time.perf_counter() - t0
    return res


def _by_frdm(robot: Chain, res: BatchIKResult, H: np.ndarray, starts: np.ndarray | None, rest: np.ndarray,
             req: Request, deadline: float) -> None:
    """The rows no held value solves, by FRDM from their starts within what is left before ``deadline``, written
    into ``res``: row b with seed + b, as FRDM's batch runs it, so that a row's answer does not depend on which
    other rows share its batch (a cluster's chunks give the rows of one batch)."""
    seed = fresh_seed() if req.seed is None else req.seed
    for b in rest:
        left = None if req.time_budget is None else max(deadline - time.perf_counter(), 1e-5)
        frdm = run_batch(robot, H[b:b + 1], None if starts is None else starts[b:b + 1],
                         replace(req, seed=seed + int(b), time_budget=left))
        for name in ("q", "success", "status_code", "position_error", "rotation_error", "iterations", "restarts"):
            getattr(res, name)[b] = getattr(frdm, name)[0]
    res.seed = seed  # the FRDM rows' base seed (row b used seed + b)
    res.mode += f"; {rest.size} of {len(H)} rows by FRDM (no branch at any value tried)"


def nearest_held_one(robot: Chain, target: Target, q0: np.ndarray | None, req: Request) -> IKResult:
    """Solver "analytic" for one target of a 7R arm: the batch of one (:func:`nearest_held`), as a result."""
    t0 = time.perf_counter()
    res = nearest_held(robot, [target], None if q0 is None else q0[None, :], req)
    status = Status.of_codes(res.status_code)[0]
    return IKResult(q=res.q[0], success=bool(res.success[0]), status=status,
                    position_error=float(res.position_error[0]), rotation_error=float(res.rotation_error[0]),
                    iterations=int(res.iterations[0]), restarts=int(res.restarts[0]),
                    wall_time=time.perf_counter() - t0, solver="analytic", mode=res.mode, task=req.task_label,
                    judge=res.judge, diagnostics=Diagnostics(path="compiled"))
