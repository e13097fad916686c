"""``kinelab singular``: rank, singular values and lost directions at q, or a sweep for singular families."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli import closed, common
from kinelab.cli.common import Subcommands
from kinelab.errors import KinelabError

if TYPE_CHECKING:
    from kinelab.analysis import families, singular
else:
    families = lazy.module("kinelab.analysis.families", globals())
    singular = lazy.module("kinelab.analysis.singular", globals())


def reading(value: float, digits: int = 4) -> str:
    """A number rounded for reading (no "-0.0000": a rounded zero has no sign)."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def add(sub: Subcommands) -> None:
    """The ``singular`` subcommand."""
    s = sub.add_parser("singular", help="rank, singular values, lost directions; or a sweep for singular families")
    common.robot_arguments(s, "one number per joint (rad and m; deg with --deg)")
    s.add_argument("--sweep", type=int, help="sample N configurations within the limits and report families")
    s.add_argument("--grid", action="store_true", help="sweep a stratified grid instead of uniform samples")
    s.add_argument("--force", action="store_true", help="run a sweep even when its memory estimate is over the limit")
    s.add_argument("--closures", metavar="FILE", help="a closures declaration (YAML): the robot closes loops, Q gives "
                                                        "its motors (registered robots with loops take theirs)")
    s.add_argument("--output", metavar="FRAME", help="a robot with loops: the frame whose position is the output "
                                                     "(default: its first hand)")
    common.seed_argument(s)
    common.json_flag(s)
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """The analysis at one q, or the sweep's families (a robot with loops: its two types, :mod:`kinelab.cli.closed`)."""
    looped = closed.closed_robot(args)
    if looped is not None:
        return closed.run(looped, args)
    robot = common.load_robot(args)
    if args.sweep is not None:
        if args.q:
            raise KinelabError("give either a configuration or --sweep N, not both")
        return _sweep(robot, args)
    if not args.q:
        raise KinelabError("give a configuration Q1 ... Qn or --sweep N")
    q = common.q_from_cli(robot, args.q, args.deg)
    a = singular.analyze(robot, robot.check_q(q, limits=not args.ignore_limits))
    if args.json:
        common.print_json({"robot": robot.name, **a.to_dict()})
        return 0
    print(f"{robot.name}: rank {a.rank} of {a.full_rank}{' (SINGULAR)' if a.singular else ''}; "
          f"σ = {common.shown(a.singular_values, precision=4)} (linear rows / L = {a.length:.4g} m)")
    print(f"  σ_min/σ_max {a.sigma_ratio:.3g}: {singular.sigma_words(a.sigma_ratio)} (near-singular below "
          f"{singular.NEAR_SINGULAR:g}); manipulability {a.manipulability:.4g}, condition {a.condition:.4g}")
    for d in a.lost_directions:
        parts = []
        if d.translation_axis is not None:
            parts.append(f"translation {common.rounded(d.translation_axis, 3)} ({100 * d.translation_share:.0f} %)")
        if d.rotation_axis is not None:
            parts.append(f"rotation about {common.rounded(d.rotation_axis, 3)} ({100 * d.rotation_share:.0f} %)")
        print(f"  lost tool motion (base axes, at the tool): {' + '.join(parts)}")
    for m in a.null_motions:
        print(f"  joint motion that moves nothing: {common.rounded(m, 4)}")
    return 0


def _sweep(robot: Any, args: argparse.Namespace) -> int:
    families.check_sweep_size(robot, args.sweep, force=args.force)
    result = families.sweep(robot, samples=args.sweep, seed=args.seed, progress=common.progress_of(args),
                            method="grid" if args.grid else "random")
    out = {"robot": robot.name, **result.to_dict()}
    if args.json:
        common.print_json(out)
        return 0
    for note in result.notes:
        print(f"note: {note}")
    asked = f" (a grid of {args.sweep} asked for)" if result.samples != args.sweep else ""
    print(f"{robot.name}: {common.plural(result.samples, 'sample')}{asked}, {out['near_singular']} near-singular "
          f"(σ_min/σ_max < {singular.NEAR_SINGULAR:g}), {out['refined']} refined, {out['singular']} singular "
          "after refinement (relations of angles hold modulo 2π; q to 8 decimals, still singular when pasted back; "
          "--json has every digit)")
    for f in result.families:
        print(f"  rank {f.rank}, {f.count:4d} found: {f.text}")
        print(f"      e.g. q = {' '.join(reading(v, 8) for v in f.representative)}")
    return 0
