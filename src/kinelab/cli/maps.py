"""``kinelab map reach|base|singular``: reachability, base placement and singularity maps (kinelab.maps)."""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli import common
from kinelab.cli.common import (
    Interrupted,
    Parser,
    Subcommands,
    load_robot,
    plural,
    print_json,
    progress_of,
    seed_argument,
    source_arguments,
)
from kinelab.errors import KinelabError
from kinelab.files import write_output
from kinelab.progress import step
from kinelab.robot.catalog import names

if TYPE_CHECKING:
    import numpy as np

    from kinelab import ik, maps
    from kinelab import robot as robot_module
    from kinelab.analysis import singular
    from kinelab.maps import base, cluster, store
    from kinelab.view import maps as maps_module
else:
    base = lazy.module("kinelab.maps.base", globals())
    cluster = lazy.module("kinelab.maps.cluster", globals())
    ik = lazy.module("kinelab.ik", globals())
    maps = lazy.module("kinelab.maps", globals())
    maps_module = lazy.module("kinelab.view.maps", globals())
    np = lazy.module("numpy", globals())
    robot_module = lazy.module("kinelab.robot", globals())
    singular = lazy.module("kinelab.analysis.singular", globals())
    store = lazy.module("kinelab.maps.store", globals())


def add(sub: Subcommands) -> None:
    """The ``map`` subcommand and its three kinds."""
    s = sub.add_parser("map", help="reachability, base placement and singularity maps (kinelab.maps)")
    kinds = s.add_subparsers(dest="kind", required=True, metavar="KIND", parser_class=Parser)
    _add_reach(kinds)
    _add_base(kinds)
    g = kinds.add_parser("singular", help="σ_min/σ_max over joint-space samples (the engine of singular --sweep)")
    g.add_argument("robot", help="a registered name or a model file (see kinelab robots)")
    g.add_argument("--samples", type=int, default=5000, help="configurations to sample (default 5000)")
    g.add_argument("--grid", action="store_true", help="a stratified grid instead of uniform samples")
    seed_argument(g)
    source_arguments(g)
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.set_defaults(func=run_singular)


def _add_reach(kinds: Any) -> None:
    r = kinds.add_parser("reach", help="the share of orientations the arm reaches in each voxel of its workspace")
    r.add_argument("robot", help="a registered name or a model file (see kinelab robots)")
    r.add_argument("--voxel", type=float, default=0.1, help="voxel side [m] (default 0.1)")
    r.add_argument("--orientations", type=int, default=16, help="target orientations per voxel (default 16)")
    r.add_argument("--task", choices=("pose", "axis"), default="pose",
                   help="pose (default), or axis: the tool z axis along spread directions, the roll free")
    r.add_argument("--restarts", type=int, default=20, help="random restarts per target (default 20)")
    seed_argument(r)
    r.add_argument("--method", choices=("auto", "numeric"), default="auto",
                   help="auto: every branch in closed form where the arm has one (task pose), else the numeric batch; "
                        "numeric: the numeric batch everywhere (default auto)")
    common.collision_arguments(r)
    r.add_argument("--chunk", type=int, default=64, help="voxels per chunk, the unit of work and storage (default 64)")
    r.add_argument("--out", help="a Zarr directory: written chunk by chunk, resumed if it holds this map unfinished")
    r.add_argument("--force", action="store_true", help="run a map of more than 2 million targets")
    r.add_argument("--scheduler", metavar="ADDRESS", help="run the chunks on this Dask scheduler (kinelab[cluster])")
    r.add_argument("--workers", type=int, help="run the chunks on a local Dask cluster of this many processes")
    source_arguments(r)
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.set_defaults(func=run_reach)


def _add_base(kinds: Any) -> None:
    v = kinds.add_parser("view", help="a stored reachability map as a page: its voxels in 3-D and three slices")
    v.add_argument("store", help="the map's folder (written by `kinelab map reach --out`)")
    v.add_argument("--html", required=True, help="the page to write")
    v.add_argument("--robot", help="the robot, by name or file, when the map's own name does not load it")
    v.set_defaults(func=run_view)
    b = kinds.add_parser("base", help="platform positions (and headings) from which a mobile manipulator reaches "
                                      "a grasp")
    b.add_argument("robot", help="a mobile manipulator with joints platform_x, platform_y, platform_yaw (youbot)")
    b.add_argument("--grasp", nargs=6, type=float, required=True, metavar=("X", "Y", "Z", "R", "P", "YAW"),
                   help="the grasp pose: position [m] and roll, pitch, yaw [rad] in the world frame")
    b.add_argument("--step", type=float, default=0.05, help="x-y grid spacing [m] (default 0.05)")
    b.add_argument("--top", type=int, default=5, help="how many of the best poses to print (default 5)")
    seed_argument(b)
    source_arguments(b)
    b.add_argument("--json", action="store_true", help="print the reachable poses as JSON")
    b.set_defaults(func=run_base)


def run_base(args: argparse.Namespace) -> int:
    """The platform positions that reach the grasp, best manipulability first."""
    base.check_count(args.top)  # before the map's work
    robot = load_robot(args)
    grasp = ik.target_from_xyz_rpy(args.grasp[:3], args.grasp[3:])
    result = maps.base_map(robot, grasp, step=args.step, seed=args.seed)
    best = result.ranked(args.top)
    rows = [{"x": float(result.poses[i, 0]), "y": float(result.poses[i, 1]), "yaw": float(result.poses[i, 2]),
             "manipulability": float(result.manipulability[i]), "arm_q": result.q[i].tolist()} for i in best]
    reached = int(result.reachable.sum())
    if args.json:
        print_json({"robot": robot.name, "candidates": len(result.poses), "reachable": reached, "best": rows})
        return 0
    if not rows:
        print(f"{robot.name}: the grasp is reached from none of {plural(len(result.poses), 'platform position')} "
              f"({args.step:g} m grid around it)")
        return 0
    print(f"{robot.name}: the grasp is reached from {reached} of "
          f"{plural(len(result.poses), 'platform position')} ({args.step:g} m grid); the best:")
    for r in rows:
        print(f"  x {r['x']:+.3f} m  y {r['y']:+.3f} m  yaw {r['yaw']:+.4f} rad  "
              f"manipulability {r['manipulability']:.3g}")
    return 0


def run_singular(args: argparse.Namespace) -> int:
    """σ_min/σ_max over samples: how many near-singular, how many rank-deficient; for a robot that closes loops,
    its type I and type II singularities over random motor configurations (``kinelab singular ROBOT --sweep N``).

    Raises:
        KinelabError: ``--grid`` for a robot with loops (its motors are drawn at random, each draw assembled).
    """
    from kinelab.cli import closed

    whole = closed.closed_robot(argparse.Namespace(robot=args.robot, closures=None))
    if whole is not None:
        if args.grid:
            raise KinelabError(f"{whole.name} closes loops: its map draws random motor configurations and assembles "
                               "each; --grid is for chains (leave it out)")
        return closed.run(whole, argparse.Namespace(sweep=args.samples, output=None, seed=args.seed, json=args.json,
                                                    q=[], deg=False))
    robot = load_robot(args)
    result = maps.singularity(robot, samples=args.samples, seed=args.seed, method="grid" if args.grid else "random",
                              progress=progress_of(args))
    ratio = result.sigma_ratio
    summary = {"robot": robot.name, "samples": int(len(ratio)), "rank_deficient": int(result.rank_deficient.sum()),
               "near_singular": int((ratio < singular.NEAR_SINGULAR).sum()),
               "median_sigma_ratio": float(np.median(ratio))}
    if args.json:
        print_json(summary)
    else:
        print(f"{robot.name}: {plural(len(ratio), 'sample')}; {summary['near_singular']} near-singular "
              f"(σ_min/σ_max < {singular.NEAR_SINGULAR:g}), {summary['rank_deficient']} rank-deficient; "
              f"median σ_min/σ_max {summary['median_sigma_ratio']:.3g}")
    return 0


def _kept(args: argparse.Namespace) -> str:
    """What an interrupted map kept, and the command that resumes it."""
    if not args.out:
        return "nothing was kept (no --out): give --out DIR to keep the chunks and resume"

    try:
        done = store.load(args.out, check=False).done[:]
    except KinelabError:
        return f"no chunk was written to {args.out} yet"
    return (f"{int(sum(done))} of {len(done)} chunks are saved in {args.out}; the same command resumes: "
            f"kinelab {shlex.join(args.command_line)}")


def _say_resumed(args: argparse.Namespace) -> None:
    """One line on stderr when --out holds chunks of an unfinished map (a run that resumes it)."""
    if not args.out:
        return

    try:
        done = int(sum(store.load(args.out, check=False).done[:]))
    except KinelabError:
        return
    if done:
        print(f"kinelab: map (resumed: {done} chunks already in {args.out})", file=sys.stderr, flush=True)


def _client(args: argparse.Namespace) -> Any:
    """The Dask client --scheduler or --workers asks for, or None (the map runs here, in this process).

    Raises:
        KinelabError: both given, or a number of workers outside 1 to the cores here.
    """
    if args.scheduler and args.workers:
        raise KinelabError("give --scheduler ADDRESS or --workers N, not both")
    if args.workers is not None and not 1 <= args.workers <= cluster.cores():
        raise KinelabError(f"--workers must be 1 to {cluster.cores()} (the cores here), got {args.workers}")
    if args.scheduler is not None or args.workers:
        return cluster.client_for(args.scheduler, args.workers)
    return None


def _reach_figures(result: Any, orientations: int) -> dict[str, Any]:
    """The map's voxels, targets, voxels reached, mean reachability and mean branches per reached pose (None where
    the solver counts none or nothing is reached)."""
    reach, branches = result.array("reachability"), result.array("branches")
    reached = reach > 0
    return {"voxels": int(len(reach)), "targets": int(len(reach) * orientations), "reached_voxels": int(reached.sum()),
            "mean_reachability": float(np.nanmean(reach)),
            "mean_branches": None if np.isnan(branches).all() or not reached.any()
            else float(np.mean(branches[reached]))}


def run_reach(args: argparse.Namespace) -> int:
    """Build (or resume) the reachability map and print its summary."""
    robot = load_robot(args)
    spec = maps.MapSpec(voxel=args.voxel, orientations=args.orientations, task=args.task, restarts=args.restarts,
                        seed=args.seed, chunk_voxels=args.chunk, method=args.method,
                        collisions=common.collisions_of(args))
    client = _client(args)
    t0 = time.perf_counter()
    shown = progress_of(args)
    if not shown:  # the bar says it where someone watches; a log file gets the one line
        _say_resumed(args)
    try:
        result = maps.reachability(robot, spec, out=args.out, force=args.force, progress=shown, client=client)
    except KeyboardInterrupt:
        raise Interrupted(_kept(args)) from None
    finally:
        if client is not None:
            client.close()
    summary = {"robot": robot.name, **_reach_figures(result, spec.orientations), "solver": result.meta["solver"],
               "seconds": time.perf_counter() - t0, "out": args.out}
    if args.json:
        print_json(summary)
    else:
        print(f"{robot.name}: {plural(summary['voxels'], 'voxel')} of {args.voxel:g} m × {spec.orientations} "
              f"orientations; {summary['reached_voxels']} voxels reached, mean reachability "
              f"{summary['mean_reachability']:.3f}"
              + (f"; every branch (docs/analytic.md): {summary['mean_branches']:.2f} per pose within the limits in the "
                 "reached voxels"
                 if summary["mean_branches"] is not None else "")
              + f"; {summary['seconds']:.1f} s"
              + (f"; written to {args.out}" if args.out else ""))
    return 0


def run_view(args: argparse.Namespace) -> int:
    """Write the page of a stored map (its robot loaded by the name the map records, or --robot)."""
    rmap = maps.load(args.store)
    if Path(args.store).resolve() in (html := Path(args.html).resolve(), *html.parents):
        raise KinelabError(f"--html {args.html} lies inside the map {args.store}: the page would overwrite it; give a "
                           "file outside the store")
    meta = rmap.meta
    if args.robot is None and meta["robot"] not in names():  # a store is data: it names no file to be read
        raise KinelabError(f"the map at {args.store} names its robot {meta['robot']!r}, which is not a registered "
                           "robot (kinelab robots): give its model file with --robot")
    robot = robot_module.load(args.robot or meta["robot"], base=meta.get("base"), tool=meta.get("tool"))
    if store.model_sha256(robot) != meta["source_sha256"]:
        raise KinelabError(f"{robot.name}'s model file is not the one the map at {args.store} was computed for: "
                           "give that robot with --robot")
    step(f"drawing the map of {robot.name} and its slices")
    page = maps_module.map_page(robot, rmap)
    write_output(args.html, page, "page")
    done, chunks = rmap.finished()
    unfinished = f"; unfinished: {done} of {chunks} chunks (run the same map reach again to resume)" \
        if done < chunks else ""
    print(f"wrote {args.html}: {robot.name}, {int((rmap.array('reachability') > 0).sum())} reached voxels of "
          f"{meta['voxels']}, {meta['spec']['voxel']:g} m{unfinished}")
    return 0
