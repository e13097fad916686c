"""The routes of a prepared solver, as objects chosen once when an :class:`~kinelab.ik.prepared.IK` is built.

A route of one answer per target answers ``solve`` (one target), ``solve_batch`` (many) and ``solve(prefer=)``
(the branch nearest a reference):

- :class:`Numeric`: FRDM, the biquaternion solver or DLS — the solver's compiled engine for the usual call
  (:mod:`kinelab.core._engine`), the driver for the rest, the threaded batch;
- :class:`ClosedForm`: a chain in a closed-form class (docs/analytic.md) — the branch nearest the start, in one
  compiled call where that serves;
- :class:`HeldJoint`: a 7R arm whose six are in such a class with its end joint held at the start's value; with
  ``solver="auto"`` a single call without a start is FRDM's (:func:`kinelab.ik.auto.single`).

:class:`AllBranches` answers ``solve_all`` (the closed form, the 1-D search, the elimination or the multistart, as
:class:`kinelab.ik.branches.Route` says). Each route owns what it built (the engine, the one-call closed form, the
collision model's use); ``IK``'s methods hand the call to the route without asking which it is. Every answer of
every route is judged by the FK the result's ``judge`` names, within the limits.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, Literal, Protocol

from kinelab import lazy
from kinelab.core._engine import Engine
from kinelab.errors import OptionError
from kinelab.geometry import stack_homogeneous
from kinelab.ik.batch import BatchIKResult, prepare, run_batch
from kinelab.ik.branches import UNSEEN, Route, find_all, usual_entry
from kinelab.ik.driver import prepare_solver, solve_one
from kinelab.ik.options import flag
from kinelab.ik.registry import capabilities
from kinelab.ik.request import Request, check_seed, make_request
from kinelab.ik.result import Branches, IKResult
from kinelab.ik.targets import as_target, as_target_arrays
from kinelab.robot import Chain
from kinelab.typing import CollisionSpec, Configuration, Target, Targets

if TYPE_CHECKING:
    from kinelab.collision import model
    from kinelab.collision.model import CollisionModel
    from kinelab.ik import clear
    from kinelab.ik.analytic import batch as analytic_batch
    from kinelab.ik.analytic import branches, held, nearest
    from kinelab.ik.analytic.nearest import EveryBranch, NearestBranch
    from kinelab.ik.analytic.sew import SEW
else:
    analytic_batch = lazy.module("kinelab.ik.analytic.batch", globals())
    branches = lazy.module("kinelab.ik.analytic.branches", globals())
    clear = lazy.module("kinelab.ik.clear", globals())
    held = lazy.module("kinelab.ik.analytic.held", globals())
    model = lazy.module("kinelab.collision.model", globals())
    nearest = lazy.module("kinelab.ik.analytic.nearest", globals())


class OneAnswer(Protocol):
    """A route of one answer per target (see the module's docstring)."""

    engine: Engine | None  # the usual single call's one compiled call, where the route has one

    def solve(self, target: Target, q0: Configuration | None, seed: int | None) -> IKResult:
        """One target from the start ``q0`` (None: a seeded random one), the seed already checked."""
        ...

    def solve_batch(self, targets: Targets, q0: Configuration | None, seed: int | None) -> BatchIKResult:
        """Every target of a batch (row b: seed + b), starts outside the limits refused."""
        ...

    def prefer(self, target: Target, q0: Configuration | None, seed: int | None,
               prefer: Configuration) -> IKResult:
        """The branch nearest ``prefer``."""
        ...


def with_seed(request: Request, seed: int | None) -> Request:
    """``request`` with ``seed`` (checked), or as it is for None."""
    if seed is None:
        return request
    check_seed(seed)
    return replace(request, seed=seed)


class Numeric:
    """FRDM, the biquaternion solver or DLS (see the module's docstring).

    Args:
        robot: the robot.
        request: the validated request (its solver one of those).
        check: the collision model every answer must clear, or None.
        closed_first: ``prefer=`` looks for the branches in closed form first (a picking solver without options).
    """

    def __init__(self, robot: Chain, request: Request, check: CollisionModel | None, closed_first: bool):
        self.robot, self.request, self.check, self.closed_first = robot, request, check, closed_first
        prepare_solver(request.module, robot, request.options)
        make = getattr(request.module, "engine", None)
        self.engine: Engine | None = None if check is not None or make is None else make(robot, request)

    def solve(self, target: Target, q0: Configuration | None, seed: int | None) -> IKResult:
        """The engine's one compiled call where it serves (an int: why it declines), else the driver."""
        if self.engine is not None:
            res = self.engine.solve(target, q0, seed)
            if type(res) is not int:
                return res
        return solve_clear_of(self.robot, target, q0, with_seed(self.request, seed), self.check)

    def solve_batch(self, targets: Targets, q0: Configuration | None, seed: int | None) -> BatchIKResult:
        """The threaded batch, its colliding rows solved again clear."""
        req = replace(with_seed(self.request, seed), start_outside_limits="refuse")
        return batch_clear_of(self.robot, targets, q0, req, self.check)

    def prefer(self, target: Target, q0: Configuration | None, seed: int | None,
               prefer: Configuration) -> IKResult:
        """The (clear) branch nearest ``prefer`` among every branch the branch search finds."""
        if q0 is not None:
            raise OptionError("q0", "given", "None with prefer= (the branch search draws its own starts)")
        return preferred(self.robot, target, with_seed(self.request, seed), prefer, self.check,
                         Route.EITHER if self.closed_first else Route.MULTISTART)


class _Analytic:
    """What the closed form and the held joint share: the start as the reference, ``prefer=`` as the start."""

    engine: Engine | None = None
    robot: Chain
    request: Request

    def _reference(self, q0: Configuration | None) -> Any:
        """q0 within the limits (refused or projected, as ``start_outside_limits`` says), or None."""
        if q0 is None:
            return None
        start = self.robot.check_q(q0, what="q0")[None, :]
        return analytic_batch.within_limits(self.robot, start, self.request.start_outside_limits)[0]

    def solve(self, target: Target, q0: Configuration | None, seed: int | None) -> IKResult:
        raise NotImplementedError

    def prefer(self, target: Target, q0: Configuration | None, seed: int | None,
               prefer: Configuration) -> IKResult:
        """The branch nearest ``prefer``: the route's own answer with ``prefer`` as its start."""
        if q0 is not None:
            raise OptionError("prefer", "given with q0", "one reference: q0 or prefer, with solver='analytic'")
        return self.solve(target, prefer, seed)


class ClosedForm(_Analytic):
    """A chain in a closed-form class: the branch nearest the start (see the module's docstring).

    Raises:
        OptionError: a 7R arm (:class:`HeldJoint` is its route), a chain without a closed form or a task other than
            "pose", named.
    """

    def __init__(self, robot: Chain, request: Request, check: CollisionModel | None):
        self.robot, self.request, self.check = robot, request, check
        held.refuse_7r(robot)
        branches.arm_of(robot, request)
        form = None if check is not None else branches.prepared_form(robot, request)
        self._nearest: NearestBranch | None = None if form is None else nearest.NearestBranch(robot, request, form)

    def solve(self, target: Target, q0: Configuration | None, seed: int | None) -> IKResult:
        """The branch nearest q0 in one compiled call where that serves, else root by root."""
        ref = self._reference(q0)
        found = None if self._nearest is None else self._nearest.solve(target, ref)
        if found is not None:  # the usual call: nothing imported on its way
            return found
        return nearest.analytic_one(self.robot, as_target(target, self.request.task.name), self.request, ref,
                                    self.check)

    def solve_batch(self, targets: Targets, q0: Configuration | None, seed: int | None) -> BatchIKResult:
        """Each row's branch nearest its start (the closed form's batch)."""
        req = replace(with_seed(self.request, seed), start_outside_limits="refuse")
        return analytic_batch.nearest_batch(self.robot, targets, q0, req, self.check)


class HeldJoint(_Analytic):
    """A 7R arm: its six in closed form with the end joint held (see the module's docstring).

    Args:
        robot: a 7R arm whose six are in a closed-form class.
        request: the validated request.
        check: the collision model: must be None here.
        alone: True (``solver="auto"``): a single call without a start is FRDM's, its route built on first use;
            False: this route answers it too.

    Raises:
        OptionError: a collision check (FRDM takes it) or a task other than "pose", named.
    """

    def __init__(self, robot: Chain, request: Request, check: CollisionModel | None, alone: bool):
        if check is not None:
            raise OptionError("collisions", "given", "None with solver='analytic' on a 7R arm "
                              "(solver='frdm' takes collisions=)")
        self.robot, self.request = robot, request
        branches.arm_of(held.held_robot(robot), request)
        self._picks = alone
        self._alone: Numeric | None = None

    def solve(self, target: Target, q0: Configuration | None, seed: int | None) -> IKResult:
        """The six at the held joint's start value (else at one of its samples); without a start, FRDM's answer
        where ``alone``."""
        if q0 is None and self._picks:
            return self.alone().solve(target, None, seed)
        return held.nearest_held_one(self.robot, as_target(target, self.request.task.name), self._reference(q0),
                                     self.request)

    def alone(self) -> Numeric:
        """FRDM with these tolerances, budget and restarts: ``solver="auto"``'s single call without a start."""
        if self._alone is None:
            req = self.request
            frdm = make_request("frdm", None, req.tol_pos, req.tol_rot, req.time_budget, req.max_restarts,
                                req.start_outside_limits, None, "pose", "z", {})
            self._alone = Numeric(self.robot, frdm, None, closed_first=True)
        return self._alone

    def solve_batch(self, targets: Targets, q0: Configuration | None, seed: int | None) -> BatchIKResult:
        """Each row at its start's held value (the held joint's batch)."""
        req = replace(with_seed(self.request, seed), start_outside_limits="refuse")
        return held.nearest_held(self.robot, targets, q0, req)


def one_answer(robot: Chain, request: Request, check: CollisionModel | None, closed_form: bool, picks: bool,
               options_given: bool) -> OneAnswer:
    """The route of one answer: the closed form (a held joint's on a 7R arm) or the numeric solver.

    Args:
        robot: the robot.
        request: the validated request (the closed form's runs FRDM's request).
        check: the collision model, or None.
        closed_form: the solver ("auto" resolved) is the closed form.
        picks: the solver named picks its route ("auto"): a held joint's single call without a start is FRDM's.
        options_given: solver options were given (``prefer=`` then searches with the multistart they configure).

    Raises:
        OptionError: a closed form refused for this robot or task, named.
    """
    if not closed_form:
        closed_first = capabilities(request.solver).stands_in and not options_given
        return Numeric(robot, request, check, closed_first)
    if held.applies(robot):
        return HeldJoint(robot, request, check, alone=picks)
    return ClosedForm(robot, request, check)


class AllBranches:
    """``solve_all``'s route: the kept one-call closed form for the usual call, else :func:`find_all` by ``method``.

    Args:
        robot: the robot.
        request: the validated request.
        method: how :func:`find_all` looks (the named solver's: :func:`kinelab.ik.branches.route_of`).
        usual: the usual call's key (solver named, tolerances, budget) where it applies (no options, collisions or
            another task), else None.
        check: the collision model, or None.
    """

    def __init__(self, robot: Chain, request: Request, method: Route, usual: tuple[Any, ...] | None,
                 check: CollisionModel | None):
        self.robot, self.request, self.method, self.usual, self.check = robot, request, method, usual, check
        self._every: EveryBranch | None | Literal[False] = False  # the usual call's, once looked up

    def solve_all(self, target: Target, seed: int | None, q_ref: Configuration | None, max_solutions: int | None,
                  stop_below: float | None, redundancy: int | dict[str, float] | SEW | None,
                  drop_colliding: bool) -> Branches:
        """The distinct branches of ``target``, as :func:`kinelab.solve_all` describes."""
        if drop_colliding is not False:
            flag("drop_colliding", drop_colliding)
        if self.usual is not None and q_ref is None and max_solutions is None and redundancy is None:
            entry = self._every_branch(stop_below)
            if entry is not None:
                if seed is not None and not (type(seed) is int and seed >= 0):
                    check_seed(seed)
                found = entry.solve(target)
                if found is not None:
                    return found
        found = find_all(self.robot, target, replace(with_seed(self.request, seed), max_restarts=0), q_ref=q_ref,
                         max_solutions=max_solutions, stop_below=stop_below, method=self.method,
                         redundancy=redundancy)
        return clear_of(found, self.check, drop=bool(drop_colliding))

    def _every_branch(self, stop_below: float | None) -> EveryBranch | None:
        """The one-call solver of every branch for ``stop_below`` (kept here for the default), or None."""
        if stop_below is UNSEEN and self._every is not False:
            return self._every
        entry = usual_entry(self.robot, (*self.usual, stop_below))  # type: ignore[misc]
        if stop_below is UNSEEN:
            self._every = entry
        return entry


def preferred(robot: Chain, target: Target, req: Request, prefer: Configuration | None, check: CollisionModel | None,
              method: Route) -> IKResult:
    """``solve(prefer=)``: the (clear) branch nearest ``prefer`` among every branch found."""
    prepare(robot, req)  # not the budget's time
    t0 = time.perf_counter()
    found = find_all(robot, target, req, q_ref=prefer, method=method)
    found = clear_of(found, check, drop=True)
    if found:
        return replace(found[0], diagnostics=replace(found[0].diagnostics, branches=len(found)))
    # no (clear) branch met the tolerances: the best single answer, in what is left of the same budget (at
    # least one attempt's worth, so that there is an answer to return)
    left = None if req.time_budget is None else max(req.time_budget - (time.perf_counter() - t0), 1e-4)
    return solve_clear_of(robot, target, None, replace(req, time_budget=left), check)


def collision_check(robot: Chain, collisions: CollisionSpec) -> CollisionModel | None:
    """The collision model a ``collisions=`` argument asks for (None, "self", an Environment or a Collisions), or
    None: the collision package (coal's geometry, the robot's meshes) loads only for a solve that checks."""
    if collisions is None:
        return None

    spec = model.as_collisions(collisions)
    return None if spec is None else model.collision_model(robot, spec)


def solve_clear_of(robot: Chain, target: Target, q0: Configuration | None, req: Request,
                   check: CollisionModel | None) -> IKResult:
    """One solve through the driver, clear of collisions when ``check`` is given (:mod:`kinelab.ik.clear`, which
    loads with the first solve that checks)."""
    if check is None:
        return solve_one(robot, target, q0, req)

    return clear.solve_clear(robot, target, q0, req, check)


def batch_clear_of(robot: Chain, targets: Targets, q0: Configuration | None, req: Request,
                   check: CollisionModel | None) -> BatchIKResult:
    """A batch through the FRDM batch, its colliding rows solved again clear of ``check`` when given."""
    t0 = time.perf_counter()
    res = run_batch(robot, targets, q0, req)
    if check is None:
        return res

    return clear.clear_batch(robot, stack_homogeneous(*as_target_arrays(targets)), res, req, check, t0)


def clear_of(found: Branches, check: CollisionModel | None, drop: bool) -> Branches:
    """The branches with the colliding ones dropped (``drop``) or marked, by ``check`` (None: as found)."""
    if check is None:
        return found

    return clear.mark_colliding(found, check, drop=drop)
