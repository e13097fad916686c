"""``kinelab bench``: kinelab's solvers and the installed peers, side by side."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.cli.common import (
    Subcommands,
    count,
    count_or_zero,
    positive_number,
    print_json,
    progress_of,
    seed_argument,
)
from kinelab.errors import KinelabError
from kinelab.ik.words import TASKS
from kinelab.report.outfolder import check_output_folder

if TYPE_CHECKING:
    from kinelab.report import render
    from kinelab.report.bench import (
        branches,
        closed_step,
        collision_step,
        collisions,
        completeness,
        first_call,
        loops,
        paths,
        router,
        runner,
        scaling,
        standing_solve,
        startup,
        throughput,
        versus,
        wholebody,
        worlds,
    )
    from kinelab.studies import paper000_era
else:
    branches = lazy.module("kinelab.report.bench.branches", globals())
    collisions = lazy.module("kinelab.report.bench.collisions", globals())
    completeness = lazy.module("kinelab.report.bench.completeness", globals())
    loops = lazy.module("kinelab.report.bench.loops", globals())
    paper000_era = lazy.module("kinelab.studies.paper000_era", globals())
    render = lazy.module("kinelab.report.render", globals())
    router = lazy.module("kinelab.report.bench.router", globals())
    runner = lazy.module("kinelab.report.bench.runner", globals())
    scaling = lazy.module("kinelab.report.bench.scaling", globals())
    startup = lazy.module("kinelab.report.bench.startup", globals())
    throughput = lazy.module("kinelab.report.bench.throughput", globals())
    versus = lazy.module("kinelab.report.bench.versus", globals())
    wholebody = lazy.module("kinelab.report.bench.wholebody", globals())
    collision_step = lazy.module("kinelab.report.bench.collision_step", globals())
    closed_step = lazy.module("kinelab.report.bench.closed_step", globals())
    worlds = lazy.module("kinelab.report.bench.worlds", globals())
    first_call = lazy.module("kinelab.report.bench.first_call", globals())
    paths = lazy.module("kinelab.report.bench.paths", globals())
    standing_solve = lazy.module("kinelab.report.bench.standing_solve", globals())


def add(sub: Subcommands) -> None:
    """The ``bench`` subcommand."""
    s = sub.add_parser("bench", help="the IK benchmark: kinelab's solvers and the installed peers")
    s.add_argument("--robots", nargs="+", default=None,
                   help="robots (default: panda ur5 stanford era xarm7 z1 kinova ur10 so101 youbot)")
    s.add_argument("--n", type=count_or_zero, default=200,
                   help="targets per robot (default 200; 0 with --whole-body: its converged solves skipped)")
    seed_argument(s)
    s.add_argument("--solvers", nargs="+", default=None, help="solvers to run (default: all available)")
    s.add_argument("--budget-ms", type=positive_number, default=5.0, help="time budget per solve [ms] (default 5)")
    s.add_argument("--repeats", type=count, default=3,
                   help="rounds over the set; per problem the fastest counts (default 3)")
    s.add_argument("--start", choices=("random", "warm"), default="random",
                   help="starts: random in the limits (default), or warm: the target's q plus N(0, sigma) per joint")
    s.add_argument("--sigma", type=positive_number, default=0.2,
                   help="warm starts' noise per joint [rad or m] (default 0.2)")
    s.add_argument("--task", choices=TASKS, default="pose",
                   help="the components judged (default pose; position: random target rotations; axis: tool z, "
                        "random roll)")
    s.add_argument("--schedule", choices=("blocked", "interleaved"), default="blocked",
                   help="blocked (default): a solver runs the whole set, then the next; interleaved: every solver "
                        "per problem")
    _add_also(s)
    _add_instead(s)
    s.add_argument("--out", help="write bench.json, bench.md and bench.png here")
    s.add_argument("--json", action="store_true", help="print the results as JSON instead of tables")
    s.set_defaults(func=run)


def _add_also(s: argparse.ArgumentParser) -> None:
    """The protocols run besides the arm protocol (``--scaling``, ``--versus``, ``--startup``...)."""
    s.add_argument("--scaling", action="store_true", help="also time FRDM on synthetic chains of 7-100 links")
    s.add_argument("--tracking", action="store_true", help="also time tracking along the ERA passages (FRDM, DLS)")
    s.add_argument("--loops", action="store_true",
                   help="also the loops users run: throughput (solve loop, solve_batch, ik_LM) and path tracking")
    s.add_argument("--versus", action="store_true",
                   help="also kinelab.IK(...).solve and kinelab.solve against ik_LM: floor, warm (sigma 0.02, 0.2) "
                        "and random starts, interleaved and blocked rounds, ratios with their spread")
    s.add_argument("--branches", action="store_true",
                   help="also every branch of a pose: the closed form against the multistart and EAIK, the batch's "
                        "poses per second (the arms with a closed form or a 1-D search, the general 6R arms against "
                        "their Python route and ssik, the Stanford arm's multistart, the ERA, Baxter and the Panda "
                        "swept; --robots picks)")
    s.add_argument("--completeness", action="store_true",
                   help="also every-branch completeness: each arm with a class or the general 6R elimination on "
                        "10,000 seeded poses (its own configuration among the branches, the certified share), against "
                        "ssik's branch sets on 1,000 (pip install ssik), random arms of each 1-D search class and "
                        "random general 6R arms, and 1,000 hard poses per arm (on and beside det J = 0, at a limit)")
    s.add_argument("--throughput", action="store_true",
                   help="also targets/s of one solve_batch call on 2,000 random targets (panda, ur5, xarm7, youbot; "
                        "first starts from the start table and random), with the GPU libraries' published figures")
    s.add_argument("--collisions", action="store_true",
                   help="also solve with and without collisions= around a floor and a table (panda, ur5, kinova): "
                        "time ratio with its spread, clear success, the check's own cost")
    s.add_argument("--startup", action="store_true",
                   help="also how long --help, robots, fk, info and ik take from the shell against python -c "
                        "\"import pinocchio\" (best of --repeats + 4 rounds, interleaved)")


def _add_instead(s: argparse.ArgumentParser) -> None:
    """The protocols run instead of the arm protocol (``--whole-body``, ``--closed``, ``--router``...)."""
    s.add_argument("--whole-body", action="store_true",
                   help="instead of the arm protocol: the whole-body step side by side with pink and mink (--robots "
                        "among panda, baxter, talos, g1; default all four), --repeats rounds, and the converged "
                        "solve against pink iterated (--n targets per robot)")
    s.add_argument("--standing", action="store_true",
                   help="with --whole-body: every step from where the robot stands (TALOS's half-sitting, G1's "
                        "keyframe; the arms' neutral) instead of the bent start, velocity bounds active on most steps")
    s.add_argument("--worlds", action="store_true",
                   help="instead of the arm protocol: many worlds a step (WholeBody.step_batch): the Panda at 1,024 "
                        "worlds, G1 at 256 (--robots among panda, g1), --repeats rounds: steps per second")
    s.add_argument("--first-call", action="store_true",
                   help="instead of the arm protocol: a process's first solve, solve_batch and solve_all against its "
                        "later ones (--robots; default ur5 panda), --repeats rounds of fresh processes, with "
                        "kinelab.load's preparation and without it")
    s.add_argument("--paths", action="store_true",
                   help="instead of the arm protocol: the default path follower and the step follower on 50 "
                        "joint-space lines and cosine blends per arm (panda, xarm7, era, baxter_left, kinova; "
                        "--robots among them): paths met without a jump or a drift, µs per sample")
    s.add_argument("--standing-solve", action="store_true",
                   help="instead of the arm protocol: the converged whole-body solve from where each humanoid "
                        "stands (talos, g1, icub, romeo; --robots among them), --n targets each: met, met without a "
                        "restart, median time")
    s.add_argument("--closed", action="store_true",
                   help="instead of the arm protocol: the step on robots that close loops (fourbar, ankle, cassie) "
                        "side by side with mink's EqualityConstraintTask, --repeats rounds of 1,000 steps: time, "
                        "loop error")
    s.add_argument("--collisions-step", action="store_true",
                   help="instead of the arm protocol: the whole-body step holding collisions side by side with mink's "
                        "CollisionAvoidanceLimit and pink's self-collision barrier (--robots among panda, talos; "
                        "default both), --repeats rounds of 1,000 steps: time, penetrations, least distance")
    s.add_argument("--router", action="store_true",
                   help="instead of the arm protocol: kinelab.IK(...).solve_batch, .solve_all and .track against "
                        "the module functions (--robots; default ur5 panda kinova crx10ia era), --repeats rounds")
    s.add_argument("--budgets", action="store_true",
                   help="also measure how every entry point with a budget keeps 5 ms (p50, p99, max per robot)")


def run(args: argparse.Namespace) -> int:
    """Run the protocols asked for, print their tables (or JSON), write the files with --out."""
    if args.out:
        check_output_folder(args.out, "bench")
    if args.n == 0 and not args.whole_body:
        raise KinelabError("--n 0 skips the converged solves of --whole-body; the other protocols need --n ≥ 1 "
                           "targets per robot")
    if args.standing and not args.whole_body:
        raise KinelabError("--standing goes with --whole-body (the step from where the robot stands)")
    if args.worlds:
        return _alone(args, "worlds", lambda: worlds.run(args.robots, rounds=args.repeats), worlds.markdown)
    if args.first_call:
        return _alone(args, "first_call", lambda: first_call.run(args.robots, rounds=args.repeats),
                      first_call.markdown)
    if args.paths:
        return _alone(args, "paths", lambda: paths.run(args.robots, progress=progress_of(args)), paths.markdown)
    if args.standing_solve:
        return _alone(args, "standing_solve", lambda: standing_solve.run(
            args.robots, count=args.n, seed=args.seed, progress=progress_of(args)), standing_solve.markdown)
    if args.closed:
        return _alone(args, "closed", lambda: closed_step.run(args.robots, rounds=args.repeats), closed_step.markdown)
    if args.collisions_step:
        return _alone(args, "collisions_step", lambda: collision_step.run(
            args.robots, rounds=args.repeats, progress=progress_of(args)), collision_step.markdown)
    if args.whole_body or args.router:  # a protocol run alone
        return _whole_body(args) if args.whole_body else _router(args)
    first = _before_the_peers(args)
    result = runner.run(robots=args.robots, n=args.n, seed=args.seed, solvers=args.solvers,
                        budget=args.budget_ms / 1e3, progress=progress_of(args), repeats=args.repeats,
                        start=args.start, sigma=args.sigma, schedule=args.schedule, task=args.task)
    result.update(first)
    for key, measure in _PROTOCOLS.items():  # each protocol asked for by its flag of the same name, in this order
        if getattr(args, key):
            result[key] = measure(args)
    if args.out:
        render.write_bench(result, args.out)
    if args.json:
        print_json(result)
        return 0
    _print_tables(result)
    if args.out:
        print(f"results written to {args.out}")
    return 0


_PROTOCOLS: dict[str, Callable[[argparse.Namespace], Any]] = {
    "tracking": lambda a: paper000_era.tracking_bench(repeats=a.repeats),
    "loops": lambda a: loops.run(a.robots, seed=a.seed, repeats=a.repeats, progress=progress_of(a)),
    "budgets": lambda a: loops.budgets_run(a.robots, seed=a.seed, n=a.n, progress=progress_of(a)),
    "versus": lambda a: versus.run(a.robots, seed=a.seed, repeats=max(a.repeats, 2), progress=progress_of(a)),
    "branches": lambda a: branches.run(a.robots, seed=a.seed, repeats=max(a.repeats, 2), progress=progress_of(a)),
    "completeness": lambda a: completeness.run(seed=a.seed, progress=progress_of(a)),
    "throughput": lambda a: throughput.run(a.robots, seed=a.seed, repeats=a.repeats, progress=progress_of(a)),
    "collisions": lambda a: collisions.run(None, seed=a.seed, repeats=max(a.repeats, 2), progress=progress_of(a)),
}
"""The protocols run after the main bench, each under its flag's name (``--loops`` → ``result["loops"]``)."""


def _router(args: argparse.Namespace) -> int:
    """``--router``: the prepared solver against the module functions, alone (its table, JSON or files)."""
    return _alone(args, "router", lambda: router.run(args.robots, seed=args.seed, repeats=args.repeats,
                                                     progress=progress_of(args)), router.markdown)


def _whole_body(args: argparse.Namespace) -> int:
    """``--whole-body``: its protocol alone (its tables, JSON or files)."""
    return _alone(args, "whole_body", lambda: wholebody.run(args.robots, rounds=args.repeats, solves=args.n,
                                                            seed=args.seed, progress=progress_of(args),
                                                            standing=args.standing),
                  wholebody.markdown)


def _alone(args: argparse.Namespace, key: str, run: Callable[[], Any], markdown: Callable[[Any], str]) -> int:
    """A protocol run alone (``run()``): its figures under ``key`` after the bench header (taken first), written
    with --out, printed as JSON or as its table."""
    result = runner.header()
    found = result[key] = run()
    if args.out:
        render.write_bench(result, args.out)
    if args.json:
        print_json(result)
    else:
        print(markdown(found))
    return 0


def _before_the_peers(args: argparse.Namespace) -> dict[str, Any]:
    """The timings that run before the main bench: the peers' solver threads and caches would disturb them."""
    first: dict[str, Any] = {}
    if args.startup:  # on a quiet process: nothing of the bench's own yet competes for the cores
        first["startup"] = startup.run(rounds=args.repeats + 4)
    if args.scaling:
        first["scaling"] = scaling.run(progress=progress_of(args))
    return first


def _print_tables(result: dict[str, Any]) -> None:
    """The main bench's table, then each protocol's that ran, in _TABLES' order."""
    print(render.bench_markdown(result))
    for key, table in _TABLES.items():
        if key in result:
            print(table(result[key]))


_TABLES: dict[str, Callable[[Any], str]] = {
    "scaling": lambda r: scaling.markdown(r),
    "startup": lambda r: startup.markdown(r),
    "tracking": lambda r: paper000_era.tracking_markdown(r),
    "loops": lambda r: loops.markdown(r["throughput"], r["tracking"], r["budgets"]),
    "budgets": lambda r: "\n" + loops.budget_markdown(r),
    "whole_body": lambda r: "\n" + wholebody.markdown(r),
    "versus": lambda r: versus.markdown(r),
    "branches": lambda r: branches.markdown(r),
    "throughput": lambda r: throughput.markdown(r),
    "collisions": lambda r: collisions.markdown(r),
    "completeness": lambda r: completeness.markdown(r),
}
