"""``kinelab ik``: inverse kinematics to a target pose or configuration, with FRDM's bypasses as flags."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from dataclasses import fields
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import (
    Subcommands,
    collision_arguments,
    collisions_of,
    json_flag,
    load_robot,
    plural,
    pose_dict,
    print_json,
    q_from_cli,
    seed_argument,
    shown,
    source_arguments,
    target_arguments,
    verbose_flag,
)
from kinelab.errors import KinelabError
from kinelab.ik.frdm.policy import SWITCHABLE, bypass_plan
from kinelab.ik.words import AXES, TASKS

if TYPE_CHECKING:
    import numpy as np

    from kinelab import ik
    from kinelab.dq import kinematics as biquat_kinematics
    from kinelab.ik import registry, targets, turns
    from kinelab.ik import result as result_module
    from kinelab.ik.result import IKResult
    from kinelab.robot import Chain
else:
    biquat_kinematics = lazy.module("kinelab.dq.kinematics", globals())
    ik = lazy.module("kinelab.ik", globals())
    np = lazy.module("numpy", globals())
    registry = lazy.module("kinelab.ik.registry", globals())
    result_module = lazy.module("kinelab.ik.result", globals())
    targets = lazy.module("kinelab.ik.targets", globals())
    turns = lazy.module("kinelab.ik.turns", globals())

SOLVER_FLAGS = (("--polish", "polish", "polish"), ("--law", "law", "law"), ("--integrator", "integrator", "integrator"),
                ("--step", "step", "step"), ("--gain", "gain", "k"))  # (flag, its argparse name, the option field)


def _given(value: Any) -> bool:
    """A solver flag given on the command line: anything but None and an unset switch (0 is a value given)."""
    return value is not None and value is not False


def option_fields(solver: str) -> frozenset[str]:
    """The option fields of the solver a ``--solver`` name runs (none for the closed form, which takes none).

    Raises:
        SolverNotFoundError: an unknown solver, the valid ones named.
    """
    kind = registry.capabilities(solver)
    if kind.closed_form:
        return frozenset()
    return frozenset(f.name for f in fields(registry.solver_module(kind.request_solver(solver)).Options))


def add(sub: Subcommands) -> None:
    """The ``ik`` subcommand."""
    s = sub.add_parser("ik", help="inverse kinematics to a target pose or configuration")
    s.add_argument("robot", help="registered name or model file (URDF, xacro, MJCF)")
    s.add_argument("--solver", default="auto",
                   help="auto (the default: the fastest certified route for the arm, docs/route.md), frdm, biquat, "
                        "dls (the Pinocchio reference) or analytic (the closed form or 1-D search, for the arms "
                        "`kinelab info` names one for: the branch nearest --start-q)")
    target_arguments(s)
    s.add_argument("--task", choices=TASKS, default="pose",
                   help="the components to meet: pose (all, the default), position, axis (point and one tool axis, "
                        "roll free), orientation")
    s.add_argument("--axis", choices=AXES, default="z", help="the tool axis of --task axis (default z)")
    s.add_argument("--start-q", nargs="+",
                   help="first start, an SRDF name, or 'random' (drawn from the seed); default: the robot's SRDF "
                        "home, else the middle of the limits (revolute answers then the turn nearest it)")
    s.add_argument("--deg", action="store_true", help="angles in degrees (revolute/continuous joints, rpy)")
    seed_argument(s)
    s.add_argument("--tol-pos", type=float, default=1e-6, help="position tolerance [m] (default 1e-6)")
    s.add_argument("--tol-rot", type=float, default=1e-6, help="rotation tolerance [rad] (default 1e-6)")
    s.add_argument("--time-budget", type=float, default=1.0, help="wall-clock budget [s] (default 1)")
    s.add_argument("--polish", action="store_true", help="frdm: add damped-least-squares polish steps")
    s.add_argument("--kick", action="append", metavar="JOINT=DELTA",
                   help="frdm bypass: signed step added when the monitor fires (repeatable)")
    s.add_argument("--interval", action="append", metavar="JOINT=LO:HI",
                   help="frdm bypass: keep the joint within [LO, HI] from the start (repeatable)")
    s.add_argument("--freeze", action="append", metavar="JOINT[=VALUE]",
                   help="frdm bypass: hold the joint at VALUE (or where it starts) from the start (repeatable)")
    s.add_argument("--on-singular", nargs="+", choices=tuple(SWITCHABLE), metavar="BYPASS",
                   help="switch these bypasses on only when the monitor fires, in this order (the paper's "
                        "policy): kick, interval, freeze")
    s.add_argument("--law", choices=["simple", "regular"], help="biquat: control law (9)/(16) or (11)/(12)")
    s.add_argument("--integrator", choices=["euler", "rk4", "adaptive"], help="biquat: integrator")
    s.add_argument("--step", type=float, help="biquat: fixed step h [s] (the paper: 0.01; default 1/k); dls: fraction "
                   "of the Gauss–Newton step per iteration, in (0, 2)")
    s.add_argument("--gain", type=float, help="biquat: gain k [1/s] (default 1)")
    collision_arguments(s)
    source_arguments(s)
    json_flag(s)
    verbose_flag(s)
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Solve, print the result (or its JSON form); exit 0 when reached, 1 when not."""
    robot = load_robot(args)
    target, options = _target(robot, args)
    q0, start = _start(robot, args)
    _refuse_other_solvers_flags(args)
    options.update(_bypass_options(robot, args))
    options.update({field: getattr(args, dest) for _, dest, field in SOLVER_FLAGS if _given(getattr(args, dest))})
    result = ik.solve(robot, target, solver=args.solver, q0=q0, seed=args.seed, tol_pos=args.tol_pos,
                      tol_rot=args.tol_rot, time_budget=args.time_budget, task=args.task, axis=args.axis,
                      collisions=collisions_of(args), **options)
    result = turns.nearest_turns(robot, result, q0, target, args.task, args.axis, args.tol_pos, args.tol_rot)
    if args.json:
        print_json({"robot": robot.name, "target": pose_dict(target),
                    "start": {"q": None if q0 is None else q0.tolist(), "from": start},
                    **result.to_dict()})
    else:
        _print_ik(robot, args, result)
        print(f"  start: {start}" + ("" if q0 is None else "; each revolute angle is the turn of it nearest the start "
                                                          "within the limits"))
    return 0 if result.success else 1


def _start(robot: Chain, args: argparse.Namespace) -> tuple[np.ndarray | None, str]:
    """The first start [rad, m] and where it comes from: --start-q (``random``: drawn from the seed, None), else
    the robot's reference configuration (:meth:`~kinelab.robot.Chain.reference_q`)."""
    if args.start_q == ["random"]:
        return None, "drawn at random from the seed (--start-q random)"
    if args.start_q is not None:
        return q_from_cli(robot, args.start_q, args.deg, "--start-q"), "--start-q"
    q0, how = robot.reference_q()
    return q0, f"{how} (give --start-q for another)"


def target_of(robot: Chain, args: argparse.Namespace) -> Any:
    """The target pose of ``--target-q`` or ``--target-xyz``/``--target-rpy`` (shared with ``kinelab branches``)."""
    return _target(robot, args)[0]


def _target(robot: Chain, args: argparse.Namespace) -> tuple[Any, dict[str, Any]]:
    """The target pose, and the biquaternion solver's signed target when it is given as a configuration."""
    if (args.target_q is None) == (args.target_xyz is None):
        raise KinelabError("give the target as --target-q Q... or as --target-xyz X Y Z [--target-rpy R P Y]")
    options: dict[str, Any] = {}
    if args.target_q is None:
        rpy = np.array(args.target_rpy if args.target_rpy is not None else [0.0, 0.0, 0.0])
        if not args.deg and np.abs(rpy).max() > targets.DEGREES_LIKELY:
            raise KinelabError(f"--target-rpy {' '.join(f'{v:g}' for v in rpy)} looks like degrees (an angle beyond "
                               "±2π rad): add --deg, or give radians")
        return ik.target_from_xyz_rpy(args.target_xyz, rpy, degrees=args.deg), options
    q_target = robot.check_q(q_from_cli(robot, args.target_q, args.deg, "--target-q"), limits=True,
                             what="--target-q")
    if "target_biquaternion" in option_fields(args.solver):  # a solver that wants the signed target gets it
        options["target_biquaternion"] = biquat_kinematics.pose(robot, q_target)  # N with its sign
    return robot.fk(q_target), options


def _bypass_value(robot: Chain, joint: str, text: str, deg: bool, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise KinelabError(f"{flag} {joint}: {text!r} is not a number") from None
    kind = robot.joint_kinds[robot.joint_index(joint)]
    return float(np.deg2rad(value)) if deg and kind != "prismatic" else value


def _refuse_other_solvers_flags(args: argparse.Namespace) -> None:
    """A flag of another solver's is a mistake, said (it used to be dropped without a word); --axis goes with
    --task axis only."""
    mine = option_fields(args.solver)
    given = [(flag, field) for flag, dest, field in SOLVER_FLAGS if _given(getattr(args, dest)) and field not in mine]
    if given:
        flag, field = given[0]
        owners = [name for name in registry.names() if field in option_fields(name)]
        raise KinelabError(f"{flag} is an option of --solver {' or '.join(owners)}, not of --solver {args.solver}")
    if args.axis != "z" and args.task != "axis":
        raise KinelabError(f"--axis {args.axis} names the tool axis of --task axis; the task is {args.task}")


def _bypass_options(robot: Chain, args: argparse.Namespace) -> dict[str, Any]:
    """FRDM's bypass tables from --kick J=D, --interval J=LO:HI and --freeze J[=V] (rad, m; deg with --deg), with
    the policy :func:`kinelab.ik.frdm.options.bypass_plan` gives for --on-singular."""
    parsers: dict[str, tuple[list[str] | None, Callable[[Chain, str, bool], tuple[str, Any]]]] = {
        "kicks": (args.kick, _kick), "intervals": (args.interval, _interval), "freeze": (args.freeze, _freeze)}
    if not _bypasses_given(args, any(specs for specs, _ in parsers.values())):
        return {}
    out = {key: dict(parse(robot, spec, args.deg) for spec in specs)
           for key, (specs, parse) in parsers.items() if specs}
    return {**out, **bypass_plan(out, tuple(args.on_singular or ()))}


def _bypasses_given(args: argparse.Namespace, given: bool) -> bool:
    """Whether bypasses are ``given``, refusing --on-singular without them and bypasses for a solver without any.

    Raises:
        KinelabError: either.
    """
    if not given:
        if args.on_singular:
            raise KinelabError("--on-singular switches bypasses given by --kick, --interval or --freeze; none is")
        return False
    if "kicks" not in option_fields(args.solver):
        owners = " or ".join(name for name in registry.names() if "kicks" in option_fields(name))
        raise KinelabError(f"--kick, --interval and --freeze are bypasses of --solver {owners}, not of "
                           f"--solver {args.solver}")
    return True


def _kick(robot: Chain, spec: str, deg: bool) -> tuple[str, float]:
    """--kick JOINT=DELTA: the joint and its kick (rad or m; deg with ``deg``)."""
    joint, value = _split_spec(spec, "--kick", "JOINT=DELTA")
    return joint, _bypass_value(robot, joint, value, deg, "--kick")


def _freeze(robot: Chain, spec: str, deg: bool) -> tuple[str, float | None]:
    """--freeze JOINT[=VALUE]: the joint and the value it is held at (None: where it is)."""
    joint, sep, value = spec.partition("=")
    robot.joint_index(joint)  # an unknown joint is named with the valid ones
    return joint, _bypass_value(robot, joint, value, deg, "--freeze") if sep else None


def _interval(robot: Chain, spec: str, deg: bool) -> tuple[str, tuple[float, float]]:
    """--interval JOINT=LOWER:UPPER: the joint and its bounds (rad or m; deg with ``deg``).

    Raises:
        KinelabError: another form, an unknown joint or a bad value (named).
    """
    joint, bounds = _split_spec(spec, "--interval", "JOINT=LOWER:UPPER")
    lo, colon, hi = bounds.partition(":")
    if not colon:
        raise KinelabError(f"--interval wants JOINT=LOWER:UPPER, got {spec!r}")
    return joint, (_bypass_value(robot, joint, lo, deg, "--interval"),
                   _bypass_value(robot, joint, hi, deg, "--interval"))


def _split_spec(spec: str, flag: str, form: str) -> tuple[str, str]:
    joint, sep, value = spec.partition("=")
    if not sep:
        raise KinelabError(f"{flag} wants {form}, got {spec!r}")
    return joint, value


def _print_ik(robot: Chain, args: argparse.Namespace, result: IKResult) -> None:
    """The text form of an IK result: status, q, Pinocchio's errors on the task's components, effort."""
    _print_answer(robot, args, result)
    _print_solver_notes(args, result)
    if result.message:
        print("  " + re.sub(r"task='(\w+)'", r"--task \1", result.message))
    if not result.success and result.status is not result_module.Status.OUTSIDE_LIMITS and args.task != "position" \
            and args.target_xyz is not None and args.target_rpy is None:
        print("  (no --target-rpy: the target rotation is the identity; --task position ignores it)")


def _print_answer(robot: Chain, args: argparse.Namespace, result: IKResult) -> None:
    """Status, q (degrees with --deg), the errors on the task's components and the effort."""
    q_show = np.where([k != "prismatic" for k in robot.joint_kinds], np.rad2deg(result.q), result.q) \
        if args.deg else result.q
    route = result.solver if result.solver == args.solver else f"{result.solver} (--solver {args.solver})"
    print(f"{robot.name} {route}, task {result.task}: {result.status.value} (success: {result.success})")
    print(f"  q{' [deg, m]' if args.deg else ' [rad, m]'}  {shown(q_show)}")
    free = {"position": (False, True), "orientation": (True, False)}.get(args.task, (False, False))
    print(f"  position error {result.position_error:.3e} m{' (free)' if free[0] else ''}, "
          f"{'axis' if args.task == 'axis' else 'rotation'} error {result.rotation_error:.3e} rad"
          f"{' (free)' if free[1] else ''} (Pinocchio FK)")
    print(f"  {plural(result.iterations, 'iteration')}, {plural(result.restarts, 'restart')}, "
          f"{result.wall_time * 1e3:.2f} ms (one call, first-call costs included; `kinelab bench` times repeated "
          f"calls)" + (f", method {result.mode}" if args.verbose else ""))


def _print_solver_notes(args: argparse.Namespace, result: IKResult) -> None:
    """What the solver adds: the biquaternion model's time and M0, the singularity monitor, the collision retries."""
    diag = result.diagnostics
    if isinstance(diag, result_module.BiquatDiagnostics) and diag.model_time:
        m0 = diag.M0
        print(f"  model time {diag.model_time:.4g} s, final M0 = "
              + (f"{m0:+.6f}" if m0 is not None else "n/a (give --target-q for the sign of N)"))
    if registry.capabilities(result.solver).monitored:  # only the route with the singularity monitor has events
        _print_monitor(args, result)
    if result.success and result.diagnostics.clear_after is not None:
        print(f"  clear of collisions ({plural(result.diagnostics.clear_after, 'colliding answer')} found before)")


def _print_monitor(args: argparse.Namespace, result: IKResult) -> None:
    """The singularity monitor's account: in full with --verbose or the user's own bypasses, else one line when it
    fired."""
    if args.verbose or args.kick or args.interval or args.freeze:  # the user's own bypasses: what they did
        _print_events(result)
    elif fired := sum(e.count or 1 for e in result.singular_events):
        print(f"  passed near a singular configuration {plural(fired, 'time')} on the way (--verbose: what the "
              "solver did about it)")


def _print_answer_attempt(result: IKResult) -> None:
    """The monitor's events and the bypasses applied in the attempt that gave the answer."""
    own, held = result.diagnostics.answer_events, result.diagnostics.answer_bypasses
    fired = f"fired {plural(len(own), 'time')}" if own else "did not fire"
    applied = ", ".join(f"{b.bypass} " + ("from the start" if not b.sweep else f"at sweep {b.sweep}")
                        for b in held) or "none"
    print(f"  the answer's attempt: monitor {fired}; bypasses: {applied}")


def _print_events(result: IKResult) -> None:
    """What the monitor saw and which bypasses were applied: in the answer's own attempt, and over the restarts."""
    looped = result.diagnostics.path != "compiled"  # the compiled multistart answers a stall by a restart
    if looped:
        _print_answer_attempt(result)
    _print_attempts(result, looped)


def _print_attempts(result: IKResult, looped: bool) -> None:
    """The monitor over every attempt: how often it fired and how many bypasses it switched on (the compiled
    multistart, not ``looped``, restarts at each stall)."""
    attempts = result.restarts + 1
    fired_all = sum(e.count or 1 for e in result.singular_events)
    monitor = f"monitor fired {plural(fired_all, 'time')}" if fired_all else "monitor did not fire"
    if not looped:
        print(f"  {plural(attempts, 'attempt')}: {monitor}" + (" (each stall restarted)" if fired_all else ""))
    elif attempts > 1:
        switched = sum(1 for b in result.bypasses if b.sweep not in (None, 0))
        print(f"  over all {plural(attempts, 'attempt')}: {monitor}"
              + (f", {plural(switched, 'bypass', 'bypasses')} switched on by it" if switched else ""))
