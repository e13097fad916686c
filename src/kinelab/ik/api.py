"""The public IK entry points: :func:`solve`, :func:`solve_batch`, :func:`solve_all` and :func:`track`.

One vocabulary: the robot and the target (or targets) positionally, everything else by keyword with the
same names, defaults and meanings everywhere — ``solver``, ``q0``, ``seed``, ``tol_pos`` [m], ``tol_rot``
[rad], ``time_budget`` [s, the whole call], ``max_restarts``, ``start_outside_limits``, ``task``, ``axis``,
and the solver's options as ``options=`` (a ``FRDMOptions``, ``BiquatOptions`` or ``DLSOptions``) or as
their fields by keyword. :func:`solve`, :func:`solve_batch`, :func:`solve_all` and :func:`track` are calls on the
prepared solver (:class:`kinelab.ik.prepared.IK`) kept on the robot for their settings, which routes them (the
compiled engine, the closed form, a 7R arm's held joint, the 1-D search, the multistart, the collision check;
``solve(prefer=)`` too); :func:`solve_all_batch` is the closed forms' batch alone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.errors import OptionError
from kinelab.ik.auto import single
from kinelab.ik.batch import BatchIKResult
from kinelab.ik.branches import UNSEEN
from kinelab.ik.prepared import IK, kept_solver, prepared
from kinelab.ik.registry import SolverOptions, capabilities, refuse_options
from kinelab.ik.request import check_robot
from kinelab.ik.result import Branches, IKResult, TrackResult
from kinelab.robot import Chain
from kinelab.typing import CollisionSpec, Configuration, Target, Targets

if TYPE_CHECKING:  # the collision model and the closed forms load when a call asks for them
    from kinelab.ik.analytic import batch as analytic_batch
    from kinelab.ik.analytic.batch import BranchBatch
    from kinelab.ik.analytic.sew import SEW
else:
    analytic_batch = lazy.module("kinelab.ik.analytic.batch", globals())

# The order of the arguments after (robot, target) in kinelab 0.1's positional signatures: a call that still
# passes them positionally is told which keyword its value was
_OLD_ORDER = {
    "solve": ("solver", "q0", "seed", "tol_pos", "tol_rot", "time_budget", "max_restarts"),
    "solve_batch": ("q0", "seed", "solver", "tol_pos", "tol_rot", "max_restarts", "time_budget"),
    "solve_all": ("task", "axis", "time_budget", "seed", "q_ref", "tol_pos", "tol_rot"),
    "track": ("q0",),
}


def check_entry(robot: object, function: str, positional: tuple[Any, ...]) -> None:
    """What every entry point checks first: a Chain, and nothing positional after the target.

    Raises:
        ChainError: not a Chain. TypeError: a setting given positionally.
    """
    check_robot(robot)
    if positional:
        refuse_positional(function, positional)


def refuse_positional(function: str, extra: tuple[Any, ...]) -> None:
    """Raise the TypeError of a call that passed more than the robot and its target(s) positionally.

    Raises:
        TypeError: always, naming the keyword the first extra value stands for.
    """
    order = _OLD_ORDER.get(function, ())
    keyword = order[0] if order else "the keyword it stands for"
    raise TypeError(f"{function}() takes the robot and the target(s) positionally and everything else by "
                    f"keyword: pass {keyword}={extra[0]!r} (got {len(extra)} more positional argument"
                    f"{'s' if len(extra) > 1 else ''})")


def solve(robot: Chain, target: Target, *positional: object, solver: str = "auto", q0: Configuration | None = None,
          seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, time_budget: float = 1.0,
          max_restarts: int = 1000, start_outside_limits: str = "project", options: SolverOptions = None,
          task: str = "pose", axis: str = "z", prefer: Configuration | None = None, collisions: CollisionSpec = None,
          **solver_options: object) -> IKResult:
    """Solve IK for the tool pose ``target`` (``pin.SE3`` in the robot's base frame).

    Args:
        robot: the robot (:func:`kinelab.load`).
        target: oMtarget, the wanted tool pose in the base frame (three numbers [m] for task "position").
        positional: nothing: every argument after the target is keyword-only.
        solver: "auto" (the default): the fastest of the others with the same guarantees for this robot and
            task (:mod:`kinelab.ik.auto`, docs/route.md; ``result.solver`` and ``result.mode`` name the route
            taken); "frdm", "biquat", "dls" (the Pinocchio reference), or "analytic": the closed form's branch
            nearest ``q0`` (else the first), where the chain has one (docs/analytic.md), refused by name elsewhere.
        q0: first start (one number per joint, rad or m); default a seeded random configuration.
        seed: seed of the random starts, an int ≥ 0 (None: fresh entropy). A solve that does not run out of
            budget returns the same answer for the same seed in any process; one that does depends on speed.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad] (angle of R*ᵀR, or between the tool axes for task "axis").
        time_budget: wall-clock budget [s] for all attempts together.
        max_restarts: random restarts after the first attempt.
        start_outside_limits: "project" (default: move q0 into the limits, with a warning) or "refuse".
        options: the solver's options object (``FRDMOptions``, ``BiquatOptions``, ``DLSOptions``).
        task: "pose" (all), "position", "axis" (the tool point and tool axis ``axis``, roll free) or
            "orientation" (:mod:`kinelab.ik.tasks`); the biquaternion solver takes "pose" only.
        axis: the tool axis of task "axis": "x", "y" or "z".
        prefer: a reference configuration (rad or m): the branch nearest it (modulo 2π) among :func:`solve_all`'s
            — in closed form where the chain has one and FRDM runs without options (``solver`` "analytic"),
            else the multistart's within ``time_budget``; None (default): the first answer found. ``q0`` is
            refused with it.
        collisions: None (no check), "self", a :class:`kinelab.Environment` (itself and the obstacles) or a
            :class:`kinelab.Collisions` (with a margin [m]): a colliding answer is never a success; the solve
            runs again from new starts within ``time_budget`` (:mod:`kinelab.ik.clear`) and fails with status
            ``collision``, naming the pair, when every answer collides.
        solver_options: the solver's option fields as keyword arguments (instead of ``options``).

    Returns:
        The result, judged on the components the task constrains (``result.task``) by the FK ``result.judge``
        names (Pinocchio's, or the compiled FK certified equal to it on this robot); with ``prefer``,
        ``diagnostics.branches`` is the number of distinct solutions found.

    Raises:
        TypeError: arguments after the target given positionally.
        SolverNotFoundError, OptionError, TargetError, ConfigurationError: bad input, named.
    """
    check_entry(robot, "solve", positional)
    solver = single(robot, solver, task, collisions, options is not None or bool(solver_options),
                    q0 is not None or prefer is not None)
    key = (solver, tol_pos, tol_rot, time_budget, max_restarts, start_outside_limits, options, task, axis,
           collisions) + (tuple(solver_options.items()) if solver_options else ())
    ik = kept_solver(robot, key) if prefer is None else None  # solve is IK(robot, **settings).solve(target)
    if ik is not None:
        engine = ik.engine
        res = None if engine is None else engine.solve(target, q0, seed)  # the usual call: one compiled call
        return ik.solve(target, q0=q0, seed=seed) if res is None or type(res) is int else res
    settings = dict(solver=solver, tol_pos=tol_pos, tol_rot=tol_rot, time_budget=time_budget,
                    max_restarts=max_restarts, start_outside_limits=start_outside_limits, options=options, task=task,
                    axis=axis, collisions=collisions, **solver_options)
    return prepared(robot, settings, key).solve(target, q0=q0, seed=seed, prefer=prefer)


def solve_batch(robot: Chain, targets: Targets, *positional: object, solver: str = "auto",
                q0: Configuration | None = None,
                seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6,
                time_budget: float | None = None, max_restarts: int = 1000, start_outside_limits: str = "refuse",
                options: SolverOptions = None, task: str = "pose", axis: str = "z", collisions: CollisionSpec = None,
                **solver_options: object) -> BatchIKResult:
    """Solve IK for every target of a batch: row b is what :func:`solve` gives for ``targets[b]`` alone with
    ``seed = seed + b`` and start ``q0[b]``, when neither runs out of time — except ``solver="auto"`` on a 7R arm
    without starts, where the batch takes the held joint's closed form and a single call FRDM (each the faster for
    its entry point, docs/route.md; both answers judged alike).

    FRDM with compiled options runs the rows in parallel inside one kernel (every core; the answers do not
    depend on the thread count); the other solvers and FRDM's monitored options run the rows one by one.

    Args:
        robot: the robot.
        targets: a sequence of ``pin.SE3`` or an (B, 4, 4) array of homogeneous matrices (oMtarget).
        positional: nothing: every argument after the targets is keyword-only.
        solver: as :func:`solve` ("analytic": each row the closed form's branch nearest its start).
        seed: the base seed: row b uses seed + b; None draws one, reported in the result.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        max_restarts: random restarts per row after its first attempt.
        options: the solver's options object.
        task: the components to meet, as :func:`solve`.
        axis: the tool axis of task "axis".
        solver_options: the solver's option fields as keyword arguments.
        q0: starts: None or "random" (each row draws its own from its seed), "table" (each row's first start the
            stored configuration whose tool pose is nearest its target: :mod:`kinelab.ik.starts`; FRDM and DLS,
            task "pose"), one configuration for every row, or (B, n) [rad or m]; within the joint limits.
        time_budget: wall-clock budget [s] of the whole batch (None, the default: none); rows not started
            when it runs out are left unsolved with status ``time_budget`` and NaN in q.
        start_outside_limits: "refuse" (the default here: a batch of starts is data, checked row by row).
        collisions: as :func:`solve`: a row whose answer collides is solved again from fresh seeds within what
            is left of ``time_budget``, and fails with status ``collision`` when every answer collides.

    Returns:
        The :class:`~kinelab.ik.batch.BatchIKResult`, every row judged by the FK its ``judge`` names.

    Raises:
        TypeError: arguments after the targets given positionally.
        TargetError: a bad target (its index named); ConfigurationError: a bad q0 (its row named);
        OptionError, SolverNotFoundError: a bad option or argument.
    """
    check_entry(robot, "solve_batch", positional)
    settings = dict(solver=solver, tol_pos=tol_pos, tol_rot=tol_rot, time_budget=time_budget,
                    max_restarts=max_restarts, start_outside_limits=start_outside_limits, options=options, task=task,
                    axis=axis, collisions=collisions, **solver_options)
    return prepared(robot, settings).solve_batch(targets, q0=q0, seed=seed)


def solve_all_batch(robot: Chain, targets: Targets, *positional: object, tol_pos: float = 1e-6,
                    tol_rot: float = 1e-6, time_budget: float | None = None) -> BranchBatch:
    """Every branch of each target, arrays in, arrays out: in closed form, by the 1-D search or by the general 6R
    elimination, compiled, on all cores.

    Row b holds what ``solve_all(robot, targets[b])`` returns for a chain with a closed form, a 1-D search or the
    general elimination (each angle's copy within the limits nearest 0), every branch judged within the limits by
    the FK the result's ``judge`` names.

    Args:
        robot: a robot whose chain is in an analytic class or a 6R chain the general elimination takes
            (docs/analytic.md).
        targets: a sequence of ``pin.SE3`` or a (B, 4, 4) array of oMtarget, base frame.
        positional: nothing: the tolerances are keyword-only.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget [s] of the whole batch (None, the default: none); the targets not started
            when it runs out get no branch and are marked in the result's ``late``.

    Returns:
        The :class:`~kinelab.ik.analytic.batch.BranchBatch`: ``q`` (B, 16, n) [rad] with the first ``count[b]``
        rows of target b set (NaN after them), their errors, roots merged and continuum flags, and how complete each
        set is (``method``: "closed form", "search" or "elimination"; ``uncertified``: the elimination's reason per
        target, "" where its set is certified).

    Raises:
        TypeError: a tolerance given positionally.
        ChainError, TargetError, OptionError: not a robot, a bad target (its index named), a bad tolerance, or a
            chain none of those take (named: its branches come from ``solve_all`` one target at a time).
    """
    check_entry(robot, "solve_all_batch", positional)

    return analytic_batch.all_branches_batch(robot, targets, tol_pos, tol_rot, time_budget)


def solve_all(robot: Chain, target: Target, *positional: object, solver: str = "auto", seed: int | None = None,
              tol_pos: float = 1e-6, tol_rot: float = 1e-6, time_budget: float | str | None = "auto",
              options: SolverOptions = None,
              task: str = "pose", axis: str = "z", q_ref: Configuration | None = None, max_solutions: int | None = None,
              stop_below: float | None = UNSEEN, collisions: CollisionSpec = None, drop_colliding: bool = False,
              redundancy: int | dict[str, float] | SEW | None = None, **solver_options: object) -> Branches:
    """The distinct solutions (branches) of ``target``: every one in closed form where the chain's geometry
    allows it (docs/analytic.md), else those that seeded starts find, in rounds of 64, until the estimated
    chance that one more start finds a new branch falls below ``stop_below`` or ``time_budget`` is spent.

    Args:
        robot: the robot.
        target: oMtarget (base frame).
        positional: nothing: every argument after the target is keyword-only.
        solver: "auto" (the closed form for a chain in an analytic class and task "pose", else "frdm"),
            "analytic" (refused, with the reason, where there is none), or a multistart solver: "frdm" (a compiled
            batch per round of starts) or "dls". ``method`` of the result says how the set was found.
        seed: base seed of the starts (None: fresh entropy): the same branches when as many rounds run.
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        options: the solver's options object.
        task: the components to meet, as :func:`solve`.
        axis: the tool axis of task "axis".
        solver_options: the solver's option fields as keyword arguments.
        time_budget: wall-clock budget [s] of the search, or None (none). "auto" (the default): 0.05 s for the
            multistart (every branch of a Stanford target in 197 of 200 cases), 5 s for a 7R arm's ``redundancy=``
            searches (the values of the held joint, the SEW angle's 1-D search), none for the closed form (it takes
            microseconds). A search stopped by its budget says so (``time_budget``, or ``complete_reason``).
        q_ref: sort the solutions by distance to this configuration (rad or m; revolute joints modulo 2π).
        max_solutions: stop once this many distinct solutions are found (None: no such limit).
        stop_below: the stopping rule (:func:`kinelab.ik.branches.unseen`, a Good–Turing estimate from how many
            starts reached each branch; checked after two rounds); None: spend the whole budget.
        collisions: as :func:`solve`: a colliding branch is marked (``success`` False, status ``collision``,
            ``diagnostics.contact`` naming the pair), or left out with ``drop_colliding``.
        drop_colliding: leave colliding branches out instead of marking them.
        redundancy: a 7R arm's (docs/analytic.md; solver "auto" or "analytic"): K, every branch at K values of
            its swept end joint; ``{joint name: value}`` [rad], every branch with that joint there; ``SEW(ψ)``, every
            branch the search finds with the elbow's SEW angle ψ [rad]. None: a 7R arm gets the multistart.

    Returns:
        The :class:`~kinelab.ik.result.Branches`: one :class:`IKResult` per distinct solution, nearest ``q_ref``
        first when given; an empty one says why in its ``status`` and ``message`` (``unreachable`` only where that
        is proved, ``time_budget`` where the multistart ran out of time).

    Raises:
        TypeError: arguments after the target given positionally.
        TargetError, ConfigurationError, OptionError: bad input, named.
    """
    check_entry(robot, "solve_all", positional)
    time_budget = _all_budget(time_budget, redundancy)
    if (options is not None or solver_options) and capabilities(solver).closed_form:  # said, not ignored
        refuse_options(options or solver_options)
    ik = all_solver(robot, solver, tol_pos, tol_rot, time_budget, options, task, axis, collisions, solver_options)
    return ik.solve_all(target, seed=seed, q_ref=q_ref, max_solutions=max_solutions, stop_below=stop_below,
                        redundancy=redundancy, drop_colliding=drop_colliding)


def all_solver(robot: Chain, solver: str, tol_pos: float, tol_rot: float, time_budget: float | None,
               options: SolverOptions, task: str, axis: str, collisions: CollisionSpec,
               solver_options: dict[str, object]) -> IK:
    """:func:`solve_all`'s prepared solver for these settings, kept on the robot (:mod:`kinelab.wholebody.ready`
    builds the default one at load).

    Raises:
        SolverNotFoundError, OptionError: a bad setting, named.
    """
    key = (solver, tol_pos, tol_rot, time_budget, options, task, axis, collisions) + (
        tuple(solver_options.items()) if solver_options else ())
    ik = kept_solver(robot, key)  # the usual loop: the same settings again, one lookup (no settings dict built)
    if ik is None:
        ik = prepared(robot, dict(solver=solver, tol_pos=tol_pos, tol_rot=tol_rot, time_budget=time_budget,
                                  options=options, task=task, axis=axis, collisions=collisions, **solver_options), key)
    return ik


AUTO = "auto"  # solve_all's default time_budget: the route's own (below)
AUTO_BUDGET = 0.05  # [s] solve_all's multistart when no budget is named
AUTO_REDUNDANT_BUDGET = 5.0  # [s] a 7R arm's redundancy= searches when no budget is named (≈ 0.2-0.9 s a pose)


def _all_budget(time_budget: float | str | None, redundancy: Any) -> float | None:
    """:func:`solve_all`'s budget [s]: ``time_budget`` as given, or for "auto" its route's own.

    Raises:
        OptionError: a string other than "auto".
    """
    if not isinstance(time_budget, str):
        return time_budget
    if time_budget != AUTO:
        raise OptionError("time_budget", time_budget, "a finite number > 0 [s], None (none) or 'auto'")
    return AUTO_BUDGET if redundancy is None else AUTO_REDUNDANT_BUDGET


def track(robot: Chain, targets: Targets, *positional: object, q0: Configuration | None = None, solver: str = "frdm",
          seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, time_budget: float | None = None,
          options: SolverOptions = None, task: str = "pose", axis: str = "z", jump_limit: float | None = 0.2,
          restrict: tuple[str, ...] = (), hold: int = 10, rest_weight: float | None = None,
          collisions: CollisionSpec = None, **solver_options: object) -> TrackResult:
    """Follow a path: solve each target in turn, warm-started from the previous answer (no restarts).

    With no bypass, policy or restriction named, the whole path runs in the compiled follower; otherwise
    the monitored loop runs, switching the restrictions a policy names on when a monitor fires
    (:mod:`kinelab.ik.frdm.tracking`). Every sample is judged on the task's components within the joint limits.

    Args:
        robot: the robot.
        targets: oMtarget per sample (a sequence of ``pin.SE3`` or an (N, 4, 4) array, base frame).
        positional: nothing: every argument after the targets is keyword-only.
        q0: the configuration at the start of the path [rad or m], within the limits; None: the first target
            is solved by :func:`solve` (with ``seed``) and the path starts there.
        solver: "frdm" (the only path follower).
        seed: seed of the first solve when ``q0`` is None, and of the restarts that recover a missed sample
            (None: fresh entropy).
        tol_pos: position tolerance per sample [m].
        tol_rot: rotation tolerance per sample [rad].
        task: the components to meet per sample, as :func:`solve`.
        axis: the tool axis of task "axis".
        time_budget: wall-clock budget [s] of the whole path (None, the default: none); the compiled follower
            starts no sample after it (those are NaN rows with status ``time_budget``), the monitored loop stops
            each attempt at it.
        options: an ``FRDMOptions`` (taken as it is), or its fields as keywords (``kicks``, ``intervals``,
            ``freeze``, ``policy``, ``order``, ``w_p``, ...) over the path's defaults (max_sweeps 2000,
            stall_window 100, stall_rel 1e-6).
        solver_options: those fields as keyword arguments.
        jump_limit: largest joint step [rad or m] before the jump monitor fires (None: off).
        restrict: restrictions ("intervals", "freeze") held on every sample of the path.
        hold: samples a restriction stays on after the monitor switched it on.
        rest_weight: compiled follower only: weight of the rest term (None: 0.01 beyond six joints, else 0).
        collisions: as :func:`solve`: a sample whose answer collides is not reached (status ``collision``);
            ``contacts`` lists (sample, pair) for each; without ``q0`` the first target is solved clear.

    Returns:
        One row of q per sample, Pinocchio's errors, statuses, the monitor log (:class:`TrackResult`).

    Raises:
        TypeError: arguments after the targets given positionally.
        OptionError: a bad option, a solver other than "frdm", a restriction named without its table.
        ConfigurationError, JointLimitError, TargetError: a bad q0 or target, named.
    """
    check_entry(robot, "track", positional)
    settings = dict(solver=solver, tol_pos=tol_pos, tol_rot=tol_rot, time_budget=time_budget, options=options,
                    task=task, axis=axis, collisions=collisions, **solver_options)
    return prepared(robot, settings).track(targets, q0=q0, seed=seed, jump_limit=jump_limit, restrict=restrict,
                                           hold=hold, rest_weight=rest_weight)

