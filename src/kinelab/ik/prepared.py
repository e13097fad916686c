"""The prepared solver: build once, call in the loop (what TRAC-IK's solver, pink's Configuration and rtb's
``ets.ik_LM`` users already do).

``IK(robot, solver=..., task=..., tol_pos=..., ...)`` checks every setting once and compiles the solver's
kernels before it returns; ``ik.solve(target, q0=...)`` then checks only what changes per call (the target and
the start), so a call pays no argument validation or option building. Its answers are those of
:func:`kinelab.solve` with the same settings and seed (tested), and every one is judged.

The prepared solver owns its solver's engine (:class:`kinelab.core._engine.Engine`, which the solver's module makes:
``engine(robot, request)``; FRDM's and the biquaternion preset's). The usual call — a ``pin.SE3`` target, n real
numbers as the start (a list or any real array; or none), an integer seed or none — on a robot whose compiled FK
is certified is one compiled call: it checks both (finite, a proper rotation, the start within the limits, the
target within the reach bound), runs the multistart and judges the answer; the result is built directly, its
diagnostics only when read. Anything else (a point target, a start outside the limits or not n real numbers, a
target beyond reach, a robot judged by Pinocchio's FK, options no engine runs) takes the general driver, which
names the problem, warns or answers UNREACHABLE exactly as :func:`kinelab.solve` does: the engine changes the
cost, never the answer.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import pinocchio as pin

from kinelab import lazy
from kinelab.core._engine import Engine
from kinelab.errors import OptionError
from kinelab.geometry import stack_homogeneous
from kinelab.ik.auto import resolved
from kinelab.ik.batch import BatchIKResult, prepare, prepare_robot, run_batch
from kinelab.ik.branches import UNSEEN, Route, find_all, route_of, usual_entry
from kinelab.ik.chain import chain_model
from kinelab.ik.driver import prepare_solver, solve_one
from kinelab.ik.options import flag
from kinelab.ik.registry import SolverOptions, capabilities, refuse_options
from kinelab.ik.request import Request, check_robot, check_seed, make_request
from kinelab.ik.result import Branches, IKResult, TrackResult
from kinelab.ik.targets import TargetArrays, as_target, as_target_arrays
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
    from kinelab.ik.frdm import tracking
    from kinelab.ik.frdm.tracking import PathSettings
else:
    analytic_batch = lazy.module("kinelab.ik.analytic.batch", globals())
    branches = lazy.module("kinelab.ik.analytic.branches", globals())
    clear = lazy.module("kinelab.ik.clear", globals())
    held = lazy.module("kinelab.ik.analytic.held", globals())
    model = lazy.module("kinelab.collision.model", globals())
    nearest = lazy.module("kinelab.ik.analytic.nearest", globals())
    tracking = lazy.module("kinelab.ik.frdm.tracking", globals())


class IK:
    """A solver prepared for one robot and one set of settings.

    Args:
        robot: the robot.
        positional: nothing: every setting is keyword-only.
        solver: "auto" (the default: ``solve`` and ``solve_batch`` take the fastest route with the same guarantees
            for the arm, :mod:`kinelab.ik.auto`; ``solve_all`` the closed form where the chain has one, else FRDM's
            multistart); "frdm", "biquat" or "dls"; "analytic" (the closed form, docs/analytic.md: ``solve``
            returns the branch nearest ``q0``, ``solve_all`` every branch; refused here, by name, for a chain
            without one). Every method takes the route the module function takes for the same settings.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget of each call [s] (None: none).
        max_restarts: random restarts after the first attempt.
        start_outside_limits: "project" (a start outside the limits is moved into them, with a warning) or
            "refuse".
        options: the solver's options object.
        task: "pose", "position", "axis" or "orientation".
        axis: the tool axis of task "axis".
        collisions: as :func:`kinelab.solve` (None, "self", an Environment or a Collisions): every answer of
            every call must be clear; the collision model is built here, once.
        solver_options: the solver's option fields as keyword arguments.

    Raises:
        TypeError: a setting given positionally.
        SolverNotFoundError, OptionError: a bad setting, named (once, here).
    """

    def __init__(self, robot: Chain, *positional: object, solver: str = "auto", tol_pos: float = 1e-6,
                 tol_rot: float = 1e-6, time_budget: float | None = 1.0, max_restarts: int = 1000,
                 start_outside_limits: str = "project", options: SolverOptions = None, task: str = "pose",
                 axis: str = "z", collisions: CollisionSpec = None, **solver_options: object):
        if positional:
            raise TypeError("IK() takes the robot positionally and every setting by keyword: pass "
                            f"solver={positional[0]!r}")
        check_robot(robot)
        self.robot = robot
        given = options is not None or bool(solver_options)
        # solve_all's route is the named solver's, as kinelab.solve_all's ("auto" there: the closed form or the 1-D
        # search, the multistart where they find nothing); the other calls take what "auto" stands for here
        self.route = route_of(capabilities(solver), given)
        self._given = (solver, options, dict(solver_options), task, axis)  # what solve_all and a path are made of
        solver = resolved(robot, solver, task, collisions, given)
        kind = capabilities(solver)
        self.analytic = kind.closed_form
        if self.analytic:
            refuse_options(options or solver_options)
        self.request: Request = make_request(kind.request_solver(solver), None, tol_pos, tol_rot, time_budget,
                                             max_restarts, start_outside_limits, options, task, axis, solver_options)
        self._path_request: Request | None = None
        # solve_all's usual call (no options, collisions or another task): its closed form's key
        usual = not given and collisions is None and (task, axis) == ("pose", "z")
        req = self.request
        self._usual_all = (self._given[0], req.tol_pos, req.tol_rot, req.time_budget) if usual else None
        self.collisions = collision_check(robot, collisions)
        self._nearest: NearestBranch | None = None
        self._every: EveryBranch | None | Literal[False] = False  # solve_all's usual call, once looked up
        self.held = False  # solver "analytic" on a 7R arm: its six at the held joint's start value (_prepare)
        self._prepare()
        # the usual call's one compiled call (kinelab.core._engine), where the solver has one
        self.engine: Engine | None = None if self.collisions is not None or self.analytic else self._engine()
        # "auto" on a 7R arm: a single call without a start is FRDM's (kinelab.ik.auto.single), built on its first
        self._single: IK | None | Literal[False] = None if capabilities(self._given[0]).picks and self.held else False

    def _prepare(self) -> None:
        """Everything a call would otherwise build first: the closed form's class (a chain without one refused
        here, by name) and its one-call form, or the solver's model."""
        robot, req = self.robot, self.request
        if self.analytic:
            self.held = held.applies(robot)
            if self.held:  # a 7R arm: its six in closed form at the held joint's start value
                if self.collisions is not None:
                    raise OptionError("collisions", "given", "None with solver='analytic' on a 7R arm "
                                      "(solver='frdm' takes collisions=)")
                branches.arm_of(held.held_robot(robot), req)  # the task is "pose" (named otherwise)
                return
            held.refuse_7r(robot)
            branches.arm_of(robot, req)
            if self.collisions is None:  # the usual call's one compiled call: branches found and judged together
                form = branches.prepared_form(robot, req)
                self._nearest = None if form is None else nearest.NearestBranch(robot, req, form)
            return
        prepare_solver(req.module, robot, req.options)

    def _engine(self) -> Engine | None:
        """The solver's one-call engine, where its module offers one (``engine(robot, request)``) for this robot and
        these settings."""
        make = getattr(self.request.module, "engine", None)
        return None if make is None else make(self.robot, self.request)

    def _request(self, seed: int | None) -> Request:
        if seed is None:
            return self.request
        check_seed(seed)
        return replace(self.request, seed=seed)

    def solve(self, target: Target, *, q0: Configuration | None = None, seed: int | None = None,
              prefer: Configuration | None = None) -> IKResult:
        """IK for one target (oMtarget in the base frame), as :func:`kinelab.solve` with these settings.

        Args:
            target: oMtarget (a ``pin.SE3``; three numbers [m] for task "position").
            q0: the first start [rad or m] (None: a seeded random one).
            seed: seed of the random starts (None: fresh entropy).
            prefer: a reference configuration [rad or m]: the branch nearest it among every branch found (the
                closed form's nearest for solver "analytic"); ``q0`` is refused with it.

        Returns:
            The result, judged on the task's components within the limits (by the FK ``result.judge`` names).

        Raises:
            TargetError, ConfigurationError, JointLimitError, OptionError: a bad target, start or seed.
        """
        if seed is not None:
            check_seed(seed)  # every route refuses a bad seed, the closed form's too (it draws nothing)
        if prefer is not None:
            return self._preferring(target, q0, seed, prefer)
        if self._single is not False and q0 is None:
            return self._frdm_single().solve(target, seed=seed)
        if self.engine is not None:  # the usual call, in one compiled call (an int: why it declines)
            res = self.engine.solve(target, q0, seed)
            if type(res) is not int:
                return res
        elif self.analytic:
            return self._nearest_branch(target, q0)
        return solve_clear_of(self.robot, target, q0, self._request(seed), self.collisions)

    def _frdm_single(self) -> IK:
        """The FRDM solver with these settings, for "auto"'s single calls without a start on a 7R arm."""
        if not isinstance(self._single, IK):
            req = self.request
            self._single = IK(self.robot, solver="frdm", tol_pos=req.tol_pos, tol_rot=req.tol_rot,
                              time_budget=req.time_budget, max_restarts=req.max_restarts,
                              start_outside_limits=req.start_outside_limits)
        return self._single

    def _preferring(self, target: Any, q0: Any, seed: int | None, prefer: Any) -> IKResult:
        """``solve(prefer=)``: the closed form's branch nearest ``prefer`` for solver "analytic", else the (clear)
        branch nearest it among those the branch search finds (in closed form where the solver stands in for one
        and runs without options)."""
        if self.analytic:
            if q0 is not None:
                raise OptionError("prefer", "given with q0", "one reference: q0 or prefer, with solver='analytic'")
            return self._nearest_branch(target, prefer)
        if q0 is not None:
            raise OptionError("q0", "given", "None with prefer= (the branch search draws its own starts)")
        _, options, solver_options, _, _ = self._given
        closed = capabilities(self.request.solver).stands_in and options is None and not solver_options
        return preferred(self.robot, target, self._request(seed), prefer, self.collisions,
                         Route.EITHER if closed else Route.MULTISTART)

    def _nearest_branch(self, target: Any, q0: Any) -> IKResult:
        """Solver "analytic": the branch nearest q0 in one compiled call where that serves, else root by root (a q0
        outside the limits refused or projected, as ``start_outside_limits`` says)."""
        ref = None if q0 is None else analytic_batch.within_limits(
            self.robot, self.robot.check_q(q0, what="q0")[None, :], self.request.start_outside_limits)[0]
        if self.held:
            return held.nearest_held_one(self.robot, as_target(target, self.request.task.name), ref, self.request)
        found = None if self._nearest is None else self._nearest.solve(target, ref)
        if found is not None:  # the usual call: nothing imported on its way (an import costs 8 % of a 13 µs call)
            return found
        return nearest.analytic_one(self.robot, as_target(target, self.request.task.name), self.request, ref,
                                    self.collisions)

    def solve_batch(self, targets: Targets, *, q0: Configuration | None = None,
                    seed: int | None = None) -> BatchIKResult:
        """Every target of a batch, as :func:`kinelab.solve_batch` with these settings (row b: seed + b).

        Args:
            targets: a sequence of ``pin.SE3`` or an (B, 4, 4) array.
            q0: None, one start for every row, or (B, n) starts [rad or m].
            seed: the base seed (None: one is drawn and reported).

        Returns:
            The batch result, every row judged (by the FK its ``judge`` names).

        Raises:
            TargetError, ConfigurationError, OptionError: named.
        """
        req = replace(self._request(seed), start_outside_limits="refuse")
        if self.held:
            return held.nearest_held(self.robot, targets, q0, req)
        if self.analytic:
            return analytic_batch.nearest_batch(self.robot, targets, q0, req, self.collisions)
        return batch_clear_of(self.robot, targets, q0, req, self.collisions)

    def solve_all(self, target: Target, *, seed: int | None = None, q_ref: Configuration | None = None,
                  max_solutions: int | None = None, stop_below: float | None = UNSEEN,
                  redundancy: int | dict[str, float] | SEW | None = None, drop_colliding: bool = False) -> Branches:
        """The distinct branches of ``target`` found within the time budget, as :func:`kinelab.solve_all` with these
        settings.

        Args:
            target: oMtarget.
            seed: base seed of the starts.
            q_ref: sort the branches by distance to this configuration.
            max_solutions: stop at this many branches.
            stop_below: the stopping rule's threshold, as :func:`kinelab.solve_all` (None: the whole budget).
            redundancy: a 7R arm's, as :func:`kinelab.solve_all` (K, ``{joint: value}`` or ``SEW(ψ)``).
            drop_colliding: leave colliding branches out instead of marking them (with ``collisions``).

        Returns:
            One result per distinct branch.

        Raises:
            TargetError, ConfigurationError, OptionError: named.
        """
        if drop_colliding is not False:
            flag("drop_colliding", drop_colliding)
        if self._usual_all is not None and q_ref is None and max_solutions is None and redundancy is None:
            found = self._usual_solve_all(target, seed, stop_below)
            if found is not None:
                return found
        found = find_all(self.robot, target, replace(self._request(seed), max_restarts=0), q_ref=q_ref,
                         max_solutions=max_solutions, stop_below=stop_below, method=self.route,
                         redundancy=redundancy)
        return clear_of(found, self.collisions, drop=bool(drop_colliding))

    def _usual_solve_all(self, target: Target, seed: int | None, stop_below: float | None) -> Branches | None:
        """solve_all's usual call: every branch in one compiled call, or None where the general route answers."""
        entry = self._every_branch(stop_below)
        if entry is None:
            return None
        if seed is not None and not (type(seed) is int and seed >= 0):
            check_seed(seed)
        return entry.solve(target)

    def _every_branch(self, stop_below: float | None) -> EveryBranch | None:
        """solve_all's one-call solver for ``stop_below`` (kept here for the default), or None."""
        if stop_below is UNSEEN and self._every is not False:
            return self._every
        entry = usual_entry(self.robot, (*self._usual_all, stop_below))  # type: ignore[misc]
        if stop_below is UNSEEN:
            self._every = entry
        return entry

    def track(self, targets: Targets, *, q0: Configuration | None = None, seed: int | None = None,
              jump_limit: float | None = 0.2,
              restrict: tuple[str, ...] = (), hold: int = 10, rest_weight: float | None = None) -> TrackResult:
        """Follow a path, as :func:`kinelab.track` with these settings (solver "frdm"; the path's option defaults
        under the options given here; no restarts; starts outside the limits refused).

        Args:
            targets: oMtarget per sample (a sequence of ``pin.SE3`` or an (N, 4, 4) array, base frame).
            q0: the configuration at the start of the path [rad or m] (None: the first target's answer).
            seed: seed of the first solve and of the restarts that recover a missed sample.
            jump_limit: largest joint step [rad or m] before the jump monitor fires (None: off).
            restrict: restrictions ("intervals", "freeze") held on every sample.
            hold: samples a restriction stays on after the monitor switched it on.
            rest_weight: compiled follower only: weight of the rest term (None: its default).

        Returns:
            The :class:`TrackResult`, every sample judged.

        Raises:
            OptionError, ConfigurationError, JointLimitError, TargetError: named.
        """
        chain_model(self.robot)  # the follower's chain and the judge are built once per robot, on no budget's clock
        prepare_robot(self.robot)
        t_start = time.perf_counter()  # the budget counts from here, the checks of the call included
        req = self._path(seed)

        points, rotations = as_target_arrays(targets)
        settings = tracking.PathSettings(jump_limit, restrict, hold, rest_weight)
        return follow_path(self.robot, points, rotations, q0, req, settings, self.collisions, t_start)

    def _path(self, seed: int | None) -> Request:
        """The request of a path: the path's option defaults under the options given, no restarts, starts refused."""
        solver, options, solver_options, task, axis = self._given
        if not capabilities(self.request.solver).follows_paths:
            raise OptionError("solver", solver, "'frdm' (track follows a path with FRDM's warm-started sweeps)")
        if self._path_request is None:
            req = self.request
            self._path_request = make_request(req.solver, None, req.tol_pos, req.tol_rot, req.time_budget, 0, "refuse",
                                              options, task, axis, tracking.path_options(options, solver_options))
        if seed is None:
            return self._path_request
        check_seed(seed)
        return replace(self._path_request, seed=int(seed))


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


def follow_path(robot: Chain, points: np.ndarray, rotations: np.ndarray, q0: Configuration | None, req: Request,
                settings: PathSettings, check: CollisionModel | None, t_start: float) -> TrackResult:
    """A path once its settings and targets (points [m], rotations) are checked: the start (the first target's
    answer when q0 is None), the path, and the collision check of every answer when ``check`` is given."""
    if q0 is None:
        q0 = _first_answer(robot, pin.SE3(rotations[0], points[0]), req, check)

    path = tracking.run_track(robot, TargetArrays(points, rotations), robot.check_q(q0, limits=True, what="q0"), req,
                              settings, t_start)
    return path if check is None else clear.clear_track(path, check)


def _first_answer(robot: Chain, target: pin.SE3, req: Request, check: CollisionModel | None) -> np.ndarray:
    """Where a path without q0 starts: the answer to its first target, with the path's seed, tolerances and task
    (clear of collisions when the path checks them)."""
    settings = dict(solver="frdm", tol_pos=req.tol_pos, tol_rot=req.tol_rot, task=req.task.name,
                    axis="xyz"[req.task.axis] if req.task.axis >= 0 else "z",
                    collisions=None if check is None else check.spec)
    first = prepared(robot, settings).solve(target, seed=req.seed)
    if not first.success:
        raise OptionError("q0", None, "a start configuration: the path's first target could not be solved "
                          f"({first.status.value}: {first.message})")
    q: np.ndarray = first.q
    return q


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


PREPARED_PER_ROBOT = 16  # a caller sweeping settings: the prepared solvers kept stay bounded


def prepared(robot: Chain, settings: dict[str, Any], key: tuple[Any, ...] | None = None) -> IK:
    """The robot's prepared solver for these settings (``IK``'s keywords), built once and kept on the robot under
    ``key`` (default: the settings sorted) while the same settings come back (a loop of :func:`kinelab.solve`
    calls); settings that cannot be a key (a dict of kicks, say) get a new one each call. Either way the call takes
    the prepared solver's route.

    Raises:
        TypeError, SolverNotFoundError, OptionError: as ``IK``.
    """
    check_robot(robot)
    key = tuple(sorted(settings.items())) if key is None else key
    try:
        hash(key)
    except TypeError:
        return IK(robot, **settings)
    kept: dict[tuple[Any, ...], IK] = robot.derived("prepared solvers", _new_table)
    ik = kept.get(key)
    if ik is None:
        ik = IK(robot, **settings)
        if len(kept) >= PREPARED_PER_ROBOT:
            kept.clear()
        kept[key] = ik
    return ik


def kept_solver(robot: Chain, key: tuple[Any, ...]) -> IK | None:
    """The prepared solver :func:`prepared` keeps on the robot under ``key``, or None (none yet, or a key that
    cannot be one)."""
    try:
        return robot.derived("prepared solvers", _new_table).get(key)
    except TypeError:
        return None


def _new_table(_: Chain) -> dict[tuple[Any, ...], IK]:
    return {}
