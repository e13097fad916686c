"""``kinelab robots`` (the registered names) and ``kinelab info`` (a robot's chain, joints and limits)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli import whole_info
from kinelab.cli.common import Subcommands, json_flag, load_robot, print_json, robot_arguments, verbose_flag
from kinelab.robot import catalog

if TYPE_CHECKING:
    import numpy as np

    from kinelab import collision
    from kinelab.ik.analytic import redundancy
    from kinelab.robot import Chain, Joint
    from kinelab.wholebody import ready
else:
    collision = lazy.module("kinelab.collision", globals())
    np = lazy.module("numpy", globals())
    redundancy = lazy.module("kinelab.ik.analytic.redundancy", globals())
    ready = lazy.module("kinelab.wholebody.ready", globals())


def add(sub: Subcommands) -> None:
    """The ``robots`` and ``info`` subcommands."""
    s = sub.add_parser("robots", help="list the registered robots")
    json_flag(s)
    s.set_defaults(func=run_robots)
    s = sub.add_parser("info", help="joints, types, limits, DOF and tool frame of a robot (a whole robot: its tree)")
    robot_arguments(s, limits=False)
    s.add_argument("--whole", action="store_true",
                   help="describe the whole robot (its tree, hands, feet, loops, the whole-body step it takes); a "
                        "registered whole robot such as talos is described whole unless a chain is named")
    s.add_argument("--collisions", action="store_true",
                   help="also build the self-collision model (loads the collision meshes) and say what it checks")
    json_flag(s)
    verbose_flag(s)
    s.set_defaults(func=run_info)


def run_robots(args: argparse.Namespace) -> int:
    """Each registered name with its description, file and chain."""
    rows = [
        {"name": e.name, "source": e.source, "file": e.relpath, "chain": e.chain, "tool": e.tool, "base": e.base,
         "srdf": e.srdf, "group": e.group, "description": e.description}
        for e in catalog.ENTRIES.values()
    ]
    if args.json:
        print_json(rows)
        return 0
    width = max(len(e.name) for e in catalog.ENTRIES.values()) + 2
    for r in rows:
        print(f"{r['name']:<{width}}{r['description']}")
        kind = "" if catalog.ENTRIES[str(r["name"])].whole else "chain "  # a whole robot's "chain" says it is one
        print(f"{'':<{width}}{r['source']}: {r['file']}; {kind}{r['chain']}")
    return 0


def _joint_row(j: Joint) -> dict[str, Any]:
    row: dict[str, Any] = {"name": j.name, "type": j.kind, "lower": j.lower, "upper": j.upper, "unit": j.unit}
    if j.kind != "prismatic":
        row["lower_deg"], row["upper_deg"] = float(np.rad2deg(j.lower)), float(np.rad2deg(j.upper))
    return row


def _shown_limits(j: Joint) -> tuple[str, str]:
    """A joint's limits as printed: metres for a prismatic joint, degrees for the others."""
    if j.kind == "prismatic":
        return f"{j.lower:.4f} m", f"{j.upper:.4f} m"
    return f"{np.rad2deg(j.lower):.3f} deg", f"{np.rad2deg(j.upper):.3f} deg"


def run_info(args: argparse.Namespace) -> int:
    """The robot's chain: base, tool, joints with their limits, the locked joints (a whole robot:
    :mod:`kinelab.cli.whole_info`)."""
    if whole_info.whole_wanted(args):
        return whole_info.run(args)
    robot = load_robot(args)
    info = {"robot": robot.name, "urdf": str(robot.urdf_path), "base": robot.base, "tool": robot.tool,
            "dof": robot.n, "nq": robot.nq, "nv": robot.nv, "joints": [_joint_row(j) for j in robot.joints],
            "locked": robot.locked, "mimics": {name: m.leader for name, m in robot.mimics.items()},
            "format": robot.source_format, "collisions": _collision_summary(robot) if args.collisions else None,
            "closed_form": redundancy.closed_form_summary(robot), "judge": str(robot.fk_certificate),
            "first_call": dict(ready.routes(robot))}
    if args.json:
        print_json(info)
    else:
        _print_info(robot, info, args.verbose)
    return 0


def _print_info(robot: Chain, info: dict[str, Any], verbose: bool) -> None:
    """``info``'s human form (as ``--json`` prints it): the chain, its joints and limits, mimics, locked joints,
    its branches, its judge and its collision check."""
    print(f"{robot.name}: {robot.n} DOF (nq={robot.nq}, nv={robot.nv}), base {robot.base!r} -> tool {robot.tool!r}")
    print(f"{robot.source_format}: {robot.urdf_path}")
    print(f"  {'#':>2} {'joint':<22} {'type':<11} {'lower':>12} {'upper':>12}")
    for i, j in enumerate(robot.joints, start=1):
        lo, hi = _shown_limits(j)
        print(f"  {i:>2} {j.name:<22} {j.kind:<11} {lo:>12} {hi:>12}")
    for name, m in robot.mimics.items():
        print(f"mimic: {name} follows {m.leader}")
    if robot.locked:
        print(f"locked: {', '.join(f'{k}={v:g}' for k, v in robot.locked.items())}")
    print(f"branches: {info['closed_form'] if verbose else redundancy.closed_form_words(robot)}")
    print(f"answers judged by: {info['judge']}")
    print("default routes (readied by kinelab.load in Python; prepare=False leaves them to the first call): "
          + ", ".join(f"{entry} → {route}" for entry, route in info["first_call"].items()))
    print(f"collisions: {info['collisions'] or 'not built (add --collisions: loads the meshes, counts the pairs)'}")


def _collision_summary(robot: Any) -> str:
    """What a self-collision check of this robot uses, or why it cannot run."""
    try:
        return collision.collision_model(robot, collision.Collisions()).summary
    except collision.CollisionError as err:
        return f"none ({err})"
