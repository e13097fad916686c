"""All the branches: the distinct solutions of one target that seeded restarts find within a budget.

The FRDM paper calls its answer unique; it is unique from one start, not over the workspace (a 6R arm
has up to 16 inverse kinematic solutions, the UR arms 8). :func:`find_all` solves the target from many
seeded random starts at once (:func:`~kinelab.ik.batch.run_batch`), keeps every answer Pinocchio
confirms, and merges answers that are the same solution: equal joint by joint to SAME, revolute joints
compared modulo 2π (an arm whose joint can turn past ±π reaches the same solution at q and q ± 2π).
"""

from __future__ import annotations

import time
from dataclasses import replace
from enum import Enum
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from kinelab import lazy
from kinelab.errors import OptionError
from kinelab.ik.batch import fresh_seed, prepare, run_batch
from kinelab.ik.limits import distance as distance  # exported: the branch distance users sort by
from kinelab.ik.limits import distances
from kinelab.ik.registry import Capabilities, capabilities
from kinelab.ik.request import Request, count_ok, make_request
from kinelab.ik.result import Branches, Diagnostics, IKResult, Status
from kinelab.ik.targets import as_target, beyond_reach
from kinelab.robot import Chain
from kinelab.typing import Configuration, Target

if TYPE_CHECKING:  # the closed forms load when a route asks for them: a multistart solve does without
    from kinelab.ik.analytic import branches, nearest, sew
    from kinelab.ik.analytic import redundancy as redundancy_module
    from kinelab.ik.analytic.nearest import EveryBranch
else:
    branches = lazy.module("kinelab.ik.analytic.branches", globals())
    nearest = lazy.module("kinelab.ik.analytic.nearest", globals())
    redundancy_module = lazy.module("kinelab.ik.analytic.redundancy", globals())
    sew = lazy.module("kinelab.ik.analytic.sew", globals())

SAME = 1e-3  # [rad or m] two answers closer than this, joint by joint, are one solution (answers met to 1e-6 m
# near a singular point differ by up to ~2e-4 rad; distinct branches by far more)
ROUND = 64  # starts per round (one batch call)
ROUND_SECONDS = 1e-3  # [s] a round's fixed cost (arrays, threads, the verdict of ROUND rows)
UNSEEN = 0.01  # the search stops once a further start is estimated this unlikely to find a new branch
MIN_ROUNDS = 2  # rounds before the rule may stop the search (a single round's counts are too few to judge)


def unseen(counts: list[int]) -> float:
    """The chance that one more successful start lands on a branch not found yet, estimated from how many
    successful starts reached each branch found (Good–Turing: the share of starts whose branch was reached only
    once, n₁/n, estimates the mass of the unseen branches; (n₁ + 1)/n keeps it above 0 when every branch was
    reached twice or more, so that a rarely reached branch still asks for starts). 1 before any success."""
    n = sum(counts)
    return 1.0 if n == 0 else min(1.0, (sum(1 for c in counts if c == 1) + 1) / n)


class Route(Enum):
    """How :func:`find_all` looks for the branches."""

    MULTISTART = "multistart"  # seeded starts, in rounds, until the stopping rule or the budget
    CLOSED_FORM = "closed form"  # the chain's closed form, refused by name where there is none
    EITHER = "closed form where there is one"  # and the task is "pose"; else the multistart


def route_of(kind: Capabilities, options_given: bool) -> Route:
    """The route of every branch for a solver that can do ``kind``; options (a multistart solver's settings) given
    to a picking solver send it to the multistart, which they configure."""
    if kind.closed_form:
        return Route.CLOSED_FORM
    return Route.EITHER if kind.picks and not options_given else Route.MULTISTART


def find_all(robot: Chain, target: Target, req: Request, q_ref: Configuration | None = None,
             max_solutions: int | None = None,
             stop_below: float | None = UNSEEN, method: Route = Route.MULTISTART,
             redundancy: int | dict[str, float] | sew.SEW | None = None) -> Branches:
    """The distinct solutions of ``target``, each checked by Pinocchio: every branch in closed form where the
    chain's class allows it (:mod:`kinelab.ik.analytic`), else those seeded starts find within the request's
    time budget.

    Args:
        robot: the robot.
        target: oMtarget (base frame).
        req: the validated request (solvers "frdm", one compiled batch per round, or "dls"); rounds of
            ROUND seeded starts run until its time budget is spent; the same seed finds the same solutions
            when the budget allows the same number of rounds.
        q_ref: sort the solutions by distance to this configuration (rad or m; revolute joints modulo 2π);
            default: by the order found.
        max_solutions: stop once this many distinct solutions are found (None: no such limit).
        stop_below: stop once the estimated chance that one more start finds a new branch (:func:`unseen`) is
            below this, after MIN_ROUNDS rounds (None: spend the whole budget).
        method: the :class:`Route`.
        redundancy: K samples of a 7R arm's swept end joint (:mod:`kinelab.ik.analytic.redundancy`), or
            ``{joint name: value}`` [rad] for that joint held at one value, or a :class:`SEW` angle, on a route with
            the closed form; None: no sweep.

    Returns:
        One :class:`IKResult` per distinct solution. Multistart: ``diagnostics.found``, how many starts reached
        it; ``diagnostics.unseen``, the estimated chance, when the search stopped, that one more start would
        have found a new branch. Closed form (``solver`` "analytic"): ``diagnostics.branches``, how many
        branches the pose has within the limits (all of them are returned); ``diagnostics.found``, the roots
        merged into the answer (2 at a double root); ``unseen`` 0.

    Raises:
        TargetError, ConfigurationError, OptionError: bad input, named.
    """
    _check_search(method, max_solutions, stop_below)
    target = as_target(target, req.task.name)
    ref = None if q_ref is None else robot.check_q(q_ref, what="q_ref")
    if redundancy is not None:
        if method is Route.MULTISTART:
            raise OptionError("redundancy", redundancy, f"None with solver={req.solver!r} and options (redundancy= "
                              "sweeps a joint of the closed form: solver 'auto' or 'analytic', no options)")

        if isinstance(redundancy, sew.SEW):
            return sew.sew_all(robot, target, req, redundancy, ref, max_solutions)
        return redundancy_module.redundant_all(robot, target, req, redundancy, ref, max_solutions)
    spent = 0.0
    if method is not Route.MULTISTART:
        t0 = time.perf_counter()
        found = _closed_form_all(robot, target, req, ref, max_solutions, method)
        if found is not None:
            return found
        spent = time.perf_counter() - t0  # the search after a 1-D search that found nothing has what is left
    return _multistart_all(robot, target, req, ref, max_solutions, stop_below, spent)


def _closed_form_all(robot: Chain, target: Any, req: Request, ref: Any, max_solutions: int | None,
                     method: Route) -> Branches | None:
    """Every branch in closed form (or by the 1-D search or the general elimination) where the route and the chain
    allow it; None where the multistart is to answer instead."""
    if method is Route.CLOSED_FORM or (method is Route.EITHER and (branches.has_closed_form(robot, req)
                                                                    or branches.has_general_form(robot, req))):
        found = branches.analytic_all(robot, target, req, q_ref=ref, max_solutions=max_solutions)
        # the 1-D search is measured complete, not proved so: a pose within reach it finds nothing for is searched
        # again by the multistart rather than called unreachable (and so is an elimination's uncertified empty set)
        if found or found.complete == "certified" or not branches.arm_of(robot, req).searched \
                or beyond_reach(robot, target.translation):
            return found
    return None


USUAL_PER_ROBOT = 16  # a caller sweeping settings: the prepared closed forms kept stay bounded


def usual_entry(robot: Chain, settings: tuple[Any, ...]) -> EveryBranch | None:
    """The one-call solver of every branch for the usual call of :func:`kinelab.solve_all` — a solver that picks its
    route ("auto") on a chain with a closed form or the general elimination and a certified compiled FK, no options,
    references, collisions or sweeps — with ``settings`` = (solver, tol_pos, tol_rot, time_budget, stop_below),
    kept on the robot; None where the usual call does not apply (or a setting is unhashable: the general route
    names it). Its ``solve(target)`` answers None for what the general route must answer (a root to finish, a bad
    pose).

    Raises:
        OptionError: a bad setting, named.
    """
    kept: dict[tuple[Any, ...], EveryBranch | Literal[False]] = robot.derived("usual closed forms", _new_kept)
    try:
        entry = kept.get(settings)
    except TypeError:
        return None
    if entry is None:
        if len(kept) >= USUAL_PER_ROBOT:
            kept.clear()
        entry = kept[settings] = _usual_entry(robot, settings)
    return entry or None


def _usual_entry(robot: Chain, settings: tuple[Any, ...]) -> nearest.EveryBranch | Literal[False]:
    """The one-call solver of every branch for these settings, or False when the usual call does not apply.

    Raises:
        OptionError: a bad setting, named (as the general route would).
    """
    solver, tol_pos, tol_rot, time_budget, stop_below = settings
    if not capabilities(solver).picks:
        return False
    req = make_request("frdm", None, tol_pos, tol_rot, time_budget, 0, "refuse", None, "pose", "z", {})
    _check_search(Route.EITHER, None, stop_below)
    if not (branches.has_closed_form(robot, req) or branches.has_general_form(robot, req)):
        return False
    form = branches.prepared_form(robot, req)
    return False if form is None else nearest.EveryBranch(robot, req, form)


def _new_kept(_: Chain) -> dict[tuple[Any, ...], Any]:
    return {}


def _check_search(method: Route, max_solutions: int | None, stop_below: float | None) -> None:
    """Refuse a bad method, solution count or stopping chance, naming what is valid."""
    if not isinstance(method, Route):
        raise OptionError("method", method, " or ".join(f"Route.{r.name}" for r in Route))
    if max_solutions is not None and (not count_ok(max_solutions) or max_solutions < 1):
        raise OptionError("max_solutions", max_solutions, "an integer ≥ 1, or None")
    if stop_below is not None and not (isinstance(stop_below, float | int) and not isinstance(stop_below, bool)
                                       and 0.0 < stop_below < 1.0):
        raise OptionError("stop_below", stop_below, "a chance in (0, 1), or None to spend the whole budget")


def _multistart_all(robot: Chain, target: Any, req: Request, ref: np.ndarray | None, max_solutions: int | None,
                    stop_below: float | None, spent: float = 0.0) -> Branches:
    """Every solution rounds of seeded starts find (see :func:`find_all`), nearest ``ref`` first when given;
    ``spent`` [s] of the budget already gone."""
    prepare(robot, req)  # before the budget's clock
    t0 = time.perf_counter() - spent
    found, rounds = _search(robot, target, req, max_solutions, stop_below, t0)
    elapsed = time.perf_counter() - t0
    if ref is not None:
        found.sort(key=lambda f: distance(robot, f[0], ref))
    missing = unseen([f[3] for f in found])
    status, why = Status.CONVERGED, ""
    if not found:
        why = beyond_reach(robot, target.translation) if req.task.position else ""
        status = Status.UNREACHABLE if why else Status.TIME_BUDGET
        why = why or (f"none of {rounds * ROUND} starts met the target within the time budget: nothing proves it out "
                      "of reach (a larger time_budget may find one)")
    return Branches([IKResult(q=q, success=True, status=Status.CONVERGED, position_error=dp, rotation_error=dr,
                              iterations=0, restarts=rounds * ROUND - 1, wall_time=elapsed, solver=req.solver,
                              mode=f"{req.solver} (all branches, multistart)",
                              diagnostics=Diagnostics(found=count, starts=rounds * ROUND, unseen=missing),
                              task=req.task_label)
                     for q, dp, dr, count in found[:max_solutions]], status, why, "multistart", missing)


def _search(robot: Chain, target: Any, req: Request, max_solutions: int | None, stop_below: float | None,
            t0: float) -> tuple[list[tuple[np.ndarray, float, float, int]], int]:
    """Rounds of ROUND seeded starts until the budget (counted from t0), ``max_solutions`` or the stopping rule
    ends them: the distinct solutions (q, position error, rotation error, starts that reached it) and the rounds
    run."""
    seed = fresh_seed() if req.seed is None else req.seed
    budget = 0.05 if req.time_budget is None else req.time_budget
    found: list[tuple[np.ndarray, float, float, int]] = []
    rounds = 0
    # a round costs about ROUND_SECONDS of set-up and verdict whatever its budget: none starts in less
    while (left := budget - (time.perf_counter() - t0)) > ROUND_SECONDS and \
            _wanting(found, rounds, max_solutions, stop_below):
        # each round gets what is left of the budget: the batch stops its rows there
        rnd = replace(req, seed=seed + rounds * ROUND, max_restarts=0, time_budget=left)
        batch = run_batch(robot, [target] * ROUND, None, rnd)
        for b in np.flatnonzero(batch.success):
            _merge(robot, found, batch.q[b], batch.position_error[b], batch.rotation_error[b])
        rounds += 1
    return found, rounds


def _wanting(found: list[tuple[np.ndarray, float, float, int]], rounds: int, max_solutions: int | None,
             stop_below: float | None) -> bool:
    """Another round may find more: fewer than ``max_solutions`` found, and the stopping rule's estimate of what is
    unseen still at or above ``stop_below`` (asked only after MIN_ROUNDS rounds)."""
    if max_solutions is not None and len(found) >= max_solutions:
        return False
    return stop_below is None or rounds < MIN_ROUNDS or unseen([f[3] for f in found]) >= stop_below


def _merge(robot: Chain, found: list[tuple[np.ndarray, float, float, int]], q: np.ndarray, dp: float,
           dr: float) -> None:
    """Count q towards the first solution it equals (joint by joint, revolute joints modulo 2π), or add it; the
    distances to every solution found in one pass (a 7R arm's multistart finds ~90: one by one, the merging took
    ten times the search)."""
    if found:
        same = np.flatnonzero(distances(robot, q, np.array([f[0] for f in found])) <= SAME)
        if same.size:
            k = int(same[0])
            other, odp, odr, count = found[k]
            found[k] = (other, odp, odr, count + 1)
            return
    found.append((np.array(q, dtype=float), float(dp), float(dr), 1))
