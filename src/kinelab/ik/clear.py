"""Answers a real arm can take: a solve whose answer collides starts again from new starts, and the branches
of ``solve_all`` that collide are marked (or dropped).

A solve with ``collisions=`` runs the driver as usual, then checks the answer (:mod:`kinelab.collision`: the
sphere test, then Pinocchio's exact test). A colliding answer is never a success. On an arm with a closed
form (:mod:`kinelab.ik.analytic`) the solve then starts again from each of the pose's other branches, nearest
``q0`` (or the colliding answer) first, skipping those that collide, and fails with status ``collision`` as
soon as every branch within the limits is known to collide. Elsewhere it runs again from fresh seeded starts
until an answer is clear, the time budget is spent or ``max_restarts`` runs have collided; it then fails with
status ``collision``, naming the colliding pair and its distance.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab.ik.analytic.branches import arm_of, has_closed_form, nearest_roots
from kinelab.ik.batch import BatchIKResult, fresh_seed
from kinelab.ik.driver import solve_one
from kinelab.ik.request import Request
from kinelab.ik.result import Branches, IKResult, Status, TrackResult
from kinelab.robot import Chain
from kinelab.typing import Configuration, Target

if TYPE_CHECKING:
    from kinelab.collision.model import CollisionModel

ROW_RUNS = 20  # runs a colliding batch row gets (each a full solve): a row with no clear answer must not take the
# whole batch's budget
STRIDE = 1_000_003  # seeds between two runs: a run's restarts use seed, seed + 1, ... within one run


def solve_clear(robot: Chain, target: Target, q0: Configuration | None, req: Request,
                model: CollisionModel) -> IKResult:
    """The first answer that meets the target and collides with nothing ``model`` checks.

    Args:
        robot: the robot.
        target: oMtarget (base frame).
        q0: the first run's start (None: seeded random).
        req: the validated request; its time budget covers every run, ``max_restarts`` bounds the runs.
        model: the collision model (:func:`kinelab.collision.collision_model`).

    Returns:
        The clear answer (``diagnostics.clear_after``: the colliding answers before it), or the solver's own
        failure, or a failure with status ``collision`` (``diagnostics.contact`` and the message name the pair).
    """
    t0 = time.perf_counter()
    seed = fresh_seed() if req.seed is None else req.seed
    collided: IKResult | None = None
    runs = 0
    while (run := _run_request(req, seed, runs, t0)) is not None:
        res = solve_one(robot, target, q0 if runs == 0 else None, run)
        runs += 1
        if not res.success:
            return res if collided is None else _collided(collided, t0, runs - 1, model)
        if model.colliding_pair(res.q) is None:
            return _with(res, t0, runs - 1, None)
        if runs == 1 and has_closed_form(robot, req):
            return _from_branches(robot, target, res, q0, req, model, t0)
        collided = res
    assert collided is not None
    return _collided(collided, t0, runs, model)


def _run_request(req: Request, seed: int, runs: int, t0: float) -> Request | None:
    """The request of the next run after ``runs`` (its own seeds, what is left of the budget counted from t0), or
    None when the runs or the budget are spent (the first run always starts)."""
    if runs > req.max_restarts:
        return None
    left = None if req.time_budget is None else req.time_budget - (time.perf_counter() - t0)
    if left is not None and left <= 0 and runs:
        return None
    if runs == 0 and req.seed is not None:  # the request as given: no copy of it on the common path
        return req
    return replace(req, seed=seed + runs * STRIDE, time_budget=left)


def _from_branches(robot: Chain, target: Any, collided: IKResult, q0: Any, req: Request, model: CollisionModel,
                   t0: float) -> IKResult:
    """The solver run again from the pose's clear branches (closed form), nearest ``q0`` or the colliding answer
    first; a failure with status ``collision`` when every branch within the limits collides."""
    ref = collided.q if q0 is None else np.asarray(q0, dtype=float)  # q0 passed the first run's checks
    q, _, _, order = nearest_roots(robot, arm_of(robot, req), target, req, ref)
    for k in order:
        if model.colliding_pair(q[k]) is not None:
            continue
        left = None if req.time_budget is None else req.time_budget - (time.perf_counter() - t0)
        res = solve_one(robot, target, q[k], replace(req, max_restarts=0, time_budget=left))
        if res.success and model.colliding_pair(res.q) is None:
            return _with(res, t0, 1, None)
    contact = model.contact(collided.q)
    return replace(_with(collided, t0, 1, contact), success=False, status=Status.COLLISION,
                   message=f"the pose is met, but each of its {q.shape[0]} branch(es) within the limits "
                           f"collides; the answer found: {contact}")


def _with(res: IKResult, t0: float, before: int, contact: Any) -> IKResult:
    """res with the whole call's wall time and the collision diagnostics (built by Diagnostics.quick: a
    dataclasses.replace of its thirty fields costs ~13 µs, a fifth of a solve)."""
    diagnostics = type(res.diagnostics).quick(**{**vars(res.diagnostics), "clear_after": before, "contact": contact})
    return replace(res, wall_time=time.perf_counter() - t0, diagnostics=diagnostics)


def _collided(res: IKResult, t0: float, runs: int, model: CollisionModel) -> IKResult:
    """The last colliding answer as the failure, its pair and distance computed now (once)."""
    contact = model.contact(res.q)
    return replace(_with(res, t0, runs, contact), success=False, status=Status.COLLISION,
                   message=f"the pose is met, but every answer of {runs} run(s) collides; the last: {contact}")


def mark_colliding(found: Branches, model: CollisionModel, drop: bool) -> Branches:
    """``solve_all``'s branches with those that collide marked (success False, status ``collision``,
    ``diagnostics.contact`` set), or left out with ``drop`` (every one left out: status ``collision``)."""
    kept = []
    for res in found:
        contact = model.contact(res.q)
        if contact is None:
            kept.append(res)
        elif not drop:
            kept.append(replace(res, success=False, status=Status.COLLISION, message=f"collides: {contact}",
                                diagnostics=replace(res.diagnostics, contact=contact)))
    out = Branches(kept, found.status, found.message, found.method, found.unseen).certified_by(found._completeness)
    if found and not any(res.success for res in out):
        out.status, out.message = Status.COLLISION, f"every one of the {len(found)} branches found collides"
    return out


def clear_batch(robot: Chain, H: np.ndarray, res: BatchIKResult, req: Request, model: CollisionModel,
                t0: float) -> BatchIKResult:
    """The batch with every colliding row solved again by :func:`solve_clear` (fresh seeds, what is left of the
    budget); a row with no clear answer fails with status ``collision``."""
    q, success, code = res.q.copy(), res.success.copy(), res.status_code.copy()
    dp, dr = res.position_error.copy(), res.rotation_error.copy()
    for b in np.flatnonzero(success):
        if model.colliding_pair(q[b]) is None:
            continue
        left = None if req.time_budget is None else max(req.time_budget - (time.perf_counter() - t0), 1e-4)
        again = solve_clear(robot, pin.SE3(H[b, :3, :3], H[b, :3, 3]), None,
                            replace(req, seed=res.seed + b + STRIDE, time_budget=left,
                                    max_restarts=min(req.max_restarts, ROW_RUNS)), model)
        q[b], success[b], code[b] = again.q, again.success, again.status.code
        dp[b], dr[b] = again.position_error, again.rotation_error
    return replace(res, q=q, success=success, status_code=code, position_error=dp, rotation_error=dr,
                   wall_time=time.perf_counter() - t0)


def clear_track(res: TrackResult, model: CollisionModel) -> TrackResult:
    """The path with every reached sample whose answer collides marked ``collision`` (not reached), the
    contacts listed by sample."""
    code, contacts = res.status_code.copy(), []
    for k in np.flatnonzero(code == Status.CONVERGED.code):
        contact = model.contact(res.q[k])
        if contact is not None:
            code[k] = Status.COLLISION.code
            contacts.append((int(k), contact))
    return replace(res, status_code=code, contacts=contacts)
