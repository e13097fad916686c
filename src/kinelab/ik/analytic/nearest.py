"""One pose in closed form as a solve answers it: the branch nearest a reference (or the first) in one compiled
call where the class allows (:class:`NearestBranch`, and :class:`EveryBranch` for ``solve_all``), else root by
root (:func:`analytic_one`), with the numeric finish where a branch misses."""

from __future__ import annotations

import time
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab.core._analytic import ClosedForm
from kinelab.core._joints import turn_distances
from kinelab.ik.analytic.classify import ArmClass
from kinelab.ik.analytic.kernel import MAX_ROWS
from kinelab.ik.driver import solve_one
from kinelab.ik.request import Request
from kinelab.ik.result import Branches, Diagnostics, IKResult, Status
from kinelab.ik.targets import beyond_reach
from kinelab.ik.tasks import short_arm_note
from kinelab.robot import Chain
from kinelab.typing import Target

if TYPE_CHECKING:
    from kinelab.collision.model import CollisionModel

from kinelab.ik.analytic import branches
from kinelab.ik.analytic.branches import (
    CONTINUUM,
    Rows,
    _method,
    arm_of,
    certificate_of,
    judged,
    nearest_roots,
)


class OneCall:
    """The closed form's usual call in one compiled call: the branches of a ``pin.SE3`` target found and judged
    together by the compiled ``ClosedForm``, no collision model; the results' constant fields made once, their
    diagnostics when first read. :class:`NearestBranch` keeps one branch, :class:`EveryBranch` all.

    Args:
        robot: a robot whose chain is in an analytic class and whose compiled FK is certified.
        req: the validated request (task "pose").
        form: the robot's compiled closed form for the request's tolerances (:func:`prepared_form`).
    """

    def __init__(self, robot: Chain, req: Request, form: ClosedForm):
        arm = arm_of(robot, req)
        self.form, self.fields = form, branches.constant_fields(robot, req, arm.mode)
        self.method = _method(arm)
        self.unseen = 0.0 if self.method == "closed form" else None
        self.unfinished = np.zeros(MAX_ROWS, dtype=np.bool_)  # the compiled form finishes no root
        self.robot = robot

    def found(self, target: pin.SE3, ref: np.ndarray | None) -> tuple[Rows, float] | None:
        """(the compiled closed form's rows, the start of the clock [s]), or None where the general route must
        answer (a root to finish, no branch, a target that is not a ``pin.SE3`` or not a pose)."""
        if type(target) is not pin.SE3:
            return None
        t0 = time.perf_counter()
        got = self.form.solve(target.homogeneous, ref)
        if got is None or not len(got[0]):
            return None
        q, dp, dr, merged, continuum, _ = got
        return Rows(q, dp, dr, self.unfinished[:len(q)], merged, continuum), t0


class NearestBranch(OneCall):
    """:func:`analytic_one`'s usual call: the branch nearest the reference, in one compiled call."""

    def solve(self, target: Target, ref: np.ndarray | None) -> IKResult | None:
        """The branch nearest ``ref`` (checked, [rad]; None: the first), or None where :func:`analytic_one` must
        answer."""
        got = self.found(target, ref)
        if got is None:
            return None
        rows, t0 = got
        k = 0 if ref is None else int(np.argmin(turn_distances(rows.q, ref)))  # the first nearest, as nearest_roots
        return branches.filled(self.fields, rows, k, time.perf_counter() - t0, len(rows.q))


class EveryBranch(OneCall):
    """:func:`kinelab.solve_all`'s usual call: every branch as arrays, each IKResult built when the set is first read
    (as :func:`branch_results` builds it)."""

    def solve(self, target: Target) -> Branches | None:
        """Every branch of ``target``, or None where the general route must answer."""
        if type(target) is not pin.SE3:
            return None
        return self.form.every(target, self._made)

    def _made(self, q: np.ndarray, dp: np.ndarray, dr: np.ndarray, merged: np.ndarray, continuum: np.ndarray,
              wall_time: float, H: np.ndarray) -> Branches:
        """The set of one pose's branches from the compiled form's arrays (q (k, n) [rad], errors [m, rad]; the
        compiled form hands none with merged roots outside a continuum: the general route splits them)."""
        made = Branches.of_rows(q, dp, dr, self._row, (q, dp, dr, merged, continuum, wall_time), self.method,
                                self.unseen)
        made.certified_by(partial(certificate_of, self.robot, self.method, H, q, merged, continuum))
        return made

    def _row(self, data: tuple[Any, ...], i: int) -> IKResult:
        """Row i of a set :meth:`_made` made, as :func:`branch_results` builds it."""
        q, dp, dr, merged, continuum, wall_time = data
        rows = Rows(q, dp, dr, self.unfinished[:len(q)], merged, continuum)
        return branches.filled(self.fields, rows, i, wall_time, len(q), self.unseen)


def analytic_one(robot: Chain, target: pin.SE3, req: Request, q0: np.ndarray | None,
                 model: CollisionModel | None = None) -> IKResult:
    """The branch nearest ``q0`` (each angle's copy in the limits nearest it; without q0 the first branch) that
    Pinocchio confirms — and, with a collision ``model``, the nearest that is clear.

    Args:
        robot: a robot whose chain is in an analytic class.
        target: oMtarget (``pin.SE3``), already checked.
        req: the validated request (task "pose").
        q0: the reference configuration [rad], checked, or None.
        model: a collision model, or None.

    Returns:
        The answer (``diagnostics.branches``: the branches the pose has within the limits), or a failure:
        status ``unreachable`` when no branch meets the pose within the limits, ``collision`` when every branch
        collides (``diagnostics.contact``: the nearest one's pair).

    Raises:
        OptionError: the chain is in no analytic class, or the task is not "pose".
    """
    t0 = time.perf_counter()
    arm = arm_of(robot, req)
    if beyond_reach(robot, target.translation):  # proved unreachable: no root to look for
        return _no_branch(robot, target, req, q0, 0, (None, None), arm.mode, t0)
    q, found, free, order = nearest_roots(robot, arm, target, req, q0)
    k, verdict, collided = _first_clear(robot, q, order, target, req, model)
    if verdict is not None:
        answer, dp, dr, finished = verdict
        return IKResult(q=answer, success=True, status=Status.CONVERGED, position_error=dp, rotation_error=dr,
                        iterations=0, restarts=0, wall_time=time.perf_counter() - t0, solver="analytic",
                        mode=arm.mode, message=CONTINUUM if free[k] else "", task=req.task_label,
                        diagnostics=Diagnostics(path="compiled", branches=q.shape[0], found=int(found[k]),
                                                polished=1 if finished else None,
                                                clear_after=None if model is None else 0))
    return _none_clear(robot, target, req, q0, arm, q.shape[0], collided, model, t0)


def _none_clear(robot: Chain, target: pin.SE3, req: Request, q0: np.ndarray | None, arm: ArmClass, branches: int,
                collided: Any, model: CollisionModel | None, t0: float) -> IKResult:
    """The answer when no branch was both confirmed and clear: a search class's numeric check where no branch was
    confirmed, else the failure (``collided``: the first confirmed branch's verdict that collides, or None)."""
    contact = None if collided is None or model is None else model.contact(collided[0])
    if collided is None and arm.searched and not beyond_reach(robot, target.translation):
        return _numeric_check(robot, target, req, q0, t0)
    return _no_branch(robot, target, req, q0, branches, (collided, contact), arm.mode, t0)


def _first_clear(robot: Chain, q: np.ndarray, order: Any, target: Any, req: Request,
                 model: CollisionModel | None) -> tuple[int, Any, Any]:
    """(index, verdict) of the first root in ``order`` the judge confirms and ``model`` finds clear ((−1, None)
    when none is), and the verdict of the first confirmed one that collides (None when none did)."""
    collided = None
    for k in order:
        verdict = judged(robot, q[k], target, req)
        if verdict is None:
            continue
        if model is not None and model.colliding_pair(verdict[0]) is not None:
            collided = collided or verdict
            continue
        return int(k), verdict, collided
    return -1, None, collided


def _numeric_check(robot: Chain, target: Any, req: Request, q0: np.ndarray | None, t0: float) -> IKResult:
    """When the 1-D search finds no branch of a pose within reach: FRDM from q0 (or seeded starts) within what is
    left of the budget. The search is measured complete (99.99 %), not proved so, and a reachable pose must never be
    answered "unreachable" by it alone (2 of 6,120 poses of random arms whose axes nearly meet were)."""
    left = None if req.time_budget is None else max(req.time_budget - (time.perf_counter() - t0), 1e-4)
    res = solve_one(robot, target, q0, replace(req, time_budget=left))
    note = "the 1-D search found no branch; FRDM's answer"
    return replace(res, mode=f"{res.mode} ({note})", message=f"{res.message}; {note}" if res.message else note,
                   wall_time=time.perf_counter() - t0)


def _no_branch(robot: Chain, target: Any, req: Request, q0: np.ndarray | None, count: int, collided: Any, mode: str,
               t0: float) -> IKResult:
    """The failure of :func:`analytic_one`: the nearest colliding branch, or the reference (or zero) when the
    closed form has no branch within the limits."""
    if collided[0] is not None:
        (answer, dp, dr, _), contact = collided
        return IKResult(q=answer, success=False, status=Status.COLLISION, position_error=dp, rotation_error=dr,
                        iterations=0, restarts=0, wall_time=time.perf_counter() - t0, solver="analytic", mode=mode,
                        message=f"the pose is met, but every one of its {count} branch(es) collides; the nearest: "
                                f"{contact}", task=req.task_label,
                        diagnostics=Diagnostics(path="compiled", branches=count, contact=contact))
    q = np.zeros(robot.n) if q0 is None else np.array(q0, dtype=float)
    dp, dr = robot.tool_error(np.clip(q, robot.lower, robot.upper), target)
    message = "no branch (closed form or 1-D search) meets the pose within the joint limits: the pose is beyond " \
              "the arm's reach, or only reached with a joint outside its limits"
    note = short_arm_note(robot.name, robot.n, "pose")
    return IKResult(q=q, success=False, status=Status.UNREACHABLE, position_error=dp, rotation_error=dr,
                    iterations=0, restarts=0, wall_time=time.perf_counter() - t0, solver="analytic", mode=mode,
                    message=message if note is None else f"{message}; {note}", task=req.task_label,
                    diagnostics=Diagnostics(path="compiled", branches=0))
