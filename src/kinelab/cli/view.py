"""``kinelab view`` (a robot in meshcat) and ``kinelab animate`` (the ERA passages of seed paper 000)."""

from __future__ import annotations

import argparse
import math
import sys
import time
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import (
    Subcommands,
    collision_arguments,
    collisions_of,
    is_number,
    load_robot,
    pairs,
    plural,
    q_from_cli,
    robot_arguments,
)
from kinelab.errors import KinelabError
from kinelab.files import interrupt_taken
from kinelab.progress import step
from kinelab.robot import catalog

if TYPE_CHECKING:
    import signal

    from kinelab import collision
    from kinelab import robot as robot_module
    from kinelab.studies import paper000_era
    from kinelab.view import collisions, whole_scene
    from kinelab.view import scene as viz
else:
    whole_scene = lazy.module("kinelab.view.whole_scene", globals())
    collision = lazy.module("kinelab.collision", globals())
    collisions = lazy.module("kinelab.view.collisions", globals())
    paper000_era = lazy.module("kinelab.studies.paper000_era", globals())
    robot_module = lazy.module("kinelab.robot", globals())
    signal = lazy.module("signal", globals())
    viz = lazy.module("kinelab.view.scene", globals())

MIN_DT, MAX_DT = 1e-3, 60.0  # [s] per animation sample


def add(sub: Subcommands) -> None:
    """The ``view`` and ``animate`` subcommands."""
    s = sub.add_parser("view", help="show a robot in meshcat (live on 127.0.0.1, or --html for a static page)")
    robot_arguments(s, "configuration (default: the robot's display pose)")
    s.add_argument("--singular", action="store_true", help="draw the lost directions and σ_min at q")
    collision_arguments(s)
    s.add_argument("--whole", action="store_true",
                   help="the whole robot (a registered whole robot, such as talos or delta, is whole without it): "
                        "standing on the floor, its loops closed; Q its Pinocchio q or an SRDF configuration's name")
    s.add_argument("--html", help="write a self-contained HTML page instead of serving")
    s.set_defaults(func=run_view)
    s = sub.add_parser("animate", help="animate a solver run in meshcat (the ERA passages)")
    s.add_argument("passage", help="era-elbow, era-wrist or era-shoulder (seed paper 000)")
    s.add_argument("--without-bypass", action="store_true", help="the run without the paper's bypass")
    s.add_argument("--dt", type=float, default=0.1, help="seconds per path sample in the animation (default 0.1)")
    s.add_argument("--html", help="write a self-contained HTML page instead of serving")
    s.set_defaults(func=run_animate)


def run_view(args: argparse.Namespace) -> int:
    """Draw the robot at q (any finite q; joints outside their limits are noted); a whole robot standing."""
    if _wants_whole(args):
        return _publish(_whole_scene(args), args.html)
    robot = load_robot(args)
    q = robot.check_q(q_from_cli(robot, args.q, args.deg) if args.q else robot.display_q())
    if not args.ignore_limits:
        for note in robot.outside_limits(q):  # drawn all the same: a view is defined at any q
            print(f"kinelab: note: {note}", file=sys.stderr)
    step(f"drawing {robot.name} (its meshes load)")
    scene = viz.Scene(robot).show(q)
    if args.singular:
        scene.singular_directions(q)
    spec = collisions_of(args)
    if spec is not None:
        contacts = collisions.draw_collisions(scene, collision.collision_model(robot, spec), q)
        print(f"{len(contacts)} contact(s)" + "".join(f"\n  {c}" for c in contacts))
    return _publish(scene, args.html)


def _wants_whole(args: argparse.Namespace) -> bool:
    """The whole robot: --whole, or a registered whole robot named without a chain's flags."""
    if args.whole:
        return True
    entry = catalog.ENTRIES.get(args.robot)
    return bool(entry is not None and entry.whole and not (args.tool or args.base or args.group or args.lock))


def _whole_scene(args: argparse.Namespace) -> Any:
    """The whole robot's scene (standing, or at Q: its Pinocchio q or an SRDF configuration's name).

    Raises:
        KinelabError: a chain's flag given with it (named).
    """
    given = [flag for flag, on in (("--singular", args.singular), ("--collisions", args.collisions),
                                   ("--obstacles", args.obstacles is not None), ("--tool", args.tool),
                                   ("--base", args.base), ("--group", args.group), ("--lock", args.lock)) if on]
    if given:
        raise KinelabError(f"{given[0]} is a chain's: a whole robot's view draws it standing (name a chain with "
                           "--tool for the others)")
    robot = robot_module.load(args.robot, whole=True, srdf=args.srdf, package_dirs=args.package_dir,
                              xacro_args=pairs(args.xacro_arg, "--xacro-arg"), trust_xacro=args.trust_xacro)
    q = None
    if args.q:
        q = robot.named_q(args.q[0]) if len(args.q) == 1 and not is_number(args.q[0]) else \
            robot.check_q([float(v) for v in _numbers(args.q)])
    step(f"drawing {robot.name} (its meshes load)")
    return whole_scene.WholeScene(robot, q)


def _numbers(values: list[str]) -> list[str]:
    """The Q words, refused by name where one is not a number.

    Raises:
        KinelabError: a word that is not a number.
    """
    bad = [v for v in values if not is_number(v)]
    if bad:
        raise KinelabError(f"Q: {bad[0]!r} is not a number (a whole robot's Q is its Pinocchio q, or one SRDF name)")
    return values


def run_animate(args: argparse.Namespace) -> int:
    """Animate one ERA passage with or without the paper's bypass."""
    passages = {f"era-{name}": build for name, build in paper000_era.PASSAGES.items()}
    if args.passage not in passages:
        raise KinelabError(f"unknown passage {args.passage!r}; passages are: {', '.join(passages)}")
    if not (math.isfinite(args.dt) and MIN_DT <= args.dt <= MAX_DT):
        raise KinelabError(f"--dt {args.dt} is not valid: seconds per sample, between {MIN_DT:g} and {MAX_DT:g}")
    robot = robot_module.load("era")
    passage = passages[args.passage](robot)
    step(f"solving {args.passage} with and without the paper's bypass")
    run = paper000_era.run(passage, robot)
    result = run.without if args.without_bypass else run.with_bypass
    step(f"drawing {len(result.q)} configurations of era")
    scene = viz.Scene(robot, name=f"era ({'without' if args.without_bypass else 'with'} bypass)")
    scene.animate(result.q, dt=args.dt)
    one_lap = passage.targets[: (passage.lap or passage.samples) + 1]
    for k, target in enumerate(one_lap[:: max(1, len(one_lap) // 8)]):
        scene.frame(f"target{k}", target, 0.5 * scene.frame_length)
    _print_passage(f"{args.passage} {'without' if args.without_bypass else 'with'} bypass", result.summary())
    return _publish(scene, args.html)


def _print_passage(title: str, summary: dict[str, Any]) -> None:
    """One line on a tracked passage: samples reached, jumps, the largest joint step [rad], monitor events."""
    jumps = summary["status"].get("jump", 0)
    print(f"{title}: {summary['reached']} of {summary['samples']} samples reached"
          f"{f' ({jumps} met by a jump)' if jumps else ''}, largest joint step {summary['max_joint_step']:.3f} rad, "
          f"{plural(summary['monitor_events'], 'monitor event')}")


def _publish(scene: Any, html: str | None) -> int:
    """Write the scene as a static page (its caption in the page), or serve it live until interrupted (the
    caption printed under the address: the live page has none)."""
    if html:
        step(f"writing {html}")
        scene.save_html(html)
        scene.close()
        print(f"wrote {html}")
        _print_caption(scene)
        return 0
    return _serve(scene)


def _print_caption(scene: Any) -> None:
    print(scene.title)
    for line in scene.legend.values():
        print(f"  {line}")


def _serve(scene: Any) -> int:
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # so that the finally below stops the server
    print(f"meshcat is serving on {scene.url} (Ctrl-C to stop)", flush=True)
    _print_caption(scene)
    sys.stdout.flush()
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:  # Ctrl-C is how a server is stopped: its normal end
        interrupt_taken()
        return 0
    finally:
        scene.close()
