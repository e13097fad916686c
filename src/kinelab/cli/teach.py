"""``kinelab teach``: a robot to move by hand in the browser (sliders, a draggable target, live readings)."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import (
    Subcommands,
    collision_arguments,
    collisions_of,
    load_robot,
    pairs,
    q_from_cli,
    robot_arguments,
)
from kinelab.errors import KinelabError
from kinelab.files import interrupt_taken
from kinelab.progress import step
from kinelab.robot import catalog

if TYPE_CHECKING:
    import signal
    import webbrowser

    from kinelab import robot as robot_module
    from kinelab.view import teach
else:
    robot_module = lazy.module("kinelab.robot", globals())
    signal = lazy.module("signal", globals())
    teach = lazy.module("kinelab.view.teach", globals())
    webbrowser = lazy.module("webbrowser", globals())


def add(sub: Subcommands) -> None:
    """The ``teach`` subcommand."""
    s = sub.add_parser("teach", help="move a robot by hand in the browser: joint sliders, a target to drag that it "
                                     "follows by IK, its branches, σ_min and the velocity ellipsoid (127.0.0.1); a "
                                     "whole robot (talos, g1, baxter, ...): a target per hand, its feet held")
    robot_arguments(s, "start configuration within the limits (default: the robot's reference configuration)",
                    limits=False)
    collision_arguments(s)
    s.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default 0: a free one)")
    s.add_argument("--time-budget", type=float, default=None,
                   help="seconds one follow of the target may take (default 0.05; a whole robot's 0.5)")
    s.add_argument("--hands", nargs="+", metavar="FRAME",
                   help="the whole robot's frames to drag (default: its registered hands; implies the whole robot)")
    s.add_argument("--feet", nargs="*", metavar="FRAME",
                   help="the whole robot's frames held where they stand (default: its registered feet)")
    s.add_argument("--open", action="store_true", help="open the page in the default browser")
    s.set_defaults(func=run_teach)


def run_teach(args: argparse.Namespace) -> int:
    """Serve the teach page until Ctrl-C (or SIGTERM)."""
    if not 0 <= args.port <= 65535:
        raise KinelabError(f"--port {args.port} is not a port: give 1–65535, or 0 for a free one")
    if args.time_budget is not None and not 0 < args.time_budget <= 60:
        raise KinelabError(f"--time-budget {args.time_budget:g} s: give a time in (0, 60] s")
    session = _whole_session(args) if _wants_whole(args) else _chain_session(args)
    server = teach.TeachServer(session, args.port)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # so that the finally below frees the port
    print(f"kinelab teach is serving {session.robot.name} on {server.url} (Ctrl-C to stop)", flush=True)
    print(f"  start: {session.start}", flush=True)
    if args.open:
        webbrowser.open(server.url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:  # Ctrl-C is how a server is stopped: its normal end
        interrupt_taken()
        return 0
    finally:
        server.close()
    return 0


def _wants_whole(args: argparse.Namespace) -> bool:
    """A whole robot's page: --hands or --feet given, or a registered whole robot named without a chain's flags."""
    if args.hands is not None or args.feet is not None:
        return True

    entry = catalog.ENTRIES.get(args.robot)
    return bool(entry is not None and entry.whole and not (args.tool or args.base or args.group or args.lock))


def _chain_session(args: argparse.Namespace) -> Any:
    """A chain's page: its sliders, the target its tool follows, the collision switch."""
    robot = load_robot(args)
    q = q_from_cli(robot, args.q, args.deg) if args.q else None
    spec = collisions_of(args)
    options = teach.TeachOptions(time_budget=args.time_budget or 0.05, collisions=spec)  # None: the switch checks self
    step(f"drawing {robot.name} (its meshes load)")
    session = teach.TeachSession(robot, q, options)
    if spec is not None:
        session.set_collisions(True)
    return session


def _check_whole_arguments(args: argparse.Namespace) -> None:
    """Refuse a chain's options on a whole robot's page.

    Raises:
        KinelabError: Q, --tool, --base, --group or --lock given.
    """
    if args.q:
        raise KinelabError("a whole robot's page starts standing: drop Q (or name a chain with --tool)")
    if args.tool or args.base or args.group or args.lock:
        raise KinelabError("--hands and --feet are a whole robot's: drop --tool, --base, --group and --lock")


def _whole_session(args: argparse.Namespace) -> Any:
    """A whole robot's page: a target per hand, the feet held; with the collision flags, every pair kept apart."""
    _check_whole_arguments(args)
    robot = robot_module.load(args.robot, whole=True, srdf=args.srdf, package_dirs=args.package_dir,
                              xacro_args=pairs(args.xacro_arg, "--xacro-arg"), trust_xacro=args.trust_xacro)
    step(f"drawing {robot.name} (its meshes load)")
    options = teach.TeachOptions(time_budget=args.time_budget or 0.5, collisions=collisions_of(args))
    hands = None if args.hands is None else tuple(args.hands)
    feet = None if args.feet is None else tuple(args.feet)
    return teach.WholeTeachSession(robot, None, options, hands, feet)
