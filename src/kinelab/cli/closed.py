"""``kinelab singular`` on a robot that closes loops (``kinelab singular fourbar 0.6``, ``--sweep N``): the motors'
values in, the configuration assembled, type I and type II singularities by SVD
(:mod:`kinelab.analysis.closed_singular`)."""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli import common
from kinelab.errors import AssemblyError, KinelabError

if TYPE_CHECKING:
    import numpy as np

    from kinelab.analysis import closed_singular
    from kinelab.robot import catalog
    from kinelab.robot.tree import Robot
else:
    np = lazy.module("numpy", globals())  # the parsers load no numpy (kinelab --help's start-up)
    closed_singular = lazy.module("kinelab.analysis.closed_singular", globals())
    catalog = lazy.module("kinelab.robot.catalog", globals())

NEAR = 1e-3  # [m/rad or 1] a σ a sweep counts as near-singular below


def closed_robot(args: argparse.Namespace) -> Robot | None:
    """The whole robot when the command names one that closes loops (a registered one, or ``--closures FILE``),
    else None (the chain's analysis)."""
    from kinelab.robot.loading import load

    if args.closures:
        return load(args.robot, closures=args.closures)
    entry = catalog.ENTRIES.get(args.robot) if isinstance(args.robot, str) else None
    if entry is not None and entry.closures:
        return load(args.robot)
    return None


def run(robot: Robot, args: argparse.Namespace) -> int:
    """The two measures at the motors' values, or a sweep's smallest and near-singular counts."""
    output = args.output or (robot.hands[0] if robot.hands else robot.model.frames[-1].name)
    robot.frame_id(output)  # an unknown frame named
    if args.sweep is not None:
        return _sweep(robot, output, args)
    if len(args.q) != len(robot.actuated):
        raise KinelabError(f"{robot.name} takes one value per motor, {len(robot.actuated)} in all "
                           f"({', '.join(robot.actuated)}); got {len(args.q)}")
    bad = [v for v in args.q if not common.is_number(v)]
    if bad:
        raise KinelabError(f"{bad[0]!r} is not a number (give {len(robot.actuated)} motor values, rad or deg)")
    motors = np.array([float(v) for v in args.q]) * (math.pi / 180 if args.deg else 1.0)
    q = _assembled(robot, robot.standing(), motors)
    s = closed_singular.analyze(robot, q, output)
    if args.json:
        common.print_json({"robot": robot.name, "output": output, "q": q.tolist(), "sigma_serial": s.sigma_serial,
                           "sigma_parallel": s.sigma_parallel, "kind": s.kind})
        return 0
    print(f"{robot.name}: {s.kind} (output {output}); σ_I = {s.sigma_serial:.4g} (the motors' map to the output's "
          f"position, m/rad), σ_II = {s.sigma_parallel:.4g} (the loops' passive joints); singular at or below "
          f"{closed_singular.SINGULAR:g}")
    print(f"  assembled q = {common.shown(q, precision=6)}")
    return 0


def _assembled(robot: Robot, home: np.ndarray, motors: np.ndarray) -> np.ndarray:
    """The home pose (assembled) with the motors at ``motors``, assembled."""
    q = home.copy()
    for name, value in zip(robot.actuated, motors, strict=True):
        q[robot.model.joints[robot.model.getJointId(name)].idx_q] = value
    return robot.assemble(q)


def _sweep(robot: Robot, output: str, args: argparse.Namespace) -> int:
    """N random motor configurations within the limits, each assembled (from the home pose) and measured."""
    if not (isinstance(args.sweep, int) and args.sweep >= 1):
        raise KinelabError(f"--sweep takes a number of samples ≥ 1, got {args.sweep}")
    rng = np.random.default_rng(args.seed)
    from kinelab.robot.assembly import actuated_indices

    index = actuated_indices(robot)[0]
    home = robot.standing()  # once: every sample starts from it
    rows: list[tuple[float, float, np.ndarray]] = []
    refused = 0
    for _ in range(args.sweep):
        try:
            q = _assembled(robot, home, robot.random_q(rng)[index])
        except AssemblyError:
            refused += 1
            continue
        s = closed_singular.analyze(robot, q, output)
        rows.append((s.sigma_serial, s.sigma_parallel, q[index]))
    return _report(robot, output, args, rows, refused)


def _report(robot: Robot, output: str, args: argparse.Namespace, rows: list[tuple[float, float, Any]],
            refused: int) -> int:
    """The sweep's counts and smallest σ of each type, with the motors where it was found."""
    out: dict[str, Any] = {"robot": robot.name, "output": output, "samples": args.sweep, "no_assembly": refused}
    for key, col in (("serial", 0), ("parallel", 1)):
        best = min(rows, key=lambda r: r[col]) if rows else None
        out[f"near_{key}"] = sum(r[col] < NEAR for r in rows)
        out[f"smallest_{key}"] = None if best is None else {"sigma": best[col], "motors": best[2].tolist()}
    if args.json:
        common.print_json(out)
        return 0
    print(f"{robot.name}: {args.sweep} motor configurations, {refused} with no assembly; output {output}")
    for key, label in (("serial", "type I (σ_I)"), ("parallel", "type II (σ_II)")):
        best = out[f"smallest_{key}"]
        where = "" if best is None else (f"; smallest {best['sigma']:.3g} at motors "
                                         f"{common.shown(np.array(best['motors']), precision=4)}")
        print(f"  {label}: {out[f'near_{key}']} below {NEAR:g}{where}")
    return 0
