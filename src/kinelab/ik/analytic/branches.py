"""Every branch of a pose in closed form, each confirmed by Pinocchio within the joint limits.

The kernel (:mod:`kinelab.ik.analytic.kernel`) returns the raw roots in (−π, π]; here each joint's angle is
moved to the copy (θ + 2πk) inside its limits, nearest the reference when one is given (a joint whose range
spans more than 2π has several copies: one branch, one answer), roots that coincide (a double root at a
workspace boundary or an elbow stretched straight) are merged and counted, and every answer is judged by
Pinocchio's FK. An answer short of the tolerance (geometry within the class tolerance but not exact) is
finished by a warm-started solve from it; one that still misses is dropped.
"""

from __future__ import annotations

import math
import time
from functools import partial
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import pinocchio as pin

from kinelab.core._analytic import ClosedForm
from kinelab.core._engine import fast_result
from kinelab.core._joints import turn_distances
from kinelab.errors import OptionError
from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic import pieper
from kinelab.ik.analytic.certify import (
    Loop,
    kantorovich,
    loop_of,
    search_certificate,
    set_certificate,
    split_merged,
)
from kinelab.ik.analytic.classify import ArmClass, classify, general_class, general_vectors
from kinelab.ik.analytic.general import packed, roots_within
from kinelab.ik.analytic.kernel import GENERAL_6R, MAX_ROWS, PIEPER_6R, branches
from kinelab.ik.chain import chain_model
from kinelab.ik.driver import solve_one
from kinelab.ik.limits import distance, inside_limits
from kinelab.ik.request import Request, make_request
from kinelab.ik.result import Branches, Diagnostics, IKResult, Method, Status
from kinelab.ik.targets import beyond_reach
from kinelab.robot import Chain
from kinelab.robot.chain import _compiled_judge
from kinelab.typing import Target

if TYPE_CHECKING:
    pass

SAME = 1e-5  # [rad] roots closer than this joint by joint are one branch (a double root split by rounding:
# the two roots of arccos(1 − ε) are √(2ε) apart, 1.4e-6 rad at ε = 1e-12)
LIMIT_SLACK = 1e-9  # [rad] a root this close outside a limit is the limit (a pose taken at the limit)


def limit_slack(tol_rot: float) -> float:
    """How far [rad] a root may lie outside a limit and still be tried at the limit: tol_rot. An answer within
    the tolerances can sit at a limit while the exact root lies just beyond it (FRDM found such answers on the
    ERA 3.5e-7 rad past a wrist limit); Pinocchio then judges the clipped root, which a warm-started solve
    finishes when it falls short."""
    return max(LIMIT_SLACK, tol_rot)
CONTINUUM = "one of a continuum: a singular pose, another angle of the free joint serves too"
_NO_REF = {n: np.zeros(n) for n in (5, 6)}


def arm_of(robot: Chain, req: Request) -> ArmClass:
    """The robot's analytic class for a pose request: a closed form or a search class, else the general 6R
    elimination.

    Raises:
        OptionError: the chain is in no analytic class and not a 6R chain the elimination takes (the tests it
            failed named), or the task is not "pose".
    """
    found = classify(robot)
    arm = found.arm or general_class(robot).arm
    if arm is None:
        raise OptionError("solver", "analytic", "a chain in an analytic class or a 6R chain the general "
                          f"elimination takes (docs/analytic.md); {robot.name}'s is not: {found.reason}; "
                          f"{general_class(robot).reason}")
    if req.task.name != "pose":
        raise OptionError("task", req.task_label, "'pose' with solver='analytic' (other tasks: solver='frdm')")
    return arm


def has_closed_form(robot: Chain, req: Request) -> bool:
    """True when the chain is in an analytic class and the request asks for the whole pose."""
    return req.task.name == "pose" and classify(robot).arm is not None


def has_general_form(robot: Chain, req: Request) -> bool:
    """True when the chain is a 6R chain the general elimination takes (and no class of its own) and the request
    asks for the whole pose."""
    return req.task.name == "pose" and general_class(robot).arm is not None


def analytic_all(robot: Chain, target: pin.SE3, req: Request, q_ref: np.ndarray | None = None,
                 max_solutions: int | None = None) -> Branches:
    """Every branch of the pose ``target`` (oMtarget, base frame) that Pinocchio confirms within the limits.

    Args:
        robot: a robot whose chain is in an analytic class.
        target: oMtarget (``pin.SE3``), already checked.
        req: the validated request (task "pose"; tol_pos [m], tol_rot [rad]).
        q_ref: sort the answers by distance to this configuration and pick each angle's copy nearest it.
        max_solutions: at most this many answers (the nearest ``q_ref`` first when given).

    Returns:
        One :class:`IKResult` per branch (``diagnostics.branches``: how many the pose has within the limits;
        ``diagnostics.found``: the roots merged into this answer, 2 at a double root; ``diagnostics.polished``: 1
        when the closed form fell short and a warm-started FRDM solve finished it; ``message`` says when the
        answer is one of a continuum).

    Raises:
        OptionError: the chain is in no analytic class, or the task is not "pose".
    """
    t0 = time.perf_counter()
    arm = arm_of(robot, req)
    beyond = beyond_reach(robot, target.translation)
    if beyond:  # proved unreachable: no root to look for (the elimination overflows at 1e155 m)
        return branch_results(robot, Rows.of([], robot.n), req, arm.mode, time.perf_counter() - t0, max_solutions,
                              _method(arm), "", "", beyond=beyond)
    compiled = _compiled_rows(robot, target, req, arm, q_ref)
    # no certified compiled FK, a root to finish or roots merged: root by root
    rows, uncertified = (compiled, None) if compiled is not None else _rows_root_by_root(robot, target, req, arm,
                                                                                          q_ref)
    if q_ref is not None:
        rows = rows.taken(sorted(range(len(rows.q)), key=lambda k: distance(robot, rows.q[k], q_ref)))
    return branch_results(robot, rows, req, arm.mode, time.perf_counter() - t0, max_solutions, _method(arm),
                          f"no branch within the joint limits ({arm.method})", uncertified, target.homogeneous,
                          beyond="" if len(rows.q) else beyond_reach(robot, target.translation))


def _compiled_rows(robot: Chain, target: pin.SE3, req: Request, arm: ArmClass,
                   q_ref: np.ndarray | None) -> Rows | None:
    """The compiled closed form's judged branches of ``target``; None where the root-by-root route must answer (no
    certified compiled FK, roots merged, perhaps two beside a fold, or no root of the general elimination)."""
    form = prepared_form(robot, req)
    compiled = None if form is None else form.solve(target.homogeneous, q_ref)
    if compiled is None or ((compiled[3] > 1) & ~compiled[4]).any():
        return None
    if arm.kind == GENERAL_6R and not len(compiled[0]):
        return None  # no root: whether that is proved, the root-by-root route says
    q, dp, dr, found, free, _ = compiled
    return Rows(q, dp, dr, np.zeros(len(q), dtype=np.bool_), found, free)


def _rows_root_by_root(robot: Chain, target: pin.SE3, req: Request, arm: ArmClass,
                       q_ref: np.ndarray | None) -> tuple[Rows, str | None]:
    """The branches of ``target`` found root by root and judged by Pinocchio, and why the set is not certified
    ("" when it is; None where the class certifies its sets later, :func:`certificate_of`)."""
    uncertified = None
    if arm.kind == GENERAL_6R:
        q, found, free, uncertified = roots_within(arm, target.homogeneous, robot.lower, robot.upper, q_ref,
                                                   limit_slack(req.tol_rot))
    else:
        q, found, free = split_merged(robot_loop(robot), target.homogeneous,
                                      *roots(robot, arm, target.homogeneous, q_ref, limit_slack(req.tol_rot)))
        q, found, free = _inside(robot, q, found, free, limit_slack(req.tol_rot))
    rows = Rows.of(judged_roots(robot, q, found, free, target, req), robot.n)
    if uncertified == "" and len(rows.q) < len(q):
        uncertified = "a root the judge does not confirm"
    return rows, uncertified


def _inside(robot: Chain, q: np.ndarray, found: np.ndarray, free: np.ndarray,
            slack: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of q within the limits, each angle turned into them where it can be and clipped when ``slack`` [rad]
    past a limit (a root split beside a fold can land a hair past one); the others dropped."""
    if not len(q):
        return q, found, free
    x, keep = inside_limits(q, robot.lower, robot.upper, slack)
    return x, found[keep], free[keep]


def _method(arm: ArmClass) -> Method:
    """The set's ``method``: "elimination" (general 6R), "search" (the 1-D search) or "closed form"."""
    return Method.ELIMINATION if arm.kind == GENERAL_6R else Method.SEARCH if arm.searched else Method.CLOSED_FORM


def prepared_form(robot: Chain, req: Request) -> ClosedForm | None:
    """The robot's compiled closed form for the request's tolerances (kept on the robot), or None where its compiled
    FK is not certified (Pinocchio then judges root by root)."""
    forms: dict[tuple[float, float], ClosedForm | None] = robot.derived("closed forms", _new_forms)
    key = (float(req.tol_pos), float(req.tol_rot))
    if key not in forms:
        judge, arm = robot.derived("compiled judge", _compiled_judge), arm_of(robot, req)
        if arm.kind == PIEPER_6R:  # Pieper's decoupling is not compiled: root by root
            judge = None
        if len(forms) >= 16:  # a caller sweeping tolerances: keep the memory bounded
            forms.clear()
        lower, upper = robot.check_bounds
        forms[key] = None if judge is None else ClosedForm(judge, SimpleNamespace(
            kind=arm.kind, mirrored=arm.mirrored, h=arm.h, o=arm.o, R0=arm.R0, N0=arm.N0, lower=robot.lower,
            upper=robot.upper, same=SAME, slack=limit_slack(req.tol_rot), check_lower=lower, check_upper=upper,
            tol_pos=key[0], tol_rot=key[1], general=packed(*arm.solver) if arm.kind == GENERAL_6R else None))
    return forms[key]


def _new_forms(_: Chain) -> dict[tuple[float, float], ClosedForm | None]:
    return {}


Answer = tuple[np.ndarray, float, float, bool, int, bool]  # q, errors [m, rad], finished, roots merged, continuum


class Rows(NamedTuple):
    """A pose's judged branches as arrays, one row each: q (k, n) [rad], position_error (k,) [m], rotation_error
    (k,) [rad], finished (k,) (a warm-started solve finished the root), merged (k,) (roots merged into it),
    continuum (k,) (one of a continuum)."""

    q: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    finished: np.ndarray
    merged: np.ndarray
    continuum: np.ndarray

    @classmethod
    def of(cls, answers: list[Answer], n: int) -> Rows:
        """The rows of :data:`Answer` tuples."""
        columns = list(zip(*answers, strict=True)) if answers else [()] * 6
        return cls(np.array(columns[0], dtype=float).reshape(len(answers), n), np.array(columns[1], dtype=float),
                   np.array(columns[2], dtype=float), np.array(columns[3], dtype=np.bool_),
                   np.array(columns[4], dtype=np.int64), np.array(columns[5], dtype=np.bool_))

    def taken(self, order: np.ndarray | list[int] | slice) -> Rows:
        """These rows in ``order`` (indices; a slice keeps the first ones)."""
        return Rows(*(column[order] for column in self))


def judged_roots(robot: Chain, q: np.ndarray, found: np.ndarray, free: np.ndarray, target: pin.SE3,
                 req: Request, held: dict[str, float] | None = None, end: float = math.inf) -> list[Answer]:
    """The roots q (m × n) the judge confirms, in their order: each as (q, position error [m], rotation error [rad],
    finished, roots merged, one of a continuum). Where the robot's compiled FK is certified, every root is judged in
    one compiled pass; a root short of the tolerances but near them is finished by :func:`judged` (FRDM, the
    joints of ``held`` frozen, within what is left before ``end``: ``time.perf_counter``'s clock [s])."""
    judge = robot.derived("compiled judge", _compiled_judge)
    m = q.shape[0]
    if judge is None or m == 0:
        return _judged_each(robot, q, found, free, target, req, held, end)
    dp, dr, inside = np.empty(m), np.empty(m), np.empty(m, dtype=np.uint8)
    lower, upper = robot.check_bounds
    judge.verdicts(target.homogeneous, q, lower, upper, dp, dr, inside)
    answers = []
    for k, (p, r, within) in enumerate(zip(dp.tolist(), dr.tolist(), inside.tolist(), strict=True)):
        v = (q[k], p, r, False) if within and p <= req.tol_pos and r <= req.tol_rot else \
            judged(robot, q[k], target, req, held, end) if near_enough(p, r, req) else None
        if v is not None:
            answers.append((*v, int(found[k]), bool(free[k])))
    return answers


def _judged_each(robot: Chain, q: np.ndarray, found: np.ndarray, free: np.ndarray, target: Any, req: Request,
                 held: dict[str, float] | None, end: float) -> list[Answer]:
    """:func:`judged_roots` root by root with Pinocchio's FK (a robot whose compiled FK is not its judge)."""
    return [(*v, int(found[k]), bool(free[k])) for k in range(q.shape[0])
            if (v := judged(robot, q[k], target, req, held, end)) is not None]


def branch_results(robot: Chain, rows: Rows, req: Request, mode: str, elapsed: float, max_solutions: int | None,
                   method: str, empty: str, uncertified: str | None = None, H: np.ndarray | None = None, *,
                   beyond: str = "", late: str = "") -> Branches:
    """The closed form's judged rows as :class:`Branches`, the first ``max_solutions``: arrays, and an IKResult per
    row built when the set is first read; ``diagnostics.branches`` counts them all. With no row the set says why by
    what was proved: ``unreachable`` for ``beyond`` (the reach bound's words) or, when the set is proved complete
    (the closed form, the search; the general 6R elimination when certified), for the reason ``empty``;
    ``time_budget`` when ``late`` says the budget ran out first; else ``not_found``. ``method``: "closed form",
    "search", "elimination" or "sweep"; ``uncertified``: why the set is not certified ("" when it is); ``H``: the
    pose, for the set's certificate when ``uncertified`` is None (computed when the set's completeness is first
    read)."""
    total = len(rows.q)
    if late:
        uncertified = f"the time budget ran out ({late})"
    kept = rows if max_solutions is None or max_solutions >= total else rows.taken(slice(max_solutions))
    unseen = 0.0 if method == "closed form" else None
    make = partial(filled, constant_fields(robot, req, mode), kept, wall_time=elapsed, branches=total, unseen=unseen)
    status, message = _empty_set(total, beyond, late, uncertified, empty)
    made = Branches.from_arrays(kept.q, kept.position_error, kept.rotation_error, make, status, message, method,
                                unseen)
    if uncertified is not None:
        return made.certified_by(("certified", "") if uncertified == "" else ("search", uncertified))
    if H is not None:
        return made.certified_by(partial(certificate_of, robot, method, H, rows.q, rows.merged, rows.continuum))
    return made


def _empty_set(total: int, beyond: str, late: str, uncertified: str | None, empty: str) -> tuple[Status | None, str]:
    """(status, message) of a set of ``total`` branches (None, "" when it has one): see :func:`branch_results`."""
    if total:
        return None, ""
    if beyond:
        return Status.UNREACHABLE, beyond
    if late:
        return Status.TIME_BUDGET, f"no branch found before the time budget ran out ({late})"
    if uncertified in (None, ""):
        return Status.UNREACHABLE, empty
    return Status.NOT_FOUND, f"no branch found, and the set is not certified: {uncertified}"


def certificate_of(robot: Chain, method: str, H: np.ndarray, q: np.ndarray, merged: np.ndarray,
                   continuum: np.ndarray) -> tuple[str, str]:
    """(complete, reason) of a closed form's, a search's or the compiled elimination's set q (k, 6) [rad] of the
    pose H (docs/analytic.md, Certificates). A search's set short of 16 proved branches is certified when the
    general elimination takes the chain (the xArm6's, read from the tool) and its set, certified, is the same to
    1e-6 rad; the compiled elimination's set when the elimination's certified set (computed again with the
    eigenvalues' condition numbers, :func:`~kinelab.ik.analytic.general.roots_within`) is the same."""
    loop = robot_loop(robot)
    if method == "closed form" and _decoupled(robot):  # its subproblems can lose roots near its own singularities
        return search_certificate(loop, H, q, merged, continuum, pieper.MOST_ROOTS, "Pieper's decoupling")
    if method == "closed form":
        return set_certificate(loop, H, q, merged, continuum)
    if method == "elimination":
        level, reason = "search", "the compiled elimination's set"
        check: ArmClass | None = general_class(robot).arm
    else:
        level, reason = search_certificate(loop, H, q, merged, continuum)
        check = robot.derived("elimination cross-check", _elimination)
    if level == "certified" or check is None:
        return level, reason
    return _cross_checked(robot, check, loop, H, q, reason)


def _cross_checked(robot: Chain, check: ArmClass, loop: Loop | None, H: np.ndarray, q: np.ndarray,
                   reason: str) -> tuple[str, str]:
    """(complete, reason) of the set q (k, 6) [rad] of the pose H against the general elimination's certified set:
    certified when the two are the same to 1e-6 rad and Kantorovich's test proves each branch."""
    theirs, _, _, why = roots_within(check, H, robot.lower, robot.upper, None, LIMIT_SLACK)
    if why:
        return "search", f"{reason}; the general elimination's set is not certified: {why}"
    if len(theirs) != len(q) or not all(np.abs(wrap_to_pi(theirs - row)).max(axis=1).min() <= 1e-6 for row in q):
        return "search", f"the general elimination's certified set has {len(theirs)} branches, this one {len(q)}"
    return proved_each(loop, H, q)


def _decoupled(robot: Chain) -> bool:
    """True when the robot's chain is solved by Pieper's decoupling."""
    arm = classify(robot).arm or general_class(robot).arm
    return arm is not None and arm.kind == PIEPER_6R


def proved_each(loop: Loop | None, H: np.ndarray, q: np.ndarray) -> tuple[str, str]:
    """("certified", "") when Kantorovich's test proves each row of q a root of H, else ("search", why not)."""
    if loop is None or (len(q) and not kantorovich(loop, q, H).proved.all()):
        return "search", "a branch Kantorovich's test does not prove (a singular configuration)"
    return "certified", ""


def _elimination(robot: Chain) -> ArmClass | None:
    """The general elimination of a 6R robot's chain where it takes it, to cross-check a 1-D search's sets (None
    where the chain is taken otherwise, e.g. by Pieper's decoupling)."""
    six = _six_vectors(robot)
    arm = None if six is None else general_vectors(*six).arm
    return arm if arm is not None and arm.kind == GENERAL_6R else None


def robot_loop(robot: Chain) -> Loop | None:
    """The loop equations of a 6R robot's chain (:mod:`kinelab.ik.analytic.certify`), built once; None otherwise."""
    return robot.derived("loop equations", _loop)


def _loop(robot: Chain) -> Loop | None:
    six = _six_vectors(robot)
    return None if six is None else loop_of(*six)


def _six_vectors(robot: Chain) -> tuple[np.ndarray, ...] | None:
    """A 6-joint robot's chain at q = 0 (axes, points, tool rotation and point; base frame), None otherwise."""
    if robot.n != 6:
        return None
    v = chain_model(robot).vectors(np.zeros(6))
    return v["e"].copy(), v["o"].copy(), v["R"].copy(), v["N"].copy()


def nearest_roots(robot: Chain, arm: ArmClass, target: pin.SE3, req: Request,
                  ref: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, Any]:
    """:func:`roots` of the pose ``target`` (copies nearest ``ref``, roots up to ``tol_rot`` past a limit tried at
    it) and the order to try them in: nearest ``ref`` first (joint by joint, modulo 2π), as found without it."""
    q, found, free = roots(robot, arm, target.homogeneous, ref, limit_slack(req.tol_rot))
    order = range(q.shape[0]) if ref is None else np.argsort(turn_distances(q, ref), kind="stable")
    return q, found, free, order


def roots(robot: Chain, arm: ArmClass, H: np.ndarray, q_ref: np.ndarray | None,
          slack: float = LIMIT_SLACK) -> tuple[np.ndarray, ...]:
    """The compiled branches of the pose H (4 × 4, base frame): (q (m, n) within the limits, a root up to
    ``slack`` [rad] outside one clipped to it; roots merged into each; one-of-a-continuum flags), before
    Pinocchio's word."""
    return arm_roots(arm, H, robot.lower, robot.upper, q_ref, slack)


def arm_roots(arm: ArmClass, H: np.ndarray, lower: np.ndarray, upper: np.ndarray,
              q_ref: np.ndarray | None, slack: float = LIMIT_SLACK) -> tuple[np.ndarray, ...]:
    """:func:`roots` of the arm ``arm`` with joint limits ``lower``, ``upper`` (arm.n each, rad)."""
    if arm.kind == GENERAL_6R:
        return roots_within(arm, H, lower, upper, q_ref, slack)[:3]
    if arm.kind == PIEPER_6R:
        decoupled = pieper.roots_within(arm, H, lower, upper, q_ref, slack)
        also = arm.solver.also
        return decoupled if also is None else \
            pieper.merged_sets(decoupled, arm_roots(also, H, lower, upper, q_ref, slack))
    n = arm.n
    out, found, free = np.empty((MAX_ROWS, n)), np.zeros(MAX_ROWS, dtype=np.int64), np.zeros(MAX_ROWS, dtype=np.bool_)
    ref = _NO_REF[n] if q_ref is None else np.ascontiguousarray(q_ref, dtype=float)
    m = branches(arm.kind, arm.mirrored, arm.h, arm.o, arm.R0, arm.N0, np.ascontiguousarray(H, dtype=float),
                np.ascontiguousarray(lower), np.ascontiguousarray(upper), ref, q_ref is not None, SAME,
                slack, out, found, free)
    return out[:m], found[:m], free[:m]


def near_enough(dp: float, dr: float, req: Request) -> bool:
    """A root short of the tolerances by errors dp [m], dr [rad] that a warm-started solve may finish (the compiled
    ClosedForm draws the same line); farther off it is not this pose's root."""
    return dp <= 1e3 * req.tol_pos + 1e-6 and dr <= 1e3 * req.tol_rot + 1e-6


def judged(robot: Chain, q: np.ndarray, target: Target, req: Request, held: dict[str, float] | None = None,
           end: float = math.inf) -> tuple[np.ndarray, float, float, bool] | None:
    """(q, position error, rotation error, finished) when Pinocchio's FK of q meets the tolerances, after a
    warm-started finish (``finished``; the joints of ``held`` frozen at their values [rad]; within what is left
    before ``end``, ``time.perf_counter``'s clock [s]) if the closed form fell short; None when it still does not."""
    dp, dr = robot.tool_error(q, target)
    if dp <= req.tol_pos and dr <= req.tol_rot:
        return q, dp, dr, False
    if not near_enough(dp, dr, req):
        return None  # not this pose's root (a 5R arm's candidate for the other shoulder side, say)
    frozen = {} if held is None else {"freeze": held, "active": ("freeze",)}
    left = end - time.perf_counter()
    if left <= 0.0:
        return None  # the budget is spent: a root not finished is not an answer
    finish = make_request("frdm", seed=0, tol_pos=req.tol_pos, tol_rot=req.tol_rot, max_restarts=0,
                          solver_options=frozen, time_budget=1.0 if left == math.inf else min(left, 1.0))
    done = solve_one(robot, target, q, finish)
    return (done.q, done.position_error, done.rotation_error, True) if done.success else None


def constant_fields(robot: Chain, req: Request, mode: str) -> dict[str, Any]:
    """The fields every closed-form answer of this robot, request and mode shares."""
    return {"success": True, "status": Status.CONVERGED, "iterations": 0, "restarts": 0, "solver": "analytic",
            "mode": mode, "task": req.task_label, "judge": robot.fk_certificate.judge}


def filled(fields: dict[str, Any], rows: Rows, k: int, wall_time: float, branches: int,
            unseen: float | None = None) -> IKResult:
    """Row k of ``rows`` as an IKResult (``branches``: how many the pose has), its diagnostics built when first
    read."""
    return fast_result(IKResult, fields, {
        "q": rows.q[k].copy(), "position_error": float(rows.position_error[k]),
        "rotation_error": float(rows.rotation_error[k]), "wall_time": wall_time,
        "message": CONTINUUM if rows.continuum[k] else "", "singular_events": [], "bypasses": [],
        "_make_diagnostics": partial(Diagnostics, path="compiled", branches=branches, found=int(rows.merged[k]),
                                     unseen=unseen, polished=1 if rows.finished[k] else None)})
