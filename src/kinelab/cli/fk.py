"""``kinelab fk``: the tool pose at a configuration."""

from __future__ import annotations

import argparse
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli import common
from kinelab.cli.common import Subcommands

if TYPE_CHECKING:
    import pinocchio as pin

    from kinelab import collision
    from kinelab.robot import Chain
else:
    collision = lazy.module("kinelab.collision", globals())


def add(sub: Subcommands) -> None:
    """The ``fk`` subcommand."""
    s = sub.add_parser("fk", help="tool pose at a configuration")
    common.robot_arguments(s, "one number per joint (rad and m; deg with --deg)")
    common.collision_arguments(s)
    common.json_flag(s)
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print oMtool at q: position, quaternion (w, x, y, z), roll-pitch-yaw and the rotation matrix."""
    robot = common.load_robot(args)
    q = common.q_from_cli(robot, args.q, args.deg)
    outside = [] if args.ignore_limits else robot.outside_limits(q)
    oMtool = robot.fk(q)  # FK is defined at any q: a q outside the limits is computed and said, not refused
    out = {"robot": robot.name, "base": robot.base, "tool": robot.tool, "q": q.tolist(), **common.pose_dict(oMtool),
           "outside_limits": outside}
    spec, contacts = common.collisions_of(args), []
    if spec is not None:
        contacts = collision.collision_model(robot, spec).contacts(q)  # every pair in contact, as the view colours them
        out["collision"] = asdict(contacts[0]) if contacts else None
        out["contacts"] = [asdict(c) for c in contacts]
    if args.json:
        common.print_json(out)
    else:
        _print_pose(robot, oMtool, out, contacts)
    return 0


def _print_pose(robot: Chain, oMtool: pin.SE3, out: dict[str, Any], contacts: list[collision.Contact]) -> None:
    """The human form of ``fk``'s answer (``out`` as printed with ``--json``)."""
    print(f"{robot.name}: pose of {robot.tool!r} in {robot.base!r}")
    for note in out["outside_limits"]:
        print(f"  note: {note} (the pose is computed all the same)")
    print(f"  position [m]   {common.shown(oMtool.translation)}")
    print(f"  quat_wxyz      {common.shown(out['quat_wxyz'])}")
    print(f"  rpy [rad]      {common.shown(out['rpy_rad'])}")
    print("  rotation       " + common.shown(oMtool.rotation, prefix="  rotation       "))
    if "collision" in out:
        pairs = f"{len(contacts)} pair{'s' if len(contacts) != 1 else ''} in contact: " if contacts else "none"
        print(f"  collision      {pairs}{'; '.join(str(c) for c in contacts)}")
