"""The prepared solver: build once, call in the loop (what TRAC-IK's solver, pink's Configuration and rtb's
``ets.ik_LM`` users already do).

``IK(robot, solver=..., task=..., tol_pos=..., ...)`` checks every setting once and compiles the solver's
kernels before it returns; ``ik.solve(target, q0=...)`` then checks only what changes per call (the target and
the start), so a call pays no argument validation or option building. Its answers are those of
:func:`kinelab.solve` with the same settings and seed (tested), and every one is judged.

The routes are objects chosen once, here (:mod:`kinelab.ik.routes`): ``ik.one`` answers ``solve`` and
``solve_batch`` (the numeric solver, the closed form, a 7R arm's held joint), ``ik.every`` answers ``solve_all``,
``ik.path`` (:class:`PathFollower`) answers ``track``; the methods hand the call over without asking which route it
is. The prepared solver owns its solver's engine (:class:`kinelab.core._engine.Engine`, which the solver's module
makes: ``engine(robot, request)``; FRDM's and the biquaternion preset's). The usual call — a ``pin.SE3`` target, n
real numbers as the start (a list or any real array; or none), an integer seed or none — on a robot whose compiled
FK is certified is one compiled call: it checks both (finite, a proper rotation, the start within the limits, the
target within the reach bound), runs the multistart and judges the answer; the result is built directly, its
diagnostics only when read. Anything else (a point target, a start outside the limits or not n real numbers, a
target beyond reach, a robot judged by Pinocchio's FK, options no engine runs) takes the general driver, which names
the problem, warns or answers UNREACHABLE exactly as :func:`kinelab.solve` does: the engine changes the cost, never
the answer.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab import lazy
from kinelab.core._engine import Engine
from kinelab.errors import OptionError
from kinelab.ik.auto import resolved
from kinelab.ik.batch import BatchIKResult, prepare_robot
from kinelab.ik.branches import UNSEEN, route_of
from kinelab.ik.chain import chain_model
from kinelab.ik.registry import SolverOptions, capabilities, refuse_options
from kinelab.ik.request import Request, check_robot, check_seed, make_request
from kinelab.ik.result import Branches, IKResult, TrackResult
from kinelab.ik.routes import AllBranches, OneAnswer, collision_check, one_answer
from kinelab.ik.targets import TargetArrays, as_target_arrays
from kinelab.robot import Chain
from kinelab.typing import CollisionSpec, Configuration, Target, Targets

if TYPE_CHECKING:
    from kinelab.collision.model import CollisionModel
    from kinelab.ik import clear
    from kinelab.ik.analytic.sew import SEW
    from kinelab.ik.frdm import tracking
    from kinelab.ik.frdm.tracking import PathSettings
else:
    clear = lazy.module("kinelab.ik.clear", globals())
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
        given_settings = (solver, options, dict(solver_options), task, axis)  # what a path is made of
        named = capabilities(solver)
        resolved_solver = resolved(robot, solver, task, collisions, given)
        kind = capabilities(resolved_solver)
        if kind.closed_form:
            refuse_options(options or solver_options)
        self.request: Request = make_request(kind.request_solver(resolved_solver), None, tol_pos, tol_rot,
                                             time_budget, max_restarts, start_outside_limits, options, task, axis,
                                             solver_options)
        self.collisions = collision_check(robot, collisions)
        # the routes, chosen once: one answer per target (solve, solve_batch, prefer=), and every branch
        self.one: OneAnswer = one_answer(robot, self.request, self.collisions, kind.closed_form, named.picks, given)
        self.engine: Engine | None = self.one.engine  # the usual single call's one compiled call, where there is one
        # solve_all's route is the named solver's, as kinelab.solve_all's ("auto" there: the closed form or the 1-D
        # search, the multistart where they find nothing); its usual call (no options, collisions or another task)
        # is kept in one compiled call
        usual = not given and collisions is None and (task, axis) == ("pose", "z")
        req = self.request
        self.every = AllBranches(robot, req, route_of(named, given),
                                 (solver, req.tol_pos, req.tol_rot, req.time_budget) if usual else None,
                                 self.collisions)
        self.path = PathFollower(robot, req, given_settings, self.collisions)

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
            return self.one.prefer(target, q0, seed, prefer)
        return self.one.solve(target, q0, seed)

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
        return self.one.solve_batch(targets, q0, seed)

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
        return self.every.solve_all(target, seed, q_ref, max_solutions, stop_below, redundancy, drop_colliding)

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
        return self.path.track(targets, q0, seed, tracking.PathSettings(jump_limit, restrict, hold, rest_weight))


class PathFollower:
    """``track``'s route: FRDM's follower (the compiled one, or the monitored loop for a bypass, a policy or a
    restriction), refused by name for a solver that does not follow paths.

    Args:
        robot: the robot.
        request: the prepared solver's request (its tolerances and budget).
        given: (solver, options, solver_options, task, axis) as the prepared solver was given them.
        check: the collision model every sample must clear, or None.
    """

    def __init__(self, robot: Chain, request: Request, given: tuple[Any, ...], check: CollisionModel | None):
        self.robot, self.request, self.given, self.check = robot, request, given, check
        self._request: Request | None = None

    def track(self, targets: Targets, q0: Configuration | None, seed: int | None,
              settings: PathSettings) -> TrackResult:
        """The path (see :meth:`IK.track`)."""
        chain_model(self.robot)  # the follower's chain and the judge are built once per robot, on no budget's clock
        prepare_robot(self.robot)
        t_start = time.perf_counter()  # the budget counts from here, the checks of the call included
        req = self._path(seed)
        points, rotations = as_target_arrays(targets)
        return follow_path(self.robot, points, rotations, q0, req, settings, self.check, t_start)

    def _path(self, seed: int | None) -> Request:
        """The request of a path: the path's option defaults under the options given, no restarts, starts refused."""
        solver, options, solver_options, task, axis = self.given
        if not capabilities(self.request.solver).follows_paths:
            raise OptionError("solver", solver, "'frdm' (track follows a path with FRDM's warm-started sweeps)")
        if self._request is None:
            req = self.request
            self._request = make_request(req.solver, None, req.tol_pos, req.tol_rot, req.time_budget, 0, "refuse",
                                         options, task, axis, tracking.path_options(options, solver_options))
        if seed is None:
            return self._request
        check_seed(seed)
        return replace(self._request, seed=int(seed))


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
