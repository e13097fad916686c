"""Every branch of many poses at once, and the branch nearest a start for each: the closed forms' batches, in one
compiled call over the poses where the class allows, each answer judged within the joint limits."""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from kinelab.core import threads
from kinelab.core._analytic import ROW_NOT_STARTED, ClosedForm
from kinelab.errors import ConfigurationError, count_of
from kinelab.geometry import pose_errors, stack_homogeneous
from kinelab.ik.analytic.classify import ArmClass
from kinelab.ik.analytic.general import roots_within
from kinelab.ik.analytic.kernel import GENERAL_6R, MAX_ROWS, PIEPER_6R, branches_batch
from kinelab.ik.batch import BatchIKResult
from kinelab.ik.request import Request, make_request, verdict_reserve
from kinelab.ik.result import Status
from kinelab.ik.targets import as_target_arrays, reach_bound
from kinelab.robot import Chain
from kinelab.typing import Configuration, Targets

if TYPE_CHECKING:
    from kinelab.collision.model import CollisionModel

from kinelab.ik.analytic.branches import (
    CONTINUUM,
    SAME,
    _method,
    analytic_all,
    arm_of,
    arm_roots,
    limit_slack,
    prepared_form,
)
from kinelab.ik.analytic.nearest import analytic_one


@dataclass(frozen=True, eq=False)
class BranchBatch:
    """Every branch of each pose of a batch, each confirmed by the judge within the limits.

    Attributes:
        q: (B, MAX_ROWS, n) branches [rad], the first ``count[b]`` rows of pose b; NaN after them.
        count: (B,) branches per pose (0: none within the limits, which the closed form proves).
        found: (B, MAX_ROWS) roots merged into each branch (2 at a double root); 0 after ``count``.
        free: (B, MAX_ROWS) the branch is one of a continuum (a singular pose).
        position_error: (B, MAX_ROWS) [m] and rotation_error: (B, MAX_ROWS) [rad] of each branch, by the FK
            ``judge`` names; NaN after ``count``.
        method: "closed form" (every branch), "search" (the 1-D search: every branch, measured complete) or
            "elimination" (the general 6R elimination).
        judge: whose FK judged the branches.
        uncertified: the elimination's reason per pose that its set is not certified ("" where it is); None for
            the other methods.
        late: (B,) poses left unsolved when the time budget ran out (count 0, NaN); None: no budget was given.
    """

    q: np.ndarray
    count: np.ndarray
    found: np.ndarray
    free: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    method: str = "closed form"
    judge: str = "Pinocchio FK"
    uncertified: list[str] | None = None
    late: np.ndarray | None = None


def all_branches_batch(robot: Chain, targets: Targets, tol_pos: float = 1e-6, tol_rot: float = 1e-6,
                       time_budget: float | None = None) -> BranchBatch:
    """Every branch of each pose in ``targets`` (what :func:`analytic_all` gives each, copies nearest 0), on all
    cores: where the robot's compiled FK is certified the closed form and the judge run in one compiled pass; a pose
    with a root short of the tolerances but near them is solved by :func:`analytic_all` (which finishes it).

    Args:
        robot: a robot whose chain is in an analytic class.
        targets: a sequence of ``pin.SE3`` or a (B, 4, 4) array of oMtarget, base frame.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget [s] of the whole batch (None: none); the poses not started when it runs out
            are left with no branch and marked in ``late``.

    Returns:
        The :class:`BranchBatch`.

    Raises:
        TargetError: a bad target, its index named.
        OptionError: the chain is in no analytic class, or a bad tolerance or budget.
    """
    t0 = time.perf_counter()
    req = make_request("frdm", tol_pos=tol_pos, tol_rot=tol_rot, time_budget=time_budget)
    arm = arm_of(robot, req)
    H = np.ascontiguousarray(stack_homogeneous(*as_target_arrays(targets)))
    deadline = np.inf if time_budget is None else t0 + time_budget - verdict_reserve(time_budget)
    form = prepared_form(robot, req)
    if form is None:
        return _pinocchio_batch(robot, arm, H, req, deadline)
    B, n = H.shape[0], arm.n
    q, errors = np.full((B, MAX_ROWS, n), np.nan), np.full((B, MAX_ROWS, 2), np.nan)
    found, free = np.zeros((B, MAX_ROWS), dtype=np.int64), np.zeros((B, MAX_ROWS), dtype=np.bool_)
    count, near = np.zeros(B, dtype=np.int64), np.zeros(B, dtype=np.uint8)
    form.solve_batch(H, q, errors, found, free.view(np.uint8), count, near, threads.count(), deadline)
    late = near == ROW_NOT_STARTED
    if arm.kind == GENERAL_6R:  # no root, or roots merged: the root-by-root route says why, or splits them
        near |= (count == 0) | ((found > 1) & ~free).any(axis=1)
    near &= ~beyond_reach_rows(robot, H)  # proved unreachable: no root to look for
    for b in np.flatnonzero(near & ~late):
        if time.perf_counter() > deadline:
            late[b] = True
            continue
        one = analytic_all(robot, pin.SE3(H[b]), req)
        k = count[b] = len(one)
        q[b, :k], errors[b, :k, 0], errors[b, :k, 1] = one.q, one.position_error, one.rotation_error
        found[b, :k] = [int(r.diagnostics.found or 0) for r in one]
        free[b, :k] = [r.message == CONTINUUM for r in one]
    return BranchBatch(q, count, found, free, errors[..., 0], errors[..., 1], _method(arm), robot.fk_certificate.judge,
                       late=None if time_budget is None else late)


def beyond_reach_rows(robot: Chain, H: np.ndarray) -> np.ndarray:
    """(B,) True where pose b's point lies beyond the robot's reach bound (no configuration reaches it)."""
    anchor, radius = reach_bound(robot)
    return np.asarray(np.linalg.norm(H[:, :3, 3] - np.asarray(anchor), axis=1) > radius)


def _pinocchio_batch(robot: Chain, arm: ArmClass, H: np.ndarray, req: Request, deadline: float) -> BranchBatch:
    """:func:`all_branches_batch` where Pinocchio's FK judges: the closed form in threads, then every branch judged
    in one FK batch; a root that falls short is dropped. Pose by pose (the elimination, Pieper's decoupling) the
    poses not started before ``deadline`` are left."""
    B, n = H.shape[0], arm.n
    late = np.zeros(B, dtype=np.bool_)
    out = np.full((B, MAX_ROWS, n), np.nan)
    found, free = np.zeros((B, MAX_ROWS), dtype=np.int64), np.zeros((B, MAX_ROWS), dtype=np.bool_)
    count = np.zeros(B, dtype=np.int64)
    said: list[str] = []
    if arm.kind in (GENERAL_6R, PIEPER_6R):  # not compiled (no certified FK for the elimination): pose by pose
        said = _pose_by_pose(robot, arm, H, req, deadline, (out, found, free, count, late))
    else:
        branches_batch(arm.kind, arm.mirrored, arm.h, arm.o, arm.R0, arm.N0, H, robot.lower, robot.upper, SAME,
                       limit_slack(req.tol_rot), out, found, free, count)
    q, kept, f, loose, errors = _judged_rows(robot, H, req, out, found, free, count)
    # only the elimination's sets carry reasons; a root the judge refuses leaves its set uncertified
    reasons = [why or ("" if kept[b] == count[b] else "a root the judge does not confirm")
               for b, why in enumerate(said)] if arm.kind == GENERAL_6R else None
    return BranchBatch(q, kept, f, loose, errors[..., 0], errors[..., 1], _method(arm), robot.fk_certificate.judge,
                       reasons, None if req.time_budget is None else late)


def _pose_by_pose(robot: Chain, arm: ArmClass, H: np.ndarray, req: Request, deadline: float,
                  arrays: tuple[np.ndarray, ...]) -> list[str]:
    """Fill ``arrays`` (out, found, free, count, late) pose by pose with the elimination's or Pieper's roots of
    H (B, 4, 4) within the limits, the poses past ``deadline`` marked late; returns why each pose's set is not
    certified ("" when it is, or when the class certifies otherwise)."""
    out, found, free, count, late = arrays
    far, slack, reasons = beyond_reach_rows(robot, H), limit_slack(req.tol_rot), list[str]()
    for b in range(H.shape[0]):
        if time.perf_counter() > deadline:
            late[b:] = True
            return reasons + [""] * (H.shape[0] - b)
        if far[b]:
            reasons.append("")
            continue
        if arm.kind == GENERAL_6R:
            q, merged, loose, why = roots_within(arm, H[b], robot.lower, robot.upper, None, slack)
        else:
            (q, merged, loose), why = arm_roots(arm, H[b], robot.lower, robot.upper, None, slack), ""
        k = count[b] = len(q)
        out[b, :k], found[b, :k], free[b, :k] = q, merged, loose
        reasons.append(why)
    return reasons


def _judged_rows(robot: Chain, H: np.ndarray, req: Request, out: np.ndarray, found: np.ndarray, free: np.ndarray,
                 count: np.ndarray) -> tuple[np.ndarray, ...]:
    """Every row judged by Pinocchio's FK in one batch, those within the tolerances moved to the front of their
    pose: (q, kept per pose, found, free, errors (B, MAX_ROWS, 2): position [m], rotation [rad])."""
    B = H.shape[0]
    pose, row = np.nonzero(np.arange(MAX_ROWS)[None, :] < count[:, None])
    dp, dr = pose_errors(H[pose], robot.fk_batch(out[pose, row]))
    ok = (dp <= req.tol_pos) & (dr <= req.tol_rot)
    kept = np.bincount(pose[ok], minlength=B)
    rank = np.arange(int(ok.sum())) - np.concatenate([[0], np.cumsum(kept)[:-1]])[pose[ok]]
    q, errors = np.full_like(out, np.nan), np.full((B, MAX_ROWS, 2), np.nan)
    q[pose[ok], rank] = out[pose[ok], row[ok]]
    errors[pose[ok], rank, 0], errors[pose[ok], rank, 1] = dp[ok], dr[ok]
    f, loose = np.zeros_like(found), np.zeros_like(free)
    f[pose[ok], rank], loose[pose[ok], rank] = found[pose[ok], row[ok]], free[pose[ok], row[ok]]
    return q, kept, f, loose, errors


def nearest_batch(robot: Chain, targets: Targets, q0: Configuration | None, req: Request,
                  model: CollisionModel | None) -> BatchIKResult:
    """:func:`analytic_one` for every target of a batch (q0: None, one start for every row, or (B, n) starts).

    Raises:
        TargetError, ConfigurationError: a bad target or start, its index named.
        OptionError: the chain is in no analytic class, or the task is not "pose".
    """
    t0 = time.perf_counter()
    H = stack_homogeneous(*as_target_arrays(targets))
    starts = batch_starts(robot, q0, len(H), req)
    form = prepared_form(robot, req) if model is None else None
    if form is not None:
        return _compiled_nearest(robot, form, np.ascontiguousarray(H), starts, req, t0)
    return _nearest_rows(robot, H, starts, req, model, t0)


def batch_starts(robot: Chain, q0: Configuration | str | None, count: int, req: Request) -> np.ndarray | None:
    """A batch's references as (count, n) [rad or m] (None: none given; one serves every row). The start modes of
    the iterative solvers, "random" and "table" (task "pose"), mean no reference here; a row outside the limits is
    refused (``start_outside_limits`` "refuse", a batch's default) or projected into them with a warning.

    Raises:
        ConfigurationError: q0 of another shape, not finite, or a string of no start mode (its row named).
        JointLimitError: a row outside the limits, refused (its row named).
    """
    if isinstance(q0, str):
        if q0 not in ("random", "table") or (q0 == "table" and req.task.name != "pose"):
            raise ConfigurationError(f"q0 must be None, 'random', 'table' (task 'pose'), {robot.n} numbers or "
                                     f"(B, {robot.n}), got {q0!r} for task {req.task.name!r}")
        return None
    starts = None if q0 is None else robot.check_qs(np.atleast_2d(q0), what="q0")
    if starts is None:
        return None
    if starts.shape[0] not in (1, count):
        raise ConfigurationError(f"q0 must be None, {robot.n} numbers or ({count}, {robot.n}) for {count} targets of "
                                 f"{robot.name}, got {count_of(np.asarray(q0).shape)}")
    return np.broadcast_to(within_limits(robot, starts, req.start_outside_limits), (count, robot.n))


def within_limits(robot: Chain, refs: np.ndarray, policy: str) -> np.ndarray:
    """(k, n) references within the limits: rows outside refused (policy "refuse", JointLimitError naming the row)
    or projected into them with a warning ("project"), as the iterative solvers treat their starts."""
    outside = [b for b in range(refs.shape[0]) if not robot.within_limits(refs[b])]
    if not outside:
        return refs
    if policy == "refuse":
        robot.check_q(refs[outside[0]], limits=True, what=f"q0[{outside[0]}]" if refs.shape[0] > 1 else "q0")
    warnings.warn(f"q0 is outside the joint limits of {robot.name}; projected into them", stacklevel=4)
    return np.clip(refs, robot.lower, robot.upper)


def _compiled_nearest(robot: Chain, form: ClosedForm, H: np.ndarray, starts: np.ndarray | None, req: Request,
                      t0: float) -> BatchIKResult:
    """:func:`nearest_batch` in one compiled call on all cores (no collision model): each row the branch
    ``NearestBranch`` gives its pose alone; a row the compiled form leaves (no branch, or a root to finish) by
    :func:`analytic_one` while the budget lasts; rows not started when it runs out: NaN, status ``time_budget``."""
    B, n = len(H), robot.n
    deadline = np.inf if req.time_budget is None else t0 + req.time_budget - verdict_reserve(req.time_budget)
    q, errors = np.full((B, n), np.nan), np.full((B, 2), np.nan)
    count, near = np.zeros(B, dtype=np.int64), np.zeros(B, dtype=np.uint8)
    refs = np.empty((0, n)) if starts is None else np.ascontiguousarray(starts, dtype=float)
    form.nearest_batch(H, refs, q, errors, count, near, threads.count(), deadline)
    success = count > 0
    code = np.where(success, Status.CONVERGED.code, Status.UNREACHABLE.code).astype(np.int8)
    code[near == ROW_NOT_STARTED] = Status.TIME_BUDGET.code
    for b in np.flatnonzero(~success):
        left = deadline - time.perf_counter()
        if left <= 0:
            code[b] = Status.TIME_BUDGET.code
            continue
        row = analytic_one(robot, pin.SE3(H[b]), req if req.time_budget is None else replace(req, time_budget=left),
                           None if starts is None else starts[b], None)
        q[b], success[b], code[b] = row.q, row.success, row.status.code
        errors[b] = row.position_error, row.rotation_error
    none = np.zeros(B, dtype=int)
    return BatchIKResult(q=q, success=success, status_code=code, position_error=errors[:, 0],
                         rotation_error=errors[:, 1], iterations=none, restarts=none.copy(), seed=0,
                         wall_time=time.perf_counter() - t0, solver="analytic", mode=arm_of(robot, req).mode)


def _nearest_rows(robot: Chain, H: np.ndarray, starts: np.ndarray | None, req: Request, model: CollisionModel | None,
                  t0: float) -> BatchIKResult:
    """:func:`analytic_one` row by row within what is left of the request's budget (counted from t0): each row gets
    the rest of it, a row starts only while the rows so far say it fits (a search cannot stop inside a pose), and
    the rows not started are NaN with status ``time_budget``."""
    arm = arm_of(robot, req)
    deadline = np.inf if req.time_budget is None else t0 + req.time_budget - verdict_reserve(req.time_budget)
    B = len(H)
    q, dp, dr = np.full((B, robot.n), np.nan), np.full(B, np.nan), np.full(B, np.nan)
    success, code = np.zeros(B, dtype=bool), np.full(B, Status.TIME_BUDGET.code, dtype=np.int8)
    t_rows = time.perf_counter()
    for b in range(B):
        now = time.perf_counter()
        left = deadline - now
        if left <= 0 or (b and left < (now - t_rows) / b):
            break
        row = analytic_one(robot, pin.SE3(H[b, :3, :3], H[b, :3, 3]),
                           req if req.time_budget is None else replace(req, time_budget=left),
                           None if starts is None else starts[b], model)
        q[b], success[b], code[b] = row.q, row.success, row.status.code
        dp[b], dr[b] = row.position_error, row.rotation_error
    return BatchIKResult(q=q, success=success, status_code=code, position_error=dp, rotation_error=dr,
                         iterations=np.zeros(B, dtype=int), restarts=np.zeros(B, dtype=int), seed=0,
                         wall_time=time.perf_counter() - t0, solver="analytic", mode=arm.mode)
