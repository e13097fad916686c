"""The ``kinelab`` command: parse, call the public API, print. User errors: one line, exit code 2.

Every command that prints results takes ``--json`` for a stable machine-readable form (see README).
Angles on the command line are radians unless ``--deg`` is given; ``--deg`` applies to revolute and
continuous joints only (prismatic joints stay in metres).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import re
import shutil
import sys
import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab import __version__ as kinelab_version
from kinelab.errors import ConfigurationError, KinelabError
from kinelab.geometry import quat_wxyz_from_matrix
from kinelab.robot import Robot, catalog, load


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit 2, as for every user error
        command = " ".join(self.prog.split()[1:])  # "" for the top parser, "ik" for a subcommand
        self.exit(2, f"kinelab: error: {message} (see 'kinelab {command + ' ' if command else ''}--help')\n")


def _q_from_cli(robot: Robot, values: list[str], deg: bool, what: str = "q") -> np.ndarray:
    """One number per joint (rad or m; degrees with --deg), or the name of an SRDF configuration."""
    if len(values) == 1 and not _is_number(values[0]):
        return robot.named_q(values[0])
    numbers = []
    for v in values:
        if not _is_number(v):
            raise ConfigurationError(f"{what}: {v!r} is not a number (give {robot.n} numbers, or one SRDF "
                                     "configuration name with --srdf)")
        numbers.append(float(v))
    q = robot.check_q(numbers, what=what)
    if deg:
        angular = np.array([k != "prismatic" for k in robot.joint_kinds])
        q = np.where(angular, np.deg2rad(q), q)
    return q


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _load(args: argparse.Namespace) -> Robot:
    """The robot a per-robot command names, with its --tool, --base, --srdf, --group and --package-dir."""
    return load(args.robot, tool=args.tool, base=args.base, srdf=args.srdf, group=args.group,
                package_dirs=args.package_dir, xacro_args=_xacro_args(args.xacro_arg))


def _xacro_args(items: list[str] | None) -> dict[str, str] | None:
    """--xacro-arg NAME=VALUE flags as a dict (a flag without '=' is refused)."""
    if not items:
        return None
    bad = [item for item in items if "=" not in item]
    if bad:
        raise KinelabError(f"--xacro-arg takes NAME=VALUE, got {bad[0]!r}")
    return dict(item.split("=", 1) for item in items)


def pose_dict(oMtool: pin.SE3) -> dict:
    """The JSON form of a pose: position [m], rotation matrix, quat_wxyz, rpy [rad]."""
    return {
        "position_m": oMtool.translation.tolist(),
        "rotation_matrix": oMtool.rotation.tolist(),
        "quat_wxyz": quat_wxyz_from_matrix(oMtool.rotation).tolist(),
        "rpy_rad": pin.rpy.matrixToRpy(oMtool.rotation).tolist(),
    }


def _print_json(obj) -> None:
    print(json.dumps(obj, indent=2))


def cmd_robots(args) -> int:
    rows = [
        {"name": e.name, "source": e.source, "file": e.relpath, "chain": e.chain, "tool": e.tool, "base": e.base,
         "srdf": e.srdf, "group": e.group, "description": e.description}
        for e in catalog.ENTRIES.values()
    ]
    if args.json:
        _print_json(rows)
    else:
        width = max(len(e.name) for e in catalog.ENTRIES.values()) + 2
        for r in rows:
            print(f"{r['name']:<{width}}{r['description']}")
            print(f"{'':<{width}}{r['source']}: {r['file']}; chain {r['chain']}")
    return 0


def _joint_row(j) -> dict:
    row = {"name": j.name, "type": j.kind, "lower": j.lower, "upper": j.upper, "unit": j.unit}
    if j.kind != "prismatic":
        row["lower_deg"], row["upper_deg"] = float(np.rad2deg(j.lower)), float(np.rad2deg(j.upper))
    return row


def cmd_info(args) -> int:
    robot = _load(args)
    info = {
        "robot": robot.name,
        "urdf": str(robot.urdf_path),
        "base": robot.base,
        "tool": robot.tool,
        "dof": robot.n,
        "nq": robot.nq,
        "nv": robot.nv,
        "joints": [_joint_row(j) for j in robot.joints],
        "locked": robot.locked,
    }
    if args.json:
        _print_json(info)
        return 0
    print(f"{robot.name}: {robot.n} DOF (nq={robot.nq}, nv={robot.nv}), base {robot.base!r} -> tool {robot.tool!r}")
    print(f"urdf: {robot.urdf_path}")
    print(f"  {'#':>2} {'joint':<22} {'type':<11} {'lower':>12} {'upper':>12}")
    for i, j in enumerate(robot.joints, start=1):
        if j.kind == "prismatic":
            lo, hi = f"{j.lower:.4f} m", f"{j.upper:.4f} m"
        else:
            lo, hi = f"{np.rad2deg(j.lower):.3f} deg", f"{np.rad2deg(j.upper):.3f} deg"
        print(f"  {i:>2} {j.name:<22} {j.kind:<11} {lo:>12} {hi:>12}")
    if robot.locked:
        print(f"locked: {', '.join(f'{k}={v:g}' for k, v in robot.locked.items())}")
    return 0


def cmd_fk(args) -> int:
    robot = _load(args)
    q = _q_from_cli(robot, args.q, args.deg)
    outside = _outside_limits(robot, q)
    oMtool = robot.fk(q)  # FK is defined at any q: a q outside the limits is computed and said, not refused
    out = {"robot": robot.name, "base": robot.base, "tool": robot.tool, "q": q.tolist(), **pose_dict(oMtool),
           "outside_limits": outside}
    if args.json:
        _print_json(out)
        return 0
    print(f"{robot.name}: pose of {robot.tool!r} in {robot.base!r}")
    for note in outside:
        print(f"  note: {note} (the pose is computed all the same)")
    print(f"  position [m]   {np.array2string(oMtool.translation, precision=6)}")
    print(f"  quat_wxyz      {np.array2string(np.array(out['quat_wxyz']), precision=6)}")
    print(f"  rpy [rad]      {np.array2string(np.array(out['rpy_rad']), precision=6)}")
    print("  rotation       " + np.array2string(oMtool.rotation, precision=6, prefix="  rotation       "))
    return 0


def _outside_limits(robot: Robot, q: np.ndarray) -> list[str]:
    """One line per joint of q outside its limits (empty when q is within them)."""
    out = []
    for j, value in zip(robot.joints, q, strict=True):
        if j.kind != "continuous" and not j.lower - 1e-9 <= value <= j.upper + 1e-9:
            out.append(f"{j.name} = {value:g} {j.unit} is outside its limits [{j.lower:.4g}, {j.upper:.4g}] {j.unit}")
    return out


def _rounded(values: Any, digits: int) -> list[float]:
    """Rounded for printing, without the −0.0 that rounding a tiny negative number leaves."""
    return (np.round(np.asarray(values, dtype=float), digits) + 0.0).tolist()


def _plural(count: int, word: str, plural: str | None = None) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {plural or word + 's'}"


def _bypass_value(robot, joint: str, text: str, deg: bool, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise KinelabError(f"{flag} {joint}: {text!r} is not a number") from None
    kind = robot.joint_kinds[robot.joint_index(joint)]
    return float(np.deg2rad(value)) if deg and kind != "prismatic" else value


ON_SINGULAR = {"kick": "kicks", "interval": "intervals", "freeze": "freeze"}


def _bypass_options(robot, args) -> dict:
    """FRDM's bypasses from --kick J=D, --interval J=LO:HI and --freeze J[=V] (rad, m; deg with --deg).

    --interval and --freeze hold from the first sweep; a kick is applied when the monitor fires, and so is any
    bypass named by --on-singular (the paper's monitor-switched policy, in the order given).
    """
    specs = {"kicks": args.kick or [], "intervals": args.interval or [], "freeze": args.freeze or []}
    if not any(specs.values()):
        if args.on_singular:
            raise KinelabError("--on-singular switches bypasses given by --kick, --interval or --freeze; none is")
        return {}
    if args.solver != "frdm":
        raise KinelabError("--kick, --interval and --freeze are FRDM's bypasses; use --solver frdm")
    out: dict[str, Any] = {}
    for spec in specs["kicks"]:
        joint, value = _split_spec(spec, "--kick", "JOINT=DELTA")
        out.setdefault("kicks", {})[joint] = _bypass_value(robot, joint, value, args.deg, "--kick")
    for spec in specs["intervals"]:
        joint, bounds = _split_spec(spec, "--interval", "JOINT=LOWER:UPPER")
        lo, colon, hi = bounds.partition(":")
        if not colon:
            raise KinelabError(f"--interval wants JOINT=LOWER:UPPER, got {spec!r}")
        out.setdefault("intervals", {})[joint] = (_bypass_value(robot, joint, lo, args.deg, "--interval"),
                                                  _bypass_value(robot, joint, hi, args.deg, "--interval"))
    for spec in specs["freeze"]:
        joint, sep, value = spec.partition("=")
        robot.joint_index(joint)  # an unknown joint is named with the valid ones
        out.setdefault("freeze", {})[joint] = _bypass_value(robot, joint, value, args.deg, "--freeze") if sep else None
    return {**out, **_policy(out, args.on_singular or [])}


def _split_spec(spec: str, flag: str, form: str) -> tuple[str, str]:
    joint, sep, value = spec.partition("=")
    if not sep:
        raise KinelabError(f"{flag} wants {form}, got {spec!r}")
    return joint, value


def _policy(bypasses: dict, on_singular: list[str]) -> dict:
    """FRDM's ``active`` (held from the start) and ``policy`` (switched by the monitor) for the CLI's flags."""
    switched = [ON_SINGULAR[name] for name in on_singular]
    for name, key in zip(on_singular, switched, strict=True):
        if key not in bypasses:
            raise KinelabError(f"--on-singular {name} needs --{name} JOINT=...")
    held = tuple(key for key in ("intervals", "freeze") if key in bypasses and key not in switched)
    policy = tuple(switched) + (("kicks",) if "kicks" in bypasses and "kicks" not in switched else ())
    return {**({"active": held} if held else {}), "policy": policy or ("auto_kick",)}


@contextlib.contextmanager
def compiling_notice(after: float = 1.0) -> Iterator[None]:
    """Say on stderr that the kernels are being compiled when the block takes longer than ``after`` [s]:
    the first run on a machine compiles them (numba) and keeps them for the next runs."""
    timer = threading.Timer(after, lambda: print(
        "kinelab: compiling its solver kernels for this machine (once; later runs load them) ...",
        file=sys.stderr, flush=True))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def cmd_ik(args) -> int:
    from kinelab.ik import solve, target_from_xyz_rpy
    from kinelab.ik.solve import solver_module

    robot = _load(args)
    if (args.target_q is None) == (args.target_xyz is None):
        raise KinelabError("give the target as --target-q Q... or as --target-xyz X Y Z [--target-rpy R P Y]")
    options: dict[str, Any] = {}
    if args.target_q is not None:
        q_target = robot.check_q(_q_from_cli(robot, args.target_q, args.deg, "--target-q"), limits=True,
                                 what="--target-q")
        target = robot.fk(q_target)
        if args.solver == "biquat":
            from kinelab.dq import kinematics as biquat_kinematics

            options["target_biquaternion"] = biquat_kinematics.pose(robot, q_target)  # N with its sign
    else:
        rpy = np.array(args.target_rpy if args.target_rpy is not None else [0.0, 0.0, 0.0])
        target = target_from_xyz_rpy(args.target_xyz, np.deg2rad(rpy) if args.deg else rpy)
    q0 = None if args.start_q is None else _q_from_cli(robot, args.start_q, args.deg, "--start-q")
    if args.solver == "frdm" and args.polish:
        options["polish"] = True
    options.update(_bypass_options(robot, args))
    if args.solver == "biquat":
        options.update({k: v for k, v in (("law", args.law), ("integrator", args.integrator), ("step", args.step),
                                          ("k", args.gain)) if v is not None})
    prepare = getattr(solver_module(args.solver), "prepare", None)
    if prepare is not None:
        with compiling_notice():
            prepare(robot)
    result = solve(robot, target, solver=args.solver, q0=q0, seed=args.seed, tol_pos=args.tol_pos,
                   tol_rot=args.tol_rot, time_budget=args.time_budget, task=args.task, axis=args.axis, **options)
    if args.json:
        _print_json({"robot": robot.name, "target": pose_dict(target), **result.to_dict()})
    else:
        _print_ik(robot, args, result)
    return 0 if result.success else 1


def _print_ik(robot: Robot, args: argparse.Namespace, result: Any) -> None:
    """The text form of an IK result: status, q, Pinocchio's errors on the task's components, effort."""
    from kinelab.ik.result import Status

    q_show = np.where([k != "prismatic" for k in robot.joint_kinds], np.rad2deg(result.q), result.q) \
        if args.deg else result.q
    print(f"{robot.name} {args.solver}, task {result.task}: {result.status.value} (success: {result.success})")
    print(f"  q{' [deg, m]' if args.deg else ' [rad, m]'}  {np.array2string(q_show, precision=6)}")
    free = {"position": (False, True), "orientation": (True, False)}.get(args.task, (False, False))
    print(f"  position error {result.position_error:.3e} m{' (free)' if free[0] else ''}, "
          f"{'axis' if args.task == 'axis' else 'rotation'} error {result.rotation_error:.3e} rad"
          f"{' (free)' if free[1] else ''} (Pinocchio FK)")
    print(f"  {_plural(result.iterations, 'iteration')}, {_plural(result.restarts, 'restart')}, "
          f"{result.wall_time * 1e3:.2f} ms, mode {result.mode}")
    if result.info.get("model_time"):
        m0 = result.info.get("M0")
        print(f"  model time {result.info['model_time']:.4g} s, final M0 = "
              + (f"{m0:+.6f}" if m0 is not None else "n/a (give --target-q for the sign of N)"))
    _print_events(result)
    if result.message:
        print("  " + re.sub(r"task='(\w+)'", r"--task \1", result.message))
    if not result.success and result.status is not Status.OUTSIDE_LIMITS and args.task != "position" \
            and args.target_xyz is not None and args.target_rpy is None:
        print("  (no --target-rpy: the target rotation is the identity; --task position ignores it)")


def _print_events(result: Any) -> None:
    """What the monitor saw and which bypasses were applied: in the answer's own attempt, and over the restarts."""
    attempts = result.restarts + 1
    if "answer_events" in result.info:
        own, held = result.info["answer_events"], result.info["answer_bypasses"]
        fired = f"fired {_plural(len(own), 'time')}" if own else "did not fire"
        applied = ", ".join(f"{b['bypass']} " + ("from the start" if b.get("sweep", 0) == 0 else
                                                 f"at sweep {b['sweep']}") for b in held) or "none"
        print(f"  the answer's attempt: monitor {fired}; bypasses: {applied}")
    fired_all = sum(e.count or 1 for e in result.singular_events)
    monitor = f"monitor fired {_plural(fired_all, 'time')}" if fired_all else "monitor did not fire"
    if "answer_events" not in result.info:  # the compiled multistart: a stall is answered by a restart
        print(f"  {_plural(attempts, 'attempt')}: {monitor}" + (" (each stall restarted)" if fired_all else ""))
    elif attempts > 1:
        switched = sum(1 for b in result.bypasses if b.sweep not in (None, 0))
        print(f"  over all {_plural(attempts, 'attempt')}: {monitor}"
              + (f", {_plural(switched, 'bypass', 'bypasses')} switched on by it" if switched else ""))


def cmd_singular(args) -> int:
    from kinelab.analysis import families, singular

    robot = _load(args)
    if args.sweep is not None:
        if args.q:
            raise KinelabError("give either a configuration or --sweep N, not both")
        families.check_sweep_size(robot, args.sweep, force=args.force)
        result = families.sweep(robot, samples=args.sweep, seed=args.seed, progress=not args.json,
                                method="grid" if args.grid else "random")
        out = {"robot": robot.name, **result.to_dict()}
        if args.json:
            _print_json(out)
            return 0
        for note in result.notes:
            print(f"note: {note}")
        asked = f" (a grid of {args.sweep} asked for)" if result.samples != args.sweep else ""
        print(f"{robot.name}: {_plural(result.samples, 'sample')}{asked}, {out['near_singular']} near-singular "
              f"(σ_min/σ_max < {singular.NEAR_SINGULAR:g}), {out['refined']} refined, {out['singular']} singular "
              "after refinement")
        for f in result.families:
            print(f"  rank {f.rank}, {f.count:4d} found: {f.text}")
            print(f"      e.g. q = {' '.join(repr(float(v)) for v in f.representative)}")
        return 0
    if not args.q:
        raise KinelabError("give a configuration Q1 ... Qn or --sweep N")
    q = _q_from_cli(robot, args.q, args.deg)
    a = singular.analyze(robot, robot.check_q(q, limits=not args.ignore_limits))
    if args.json:
        _print_json({"robot": robot.name, **a.to_dict()})
        return 0
    print(f"{robot.name}: rank {a.rank} of {a.full_rank}{' (SINGULAR)' if a.singular else ''}; "
          f"σ = {np.array2string(a.singular_values, precision=4)} (linear rows / L = {a.length:.4g} m)")
    print(f"  manipulability {a.manipulability:.4g}, condition {a.condition:.4g}")
    for d in a.lost_directions:
        parts = []
        if d.translation_axis is not None:
            axis, share = _rounded(d.translation_axis, 3), 100 * d.translation_share
            parts.append(f"translation {axis} ({share:.0f} %)")
        if d.rotation_axis is not None:
            axis, share = _rounded(d.rotation_axis, 3), 100 * d.rotation_share
            parts.append(f"rotation about {axis} ({share:.0f} %)")
        print(f"  lost tool motion (base axes, at the tool): {' + '.join(parts)}")
    for m in a.null_motions:
        print(f"  joint motion that moves nothing: {_rounded(m, 4)}")
    return 0


def cmd_validate(args) -> int:
    from kinelab.report import render, validate

    out = args.out or (None if args.json else "kinelab-report")  # --json alone writes no folder
    if out:
        render.check_output_folder(out)  # before the work, not after it
    report = validate.run(robots=args.robots, n=args.n, seed=args.seed, progress=not args.json)
    if out:
        render.write_validate_report(report, out)
    if args.json:
        _print_json(report.to_dict())
    else:
        print(render.validate_table(report, width=shutil.get_terminal_size((120, 24)).columns))
        print(f"report written to {out}")
    return 0 if report.passed else 1


def cmd_bench(args) -> int:
    from kinelab.report import render
    from kinelab.report.bench import runner as bench

    if args.out:
        render.check_output_folder(args.out)
    scaled = None
    if args.scaling:  # first: the peers' solver threads and caches would disturb this timing afterwards
        from kinelab.report.bench import scaling

        scaled = scaling.run(progress=not args.json)
    result = bench.run(robots=args.robots, n=args.n, seed=args.seed, solvers=args.solvers,
                       budget=args.budget_ms / 1e3, progress=not args.json, repeats=args.repeats, start=args.start,
                       sigma=args.sigma, schedule=args.schedule, task=args.task)
    if scaled is not None:
        result["scaling"] = scaled
    if args.tracking:
        from kinelab.studies import paper000_era

        result["tracking"] = paper000_era.tracking_bench(repeats=args.repeats)
    if args.loops:
        from kinelab.report.bench import loops

        result["loops"] = loops.run(args.robots, seed=args.seed, repeats=args.repeats, progress=not args.json)
    if args.out:
        render.write_bench(result, args.out)
    if args.json:
        _print_json(result)
    else:
        print(render.bench_markdown(result))
        if "scaling" in result:
            print(scaling.markdown(result["scaling"]))
        if "tracking" in result:
            print(paper000_era.tracking_markdown(result["tracking"]))
        if "loops" in result:
            print(loops.markdown(result["loops"]["throughput"], result["loops"]["tracking"],
                                 result["loops"]["budgets"]))
        if args.out:
            print(f"results written to {args.out}")
    return 0


def _publish(scene, html: str | None) -> int:
    """Write the scene as a static page (its caption in the page), or serve it live until interrupted (the
    caption printed under the address: the live page has none)."""
    if html:
        scene.save_html(html)
        scene.close()
        print(f"wrote {html}")
        _print_caption(scene)
        return 0
    return _serve(scene)


def _print_caption(scene) -> None:
    print(scene.title)
    for line in scene.legend.values():
        print(f"  {line}")


def _serve(scene) -> int:
    import signal
    import time

    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # so that the finally below stops the server
    print(f"meshcat is serving on {scene.url} (Ctrl-C to stop)", flush=True)
    _print_caption(scene)
    sys.stdout.flush()
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        return 0
    finally:
        scene.close()


def cmd_view(args) -> int:
    from kinelab.view import scene as viz

    robot = _load(args)
    q = robot.check_q(_q_from_cli(robot, args.q, args.deg) if args.q else robot.display_q())
    if not args.ignore_limits:
        for note in _outside_limits(robot, q):  # drawn all the same: a view is defined at any q
            print(f"kinelab: note: {note}", file=sys.stderr)
    scene = viz.Scene(robot).show(q)
    if args.singular:
        scene.singular_directions(q)
    return _publish(scene, args.html)


def cmd_animate(args) -> int:
    from kinelab.studies import paper000_era
    from kinelab.view import scene as viz

    passages = {f"era-{name}": build for name, build in paper000_era.PASSAGES.items()}
    if args.passage not in passages:
        raise KinelabError(f"unknown passage {args.passage!r}; passages are: {', '.join(passages)}")
    if not (math.isfinite(args.dt) and MIN_DT <= args.dt <= MAX_DT):
        raise KinelabError(f"--dt {args.dt} is not valid: seconds per sample, between {MIN_DT:g} and {MAX_DT:g}")
    robot = load("era")
    passage = passages[args.passage](robot)
    run = paper000_era.run(passage, robot)
    result = run.without if args.without_bypass else run.with_bypass
    scene = viz.Scene(robot, name=f"era ({'without' if args.without_bypass else 'with'} bypass)")
    scene.animate(result.q, dt=args.dt)
    one_lap = passage.targets[: (passage.lap or passage.samples) + 1]
    for k, target in enumerate(one_lap[:: max(1, len(one_lap) // 8)]):
        scene.frame(f"target{k}", target, 0.5 * scene.frame_length)
    summary = result.summary()
    print(f"{args.passage} {'without' if args.without_bypass else 'with'} bypass: {summary['reached']} of "
          f"{summary['samples']} samples reached, largest joint step {summary['max_joint_step']:.3f} rad, "
          f"{_plural(summary['monitor_events'], 'monitor event')}")
    return _publish(scene, args.html)


MIN_DT, MAX_DT = 1e-3, 60.0  # [s] per animation sample


def _robot_arguments(s: argparse.ArgumentParser, q_help: str | None = None, limits: bool = True) -> None:
    """The arguments every per-robot command shares: ROBOT [Q...] [--deg] [--tool] [--ignore-limits]."""
    s.add_argument("robot", help="registered name or URDF path")
    if q_help:
        s.add_argument("q", nargs="*", help=q_help + " (or the name of an SRDF configuration, with --srdf)")
        s.add_argument("--deg", action="store_true", help="angles of revolute/continuous joints in degrees")
    _add_source_args(s)
    if limits:
        s.add_argument("--ignore-limits", action="store_true",
                       help="accept q outside the joint limits (fk and view compute any finite q and note the joints "
                            "outside; this flag drops the note)")


def _add_source_args(s: argparse.ArgumentParser) -> None:
    """Where the chain starts and ends, and the files that describe the robot beyond its URDF."""
    s.add_argument("--tool", help="tool frame (default: the robot's own)")
    s.add_argument("--base", help="frame the chain starts from (default: the URDF root); poses are in this frame")
    s.add_argument("--srdf", help="SRDF file: named configurations (give a name as Q) and groups")
    s.add_argument("--group", help="SRDF group whose chain gives base and tool")
    s.add_argument("--package-dir", action="append", help="where package:// meshes resolve (repeatable)")
    s.add_argument("--xacro-arg", action="append", metavar="NAME=VALUE", help="an argument of a .xacro robot")


def build_parser() -> argparse.ArgumentParser:
    """The ``kinelab`` command line: one subparser per command."""
    p = _Parser(prog="kinelab", description="Kinematics of serial arms, checked against Pinocchio.")
    p.add_argument("--version", action="version", version=f"kinelab {kinelab_version}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for add in (_add_robots, _add_info, _add_fk, _add_ik, _add_singular, _add_view, _add_animate, _add_bench,
                _add_map, _add_validate):
        add(sub)
    return p


def _add_robots(sub: Any) -> None:
    s = sub.add_parser("robots", help="list the registered robots")
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_robots)


def _add_info(sub: Any) -> None:
    s = sub.add_parser("info", help="joints, types, limits, DOF and tool frame of a robot")
    _robot_arguments(s, limits=False)
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_info)


def _add_fk(sub: Any) -> None:
    s = sub.add_parser("fk", help="tool pose at a configuration")
    _robot_arguments(s, "one number per joint (rad and m; deg with --deg)")
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_fk)


def _add_ik(sub: Any) -> None:
    s = sub.add_parser("ik", help="inverse kinematics to a target pose or configuration")
    s.add_argument("robot", help="registered name or URDF path")
    s.add_argument("--solver", default="frdm", help="frdm, biquat or dls (the Pinocchio reference)")
    s.add_argument("--target-q", nargs="+", help="target as a configuration (its FK pose), or an SRDF name")
    s.add_argument("--target-xyz", nargs=3, type=float, help="target position [m] in the base frame")
    s.add_argument("--target-rpy", nargs=3, type=float,
                   help="target roll, pitch, yaw (rad; deg with --deg); without it the target rotation is the identity")
    s.add_argument("--task", choices=("pose", "position", "axis", "orientation"), default="pose",
                   help="the components to meet: pose (all), position, axis (point and one tool axis, roll free), "
                        "orientation")
    s.add_argument("--axis", choices=("x", "y", "z"), default="z", help="the tool axis of --task axis")
    s.add_argument("--start-q", nargs="+", help="first start (default: seeded random), or an SRDF name")
    s.add_argument("--deg", action="store_true", help="angles in degrees (revolute/continuous joints, rpy)")
    s.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    s.add_argument("--tol-pos", type=float, default=1e-6, help="[m]")
    s.add_argument("--tol-rot", type=float, default=1e-6, help="[rad]")
    s.add_argument("--time-budget", type=float, default=1.0, help="[s]")
    s.add_argument("--polish", action="store_true", help="frdm: add damped-least-squares polish steps")
    s.add_argument("--kick", action="append", metavar="JOINT=DELTA",
                   help="frdm bypass: signed step added when the monitor fires (repeatable)")
    s.add_argument("--interval", action="append", metavar="JOINT=LO:HI",
                   help="frdm bypass: keep the joint within [LO, HI] from the start (repeatable)")
    s.add_argument("--freeze", action="append", metavar="JOINT[=VALUE]",
                   help="frdm bypass: hold the joint at VALUE (or where it starts) from the start (repeatable)")
    s.add_argument("--on-singular", nargs="+", choices=tuple(ON_SINGULAR), metavar="BYPASS",
                   help="switch these bypasses on only when the monitor fires, in this order (the paper's "
                        "policy): kick, interval, freeze")
    s.add_argument("--law", choices=["simple", "regular"], help="biquat: control law (9)/(16) or (11)/(12)")
    s.add_argument("--integrator", choices=["euler", "rk4", "adaptive"], help="biquat: integrator")
    s.add_argument("--step", type=float, help="biquat: fixed step h [s] (the paper: 0.01; default 1/k)")
    s.add_argument("--gain", type=float, help="biquat: gain k [1/s] (default 1)")
    _add_source_args(s)
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_ik)


def _add_singular(sub: Any) -> None:
    s = sub.add_parser("singular", help="rank, singular values, lost directions; or a sweep for singular families")
    _robot_arguments(s, "one number per joint (rad and m; deg with --deg)")
    s.add_argument("--sweep", type=int, help="sample N configurations within the limits and report families")
    s.add_argument("--grid", action="store_true", help="sweep a stratified grid instead of uniform samples")
    s.add_argument("--force", action="store_true", help="run a sweep even when its memory estimate is over the limit")
    s.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_singular)


def _add_view(sub: Any) -> None:
    s = sub.add_parser("view", help="show a robot in meshcat (live on 127.0.0.1, or --html for a static page)")
    _robot_arguments(s, "configuration (default: zero, moved into the limits)")
    s.add_argument("--singular", action="store_true", help="draw the lost directions and σ_min at q")
    s.add_argument("--html", help="write a self-contained HTML page instead of serving")
    s.set_defaults(func=cmd_view)


def _add_animate(sub: Any) -> None:
    s = sub.add_parser("animate", help="animate a solver run in meshcat (the ERA passages)")
    s.add_argument("passage", help="era-elbow, era-wrist or era-shoulder (seed paper 000)")
    s.add_argument("--without-bypass", action="store_true", help="the run without the paper's bypass")
    s.add_argument("--dt", type=float, default=0.1, help="seconds per path sample in the animation")
    s.add_argument("--html", help="write a self-contained HTML page instead of serving")
    s.set_defaults(func=cmd_animate)


def _add_bench(sub: Any) -> None:
    s = sub.add_parser("bench", help="the IK benchmark: kinelab's solvers and the installed peers")
    s.add_argument("--robots", nargs="+", default=None,
                   help="robots (default: panda ur5 stanford era xarm7 z1 kinova ur10 so101 youbot)")
    s.add_argument("--n", type=int, default=200, help="targets per robot")
    s.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    s.add_argument("--solvers", nargs="+", default=None, help="solvers to run (default: all available)")
    s.add_argument("--budget-ms", type=float, default=5.0, help="time budget per solve [ms]")
    s.add_argument("--repeats", type=int, default=3, help="rounds over the set; per problem the fastest counts")
    s.add_argument("--start", choices=("random", "warm"), default="random",
                   help="starts: random in the limits, or warm: the target's q plus N(0, sigma) per joint")
    s.add_argument("--sigma", type=float, default=0.2, help="warm starts' noise per joint [rad or m]")
    s.add_argument("--task", choices=("pose", "position", "axis", "orientation"), default="pose",
                   help="the components judged (position: random target rotations; axis: tool z, random roll)")
    s.add_argument("--schedule", choices=("blocked", "interleaved"), default="blocked",
                   help="blocked: a solver runs the whole set, then the next; interleaved: every solver per problem")
    s.add_argument("--scaling", action="store_true", help="also time FRDM on synthetic chains of 7-100 links")
    s.add_argument("--tracking", action="store_true", help="also time tracking along the ERA passages (FRDM, DLS)")
    s.add_argument("--loops", action="store_true",
                   help="also the loops users run: throughput (solve loop, solve_batch, ik_LM) and path tracking")
    s.add_argument("--out", help="write bench.json, bench.md and bench.png here")
    s.add_argument("--json", action="store_true", help="print the results as JSON instead of tables")
    s.set_defaults(func=cmd_bench)


def _add_map(sub: Any) -> None:
    s = sub.add_parser("map", help="reachability maps (kinelab.maps)")
    kinds = s.add_subparsers(dest="kind", required=True, metavar="KIND", parser_class=_Parser)
    r = kinds.add_parser("reach", help="the share of orientations the arm reaches in each voxel of its workspace")
    r.add_argument("robot", help="a registered name or a model file (see kinelab robots)")
    r.add_argument("--voxel", type=float, default=0.1, help="voxel side [m]")
    r.add_argument("--orientations", type=int, default=16, help="target orientations per voxel")
    r.add_argument("--task", choices=("pose", "axis"), default="pose",
                   help="pose, or axis: the tool z axis along spread directions, the roll free")
    r.add_argument("--restarts", type=int, default=20, help="random restarts per target")
    r.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    r.add_argument("--chunk", type=int, default=64, help="voxels per chunk (the unit of work and of storage)")
    r.add_argument("--out", help="a Zarr directory: written chunk by chunk, resumed if it holds this map unfinished")
    r.add_argument("--force", action="store_true", help="run a map of more than 2 million targets")
    r.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on this Dask scheduler (kinelab[cluster])")
    r.add_argument("--workers", type=int, help="run the chunks on a local Dask cluster of this many processes")
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.set_defaults(func=cmd_map_reach)
    b = kinds.add_parser("base", help="platform positions (and headings) from which a mobile manipulator reaches "
                                      "a grasp")
    b.add_argument("robot", help="a mobile manipulator with joints platform_x, platform_y, platform_yaw (youbot)")
    b.add_argument("--grasp", nargs=6, type=float, required=True, metavar=("X", "Y", "Z", "R", "P", "YAW"),
                   help="the grasp pose: position [m] and roll, pitch, yaw [rad] in the world frame")
    b.add_argument("--step", type=float, default=0.05, help="x-y grid spacing [m]")
    b.add_argument("--top", type=int, default=5, help="how many of the best poses to print")
    b.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    b.add_argument("--json", action="store_true", help="print the reachable poses as JSON")
    b.set_defaults(func=cmd_map_base)
    g = kinds.add_parser("singular", help="σ_min/σ_max over joint-space samples (the engine of singular --sweep)")
    g.add_argument("robot", help="a registered name or a model file (see kinelab robots)")
    g.add_argument("--samples", type=int, default=5000, help="configurations to sample")
    g.add_argument("--grid", action="store_true", help="a stratified grid instead of uniform samples")
    g.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.set_defaults(func=cmd_map_singular)


def cmd_map_base(args) -> int:
    from kinelab import maps
    from kinelab.ik import target_from_xyz_rpy

    robot = load(args.robot)
    grasp = target_from_xyz_rpy(args.grasp[:3], args.grasp[3:])
    result = maps.base_map(robot, grasp, step=args.step, seed=args.seed)
    best = result.ranked(args.top)
    rows = [{"x": float(result.poses[i, 0]), "y": float(result.poses[i, 1]), "yaw": float(result.poses[i, 2]),
             "manipulability": float(result.manipulability[i]), "arm_q": result.q[i].tolist()} for i in best]
    if args.json:
        _print_json({"robot": robot.name, "candidates": len(result.poses), "reachable": int(result.reachable.sum()),
                     "best": rows})
        return 0
    print(f"{robot.name}: the grasp is reached from {int(result.reachable.sum())} of "
          f"{_plural(len(result.poses), 'platform position')} ({args.step:g} m grid); the best:")
    for r in rows:
        print(f"  x {r['x']:+.3f} m  y {r['y']:+.3f} m  yaw {r['yaw']:+.4f} rad  "
              f"manipulability {r['manipulability']:.3g}")
    return 0


def cmd_map_singular(args) -> int:
    from kinelab import maps

    robot = load(args.robot)
    result = maps.singularity(robot, samples=args.samples, seed=args.seed, method="grid" if args.grid else "random",
                              progress=not args.json)
    ratio = result.sigma_ratio
    summary = {"robot": robot.name, "samples": int(len(ratio)), "rank_deficient": int(result.rank_deficient.sum()),
               "near_singular": int((ratio < 0.01).sum()), "median_sigma_ratio": float(np.median(ratio))}
    if args.json:
        _print_json(summary)
    else:
        print(f"{robot.name}: {_plural(len(ratio), 'sample')}; {summary['near_singular']} near-singular "
              f"(σ_min/σ_max < 0.01), {summary['rank_deficient']} rank-deficient; median σ_min/σ_max "
              f"{summary['median_sigma_ratio']:.3g}")
    return 0


def cmd_map_reach(args) -> int:
    import time

    from kinelab import maps

    robot = load(args.robot)
    spec = maps.MapSpec(voxel=args.voxel, orientations=args.orientations, task=args.task, restarts=args.restarts,
                        seed=args.seed, chunk_voxels=args.chunk)
    if args.scheduler and args.workers:
        raise KinelabError("give --scheduler ADDRESS or --workers N, not both")
    if args.workers is not None and args.workers < 1:
        raise KinelabError(f"--workers must be at least 1, got {args.workers}")
    client = None
    if args.scheduler or args.workers:
        from kinelab.maps import cluster

        client = cluster.client_for(args.scheduler, args.workers)
    t0 = time.perf_counter()
    try:
        result = maps.reachability(robot, spec, out=args.out, force=args.force, progress=not args.json, client=client)
    finally:
        if client is not None:
            client.close()
    reach = result.array("reachability")
    summary = {"robot": robot.name, "voxels": int(len(reach)), "targets": int(len(reach) * spec.orientations),
               "reached_voxels": int((reach > 0).sum()), "mean_reachability": float(np.nanmean(reach)),
               "seconds": time.perf_counter() - t0, "out": args.out}
    if args.json:
        _print_json(summary)
    else:
        print(f"{robot.name}: {_plural(summary['voxels'], 'voxel')} of {args.voxel:g} m × {spec.orientations} "
              f"orientations; {summary['reached_voxels']} voxels reached, mean reachability "
              f"{summary['mean_reachability']:.3f}; {summary['seconds']:.1f} s"
              + (f"; written to {args.out}" if args.out else ""))
    return 0


def _add_validate(sub: Any) -> None:
    s = sub.add_parser("validate", help="check every kinelab computation against Pinocchio on the bundled robots")
    s.add_argument("--robots", nargs="+", default=None, help="robots to check (default: the embedded set)")
    s.add_argument("--n", type=int, default=None, help="random configurations per check")
    s.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")
    s.add_argument("--out", default=None,
                   help="the report folder (Markdown, HTML with the figures, JSON); default ./kinelab-report, "
                        "none with --json")
    s.add_argument("--json", action="store_true", help="print the result as JSON")
    s.set_defaults(func=cmd_validate)


def main(argv: list[str] | None = None) -> int:
    """Run one command; a user error prints one line and returns 2, Ctrl-C returns 130."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except KinelabError as exc:
        print(f"kinelab: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("kinelab: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (| head): say nothing more
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
