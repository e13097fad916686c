"""``kinelab teach``: a robot to move by hand in the browser (sliders, a draggable target, live readings)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from kinelab.cli.common import collision_arguments, collisions_of, load_robot, q_from_cli, robot_arguments
from kinelab.errors import KinelabError
from kinelab.progress import step


def add(sub: Any) -> None:
    """The ``teach`` subcommand."""
    s = sub.add_parser("teach", help="move a robot by hand in the browser: joint sliders, a target to drag that it "
                                     "follows by IK, its branches, σ_min and the velocity ellipsoid (127.0.0.1)")
    robot_arguments(s, "start configuration within the limits (default: the robot's reference configuration)",
                    limits=False)
    collision_arguments(s)
    s.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default 0: a free one)")
    s.add_argument("--time-budget", type=float, default=0.05,
                   help="seconds one follow of the target may take (default 0.05)")
    s.add_argument("--open", action="store_true", help="open the page in the default browser")
    s.set_defaults(func=run_teach)


def run_teach(args: argparse.Namespace) -> int:
    """Serve the teach page until Ctrl-C (or SIGTERM)."""
    import signal

    from kinelab.view.teach import TeachOptions, TeachServer, TeachSession

    if not 0 <= args.port <= 65535:
        raise KinelabError(f"--port {args.port} is not a port: give 1–65535, or 0 for a free one")
    if not 0 < args.time_budget <= 60:
        raise KinelabError(f"--time-budget {args.time_budget:g} s: give a time in (0, 60] s")
    robot = load_robot(args)
    q = q_from_cli(robot, args.q, args.deg) if args.q else None
    spec = collisions_of(args)
    options = TeachOptions(time_budget=args.time_budget, collisions=spec)  # None: the switch checks self-collisions
    step(f"drawing {robot.name} (its meshes load)")
    session = TeachSession(robot, q, options)
    if spec is not None:
        session.set_collisions(True)
    server = TeachServer(session, args.port)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # so that the finally below frees the port
    print(f"kinelab teach is serving {robot.name} on {server.url} (Ctrl-C to stop)", flush=True)
    print(f"  start: {session.start}", flush=True)
    if args.open:
        import webbrowser

        webbrowser.open(server.url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        return 0
    finally:
        server.close()
    return 0
