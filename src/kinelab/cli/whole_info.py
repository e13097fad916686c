"""``kinelab info`` of a whole robot (``kinelab info talos``, ``info delta``, ``info FILE --whole``): its tree — joints,
frames, hands and feet, the free-flyer, its mass — its loops and folded mimic joints, and which whole-body step
answers it and why."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import pairs, print_json
from kinelab.robot import catalog

if TYPE_CHECKING:
    import numpy as np

    from kinelab.robot.tree import Robot
else:
    np = lazy.module("numpy", globals())


def whole_wanted(args: argparse.Namespace) -> bool:
    """Whether ``info`` describes the whole robot: ``--whole``, or a registered whole robot named with no chain
    setting (--tool, --base, --group, --lock)."""
    if args.whole:
        return True
    entry = catalog.ENTRIES.get(args.robot)
    chain = args.tool or args.base or args.group or args.lock
    return bool(entry is not None and entry.whole and not chain)


def run(args: argparse.Namespace) -> int:
    """The whole robot's description, printed or as JSON."""
    from kinelab.robot.loading import load

    robot = load(args.robot, package_dirs=args.package_dir, srdf=args.srdf, whole=True,
                 xacro_args=pairs(args.xacro_arg, "--xacro-arg"), trust_xacro=args.trust_xacro)
    info = describe(robot)
    if args.json:
        print_json(info)
        return 0
    _print(info)
    return 0


def describe(robot: Robot) -> dict[str, Any]:
    """The whole robot in numbers and names (see the module's docstring)."""
    model, space = robot.model, robot.space
    joints = [{"name": model.names[j], "type": model.joints[j].shortname(), "nq": model.joints[j].nq,
               "lower": [float(x) for x in space.lower[model.joints[j].idx_q:][:model.joints[j].nq]],
               "upper": [float(x) for x in space.upper[model.joints[j].idx_q:][:model.joints[j].nq]]}
              for j in range(1, model.njoints)]
    return {"robot": robot.name, "file": None if robot.source is None else str(robot.source), "nq": robot.nq,
            "nv": robot.nv, "floating": robot.floating, "mass_kg": robot.mass, "joints": joints,
            "frames": len(model.frames), "hands": list(robot.hands), "feet": list(robot.feet),
            "named_poses": [] if robot.srdf is None else sorted(robot.srdf.states),
            "loops": [c.label for c in robot.closures], "actuated": list(robot.actuated),
            "mimics": {m.name: f"{m.multiplier:g} × {m.leader} + {m.offset:g}" for m in robot.mimics},
            "step": _route(robot)}


def _route(robot: Robot) -> str:
    """Which whole-body step answers a task on the robot's first hand (or last frame), and why."""
    from kinelab.wholebody import FrameTask, WholeBody

    frame = robot.hands[0] if robot.hands else robot.model.frames[-1].name
    q = robot.neutral()
    return WholeBody(robot, [FrameTask(frame, robot.frame_placement(q, frame))]).route


def _print(info: dict[str, Any]) -> None:
    base = "a free-flyer base" if info["floating"] else "a fixed base"
    print(f"{info['robot']}: the whole robot, {base}; nq={info['nq']}, nv={info['nv']}, {len(info['joints'])} joints, "
          f"{info['frames']} frames, mass {info['mass_kg']:.3f} kg")
    print(f"file: {info['file']}")
    for key, words in (("hands", "hands (the frames a user moves first)"), ("feet", "feet (held where they stand)"),
                       ("named_poses", "named poses (SRDF)"), ("loops", "loops"), ("actuated", "actuated joints")):
        if info[key]:
            print(f"{words}: {', '.join(info[key])}")
    for name, rule in info["mimics"].items():
        print(f"mimic (held as a coupling): {name} = {rule}")
    print(f"whole-body step: {info['step']}")
    print(f"  {'joint':<28} {'type':<22} {'lower':>10} {'upper':>10}")
    for j in info["joints"]:
        lo, hi = (f"{j['lower'][0]:.4g}", f"{j['upper'][0]:.4g}") if j["nq"] == 1 else ("", "")
        print(f"  {j['name']:<28} {j['type']:<22} {lo:>10} {hi:>10}")
