"""``kinelab branches``: every inverse-kinematics branch of one pose, as a table and, with ``--html``, side by side."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import (
    Subcommands,
    json_flag,
    load_robot,
    pose_dict,
    print_json,
    q_from_cli,
    rounded,
    seed_argument,
    source_arguments,
    target_arguments,
    verbose_flag,
)
from kinelab.cli.ik import target_of
from kinelab.errors import KinelabError, OptionError
from kinelab.progress import step

if TYPE_CHECKING:
    import numpy as np

    from kinelab import ik
    from kinelab.ik import limits
    from kinelab.ik.analytic import sew
    from kinelab.ik.result import Branches, IKResult
    from kinelab.robot import Chain
    from kinelab.view import caption
    from kinelab.view import scene as scene_module
else:
    caption = lazy.module("kinelab.view.caption", globals())
    ik = lazy.module("kinelab.ik", globals())
    limits = lazy.module("kinelab.ik.limits", globals())
    np = lazy.module("numpy", globals())
    scene_module = lazy.module("kinelab.view.scene", globals())
    sew = lazy.module("kinelab.ik.analytic.sew", globals())


def add(sub: Subcommands) -> None:
    """The ``branches`` subcommand."""
    s = sub.add_parser("branches", help="every inverse-kinematics branch of a pose: a table, or a page with --html")
    s.add_argument("robot", help="registered name or model file (URDF, xacro, MJCF)")
    target_arguments(s)
    s.add_argument("--ref-q", nargs="+", help="sort the branches nearest this configuration first (or an SRDF name)")
    s.add_argument("--deg", action="store_true", help="angles in degrees (revolute/continuous joints, rpy)")
    s.add_argument("--solver", default="auto", choices=("auto", "analytic", "frdm", "dls"),
                   help="auto (default: the closed form or 1-D search where the arm has one, else the multistart), "
                        "analytic (refused, with the reason, where there is none), frdm or dls (the multistart)")
    s.add_argument("--redundancy", type=int, metavar="K",
                   help="a 7R arm with a joint held (docs/analytic.md): every branch at K values of that joint")
    s.add_argument("--sew", type=float, metavar="PSI",
                   help="a 7R arm: every branch with the elbow at this SEW angle (rad, degrees with --deg; "
                        "docs/analytic.md, The SEW angle)")
    seed_argument(s)
    s.add_argument("--time-budget", type=float, default=None,
                   help="the search's wall-clock budget [s] (default: 0.05 for the multistart, 5 for --redundancy and "
                        "--sew); the closed form needs none")
    s.add_argument("--html", help="also write the branches side by side, labelled, as a self-contained page")
    source_arguments(s)
    json_flag(s, "the branches")
    verbose_flag(s)
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Find, print (or print as JSON), and with --html draw, every branch; exit 0 when there is one, 1 when none."""
    robot = load_robot(args)
    target = target_of(robot, args)
    ref = None if args.ref_q is None else q_from_cli(robot, args.ref_q, args.deg, "--ref-q")
    budget = "auto" if args.time_budget is None else args.time_budget
    found = ik.solve_all(robot, target, solver=args.solver, seed=args.seed, time_budget=budget, q_ref=ref,
                         redundancy=_redundancy(args))
    if args.json:
        print_json({"robot": robot.name, "target": pose_dict(target), "method": _method(found),
                    "completeness": _completeness(found), "complete": found.complete,
                    "complete_reason": found.complete_reason, "branches": [r.to_dict() for r in found]})
    else:
        _print_branches(robot, args, found, ref)
    if args.html:
        _write_page(robot, found, args.html, target, ref, args.deg)
    return 0 if found else 1


def _redundancy(args: argparse.Namespace) -> int | sew.SEW | None:
    """--redundancy K or --sew PSI (one of them) as solve_all's ``redundancy``.

    Raises:
        OptionError: both given.
    """
    if args.sew is None:
        return args.redundancy
    if args.redundancy is not None:
        raise OptionError("--sew", args.sew, "either --sew PSI or --redundancy K, not both")
    return sew.SEW(math.radians(args.sew) if args.deg else args.sew)


def _method(found: Sequence[IKResult]) -> str:
    return found[0].mode if found else "none found"


COMPLETENESS = {
    "closed form": "every branch: closed form",
    "sweep": "every branch at each value of the swept joint: closed form",
    "search": "every branch the search finds, each root refined to rounding (measured: docs/analytic.md, Completeness)",
    "elimination": "every branch: general 6R algebraic elimination",
}


def _completeness(found: Branches) -> str:
    """How sure the list is to hold every branch, in words (none: why, as the result's status says it): the method,
    and ``complete`` with its reason."""
    if not found:
        return f"no branch ({found.status.value}): {found.message}"
    if found.method == "multistart":
        return (f"multistart (complete: estimate): chance that one more start finds a new branch estimated at "
                f"{found[0].diagnostics.unseen:.2g}")
    how = found.complete + (f" — {found.complete_reason}" if found.complete_reason else "")
    return f"{COMPLETENESS.get(found.method, found.method)} (complete: {how})"


PLAIN = {  # how sure the list is to hold every branch, in plain words, by method
    "closed form": "every branch, from a formula; each one proved",
    "sweep": "every branch at each value of the swept joint, from a formula",
    "search": "every branch a one-dimensional search finds (checked complete on thousands of poses, not proved)",
    "elimination": "every branch, from the general six-joint elimination; each one proved",
}


def _completeness_words(found: Branches) -> str:
    """:func:`_completeness` in plain words (``--verbose`` prints the solver's own)."""
    if not found:
        return f"no branch ({found.status.value}): {found.message}"
    unseen = found[0].diagnostics.unseen
    if found.method == "multistart" and unseen is not None:
        return (f"found from many random starts; one more start would find yet another branch with a chance of "
                f"about {100 * unseen:.2g} %")
    return PLAIN.get(found.method, found.method)


def _shown_q(robot: Chain, q: np.ndarray, deg: bool) -> np.ndarray:
    """q as shown: radians and metres, or with ``deg`` the revolute joints in degrees."""
    return np.where([j != "prismatic" for j in robot.joint_kinds], np.rad2deg(q), q) if deg else q


def _print_notes(robot: Chain, found: Branches, ref: Any) -> None:
    """What to know before reading the list: a redundant arm's answers sample a continuum; the order with ref."""
    if found.method == "multistart" and robot.n > 6:
        print(f"  {robot.name} has {robot.n} joints for a 6-number pose: its configurations form a continuum, of "
              "which these are samples; --redundancy K or --sew PSI lists every branch at chosen values")
    if ref is not None:
        print("  nearest --ref-q first (revolute joints compared modulo 2π)")


def _print_branches(robot: Chain, args: argparse.Namespace, found: Branches, ref: Any) -> None:
    """One line per branch: its configuration and Pinocchio's errors (nearest ``ref`` first when given)."""
    unit = " [deg, m]" if args.deg else " [rad, m]"
    print(f"{robot.name}: {len(found)} branch{'es' if len(found) != 1 else ''}, {_method(found)}")
    print(f"  {_completeness(found) if args.verbose else _completeness_words(found)}")
    _print_notes(robot, found, ref)
    for k, r in enumerate(found):
        q = _shown_q(robot, r.q, args.deg)
        print(f"  {k + 1:>2}  q{unit} {' '.join(f'{v:9.4f}' for v in q)}   errors {r.position_error:.1e} m, "
              f"{r.rotation_error:.1e} rad"
              + (f"  ({r.message})" if r.message else ""))
    if found:
        print(f"  {found[0].wall_time * 1e3:.2f} ms for all of them (solve_all; the first call in a process also "
              "loads the solver)")


def _write_page(robot: Chain, found: Sequence[IKResult], path: str, target: Any, ref: Any, deg: bool) -> None:
    """The branches side by side, numbered in the scene as in the table of their joints under the caption (the
    target's point marked at each; with ``ref``, the nearest first, orange, its distance in the table)."""
    if not found:
        raise KinelabError("no branch to draw: the pose has none within the joint limits")
    labels = [f"branch {k + 1}" + (" (nearest --ref-q)" if ref is not None and k == 0 else "")
              for k in range(len(found))]
    step(f"drawing {len(found)} branches side by side and writing {path}")
    scene = scene_module.side_by_side(robot, [r.q for r in found], labels=labels, highlight=None if ref is None else 0,
                                      target=target)
    scene.title = f"{robot.name}: {len(found)} branch{'es' if len(found) != 1 else ''} of one pose, {_method(found)}"
    scene.view = "branches"
    scene.put_table(_joint_table(robot, found, ref, deg))
    scene.legend.pop("copies")  # the table numbers the branches as the scene does
    try:
        scene.save_html(path)
    finally:
        scene.close()
    print(f"wrote {path}")


def _gap(robot: Chain, q: np.ndarray, ref: Any, deg: bool) -> tuple[str, ...]:
    """The distance from q to ``ref`` as the table shows it (rad, or deg with ``deg``), or nothing without ref."""
    if ref is None:
        return ()
    d = limits.distance(robot, q, ref)
    return tuple(f"{v:.4f}" for v in rounded([np.rad2deg(d) if deg else d], 4))


def _joint_table(robot: Chain, found: Sequence[IKResult], ref: Any, deg: bool) -> Any:
    """Every branch's joints (rad and m; degrees and m with ``deg``), and with ``ref`` each one's distance to it
    (the largest joint difference, revolute joints modulo 2π), the nearest marked."""
    unit = "deg" if deg else "rad"
    header = ("#", *(f"q{i + 1} [{unit if k != 'prismatic' else 'm'}]" for i, k in enumerate(robot.joint_kinds)),
              *((f"to --ref-q [{unit}]",) if ref is not None else ()))
    rows = [(str(k + 1), *(f"{v:.4f}" for v in rounded(_shown_q(robot, r.q, deg), 4)), *_gap(robot, r.q, ref, deg))
            for k, r in enumerate(found)]
    names = ", ".join(f"q{i + 1} {j.name}" for i, j in enumerate(robot.joints))
    return caption.Table(header, tuple(rows), None if ref is None else 0, note=f"joints: {names}")
