"""``kinelab bench``: the runner. It runs kinelab's solvers and the installed peers over the problems of
:mod:`kinelab.report.bench.protocol` (which states the protocol), the solvers taking turns, rounds
rotating their order, and keeps per problem the fastest run with its own verdict.
"""

from __future__ import annotations

import contextlib
import importlib.metadata as md
import platform
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from tqdm import tqdm

from kinelab.errors import KinelabError
from kinelab.ik.request import check_seed
from kinelab.ik.tasks import TASKS
from kinelab.report.bench import fabrik, peers
from kinelab.report.bench.adapters import KINELAB_SOLVERS
from kinelab.report.bench.protocol import (
    BUDGET,
    DEFAULT_ROBOTS,
    REPEATS,
    SCHEDULES,
    STARTS,
    TOL_POS,
    TOL_ROT,
    Case,
    Prepare,
    SolveFn,
    cases,
    check_solution,
)
from kinelab.robot import Chain, load


@dataclass
class Row:
    """Figures of one (robot, solver) pair."""

    robot: str
    solver: str
    n: int
    solved: int
    success_pct: float
    median_us: float  # over all problems, failures included
    p95_us: float
    median_solved_us: float
    median_iterations: float
    failures: dict[str, int] = field(default_factory=dict)


class _Tally:
    """Per-problem (time, verdict, iterations) of one (robot, solver) pair, the fastest of its repeats kept."""

    def __init__(self, robot: Chain, name: str, solve_fn: SolveFn, n: int):
        self.robot, self.name, self.solve_fn = robot, name, solve_fn
        self.best: list[tuple[float, bool, str, int] | None] = [None] * n
        self.raised: Exception | None = None  # the last exception of a solve, kept to name a peer that always fails
        self.calls = self.raising = 0

    def attempt(self, k: int, case: Case, budget: float, seed: int) -> None:
        t0 = time.perf_counter()
        self.calls += 1
        try:
            q, it = self.solve_fn(case, seed + case.index)
        except Exception as exc:  # noqa: BLE001 - a solver that raises on a problem has failed that problem
            q, it = None, -1
            self.raised, self.raising = exc, self.raising + 1
        elapsed = time.perf_counter() - t0
        ok, why = check_solution(self.robot, q, case.oMtarget, elapsed, budget, task=case.task)
        kept = self.best[k]
        if kept is None or elapsed < kept[0]:
            self.best[k] = (elapsed, ok, why, it)

    def row(self) -> Row:
        """The pair's figures.

        Raises:
            PeerFailedError: every solve raised (a broken adapter or peer, never figures without it).
        """
        _tally_check(self)
        best = [b for b in self.best if b is not None]
        times = np.array([b[0] for b in best]) * 1e6
        solved = [b[0] * 1e6 for b in best if b[1]]
        n = len(best)
        return Row(self.robot.name, self.name, n, len(solved), 100.0 * len(solved) / n, float(np.median(times)),
                   float(np.percentile(times, 95)), float(np.median(solved)) if solved else float("nan"),
                   float(np.median([b[3] for b in best])), _failures(best))


def _tally_check(tally: _Tally) -> None:
    """Raise when every solve of the tally raised (a broken adapter or peer).

    Raises:
        PeerFailedError: named with the last exception's line.
    """
    if tally.calls and tally.raising == tally.calls and tally.raised is not None:
        raise peers.PeerFailedError(f"{tally.name} on {tally.robot.name} raised on every problem: "
                                    f"{peers.last_line(tally.raised)}")


def _failures(best: list[tuple[float, bool, str, int]]) -> dict[str, int]:
    """How many problems failed for each reason (a pose miss counted by its first word)."""
    failures: dict[str, int] = {}
    for _, ok, why, _ in best:
        if not ok:
            key = why.split(" ")[0] if why.startswith("pose") else why
            failures[key] = failures.get(key, 0) + 1
    return failures


def run_robot(robot: Chain, solvers: dict[str, Prepare], problems: list[Case], budget: float, seed: int,
              missing: dict[str, str], repeats: int = REPEATS, schedule: str = "blocked") -> list[Row]:
    """Every solver on every problem of one robot, ``repeats`` times over; per problem the fastest run
    counts, with its verdict. ``blocked``: the solvers take turns over the whole set (the order rotating
    each round), each running its problems back to back, warm. ``interleaved``: per problem every solver in
    turn (the order rotating per problem and round), so each call finds the caches another library left.
    Round r gives kinelab's solvers the seeds seed + index + r·n (fresh restarts, as the peers' are)."""
    tallies = _prepared(robot, solvers, problems, budget, seed, missing)
    for r in range(repeats):
        _round(tallies, problems, budget, seed + r * len(problems), r, schedule)
    return [t.row() for t in tallies]


def _round(tallies: list[_Tally], problems: list[Case], budget: float, round_seed: int, r: int,
           schedule: str) -> None:
    """Round r of :func:`run_robot`: blocked (each solver its problems back to back, the solvers' order rotating
    per round) or interleaved (per problem every solver in turn, the order rotating per problem and round)."""
    turns = max(1, len(tallies))
    if schedule == "interleaved":
        for i, case in enumerate(problems):
            k = (r + i) % turns
            for tally in tallies[k:] + tallies[:k]:
                tally.attempt(i, case, budget, round_seed)
        return
    k = r % turns
    for tally in tallies[k:] + tallies[:k]:
        for i, case in enumerate(problems):
            tally.attempt(i, case, budget, round_seed)


def _prepared(robot: Chain, solvers: dict[str, Prepare], problems: list[Case], budget: float, seed: int,
              missing: dict[str, str]) -> list[_Tally]:
    """A tally per solver that could load the robot, each warmed up (compilation, caches)."""
    tallies = []
    for name, prepare in solvers.items():
        try:
            solve_fn = prepare(robot, budget)
            for case in problems[:3]:  # warm-up: compilation, caches (an error here shows in the timed loop)
                with contextlib.suppress(Exception):
                    solve_fn(case, seed)
        except peers.PeerDeclinedError as exc:  # a peer that does not take this robot is reported, not fatal
            missing[f"{name} on {robot.name}"] = str(exc)[:200]
            continue
        except Exception as exc:  # noqa: BLE001 - an installed peer that breaks stops the bench, named
            raise peers.PeerFailedError(f"{name} failed on {robot.name}: {peers.last_line(exc)}") from exc
        tallies.append(_Tally(robot, name, solve_fn, len(problems)))
    return tallies


def available_solvers() -> tuple[dict[str, Prepare], dict[str, str]]:
    """kinelab's solvers and the peers that are installed; the second dict says why a peer is absent."""
    solvers: dict[str, Prepare] = dict(KINELAB_SOLVERS)
    solvers["fabrik"] = fabrik.prepare  # the FRDM paper's yardstick, written here (position only)
    found, missing = peers.available()
    solvers.update(found)
    return solvers, missing


def run(robots: list[str] | None = None, n: int = 200, seed: int = 0, solvers: list[str] | None = None,
        budget: float = BUDGET, progress: bool = False, repeats: int = REPEATS, start: str = "random",
        sigma: float = 0.2, schedule: str = "blocked", task: str = "pose") -> dict[str, Any]:
    """Run the protocol; returns a JSON-ready dict with the rows, the machine and the versions."""
    check_seed(seed)
    _check_protocol(n, repeats, budget, start, schedule, sigma)
    names = list(robots or DEFAULT_ROBOTS)
    loaded = [load(name, whole=False) for name in names]
    table, missing = available_solvers()
    table = _taking(_chosen(table, missing, solvers), task, missing)
    rows = []
    for robot in tqdm(loaded, desc="bench", disable=not progress, unit="robot"):
        problems = cases(robot, n, seed, start, sigma, task)
        rows += run_robot(robot, table, problems, budget, seed, missing, repeats, schedule)
    return {
        **header(),
        "protocol": {"n": n, "seed": seed, "repeats": repeats, "budget_s": budget, "tol_pos_m": TOL_POS,
                     "tol_rot_rad": TOL_ROT, "start": start, "sigma": sigma if start == "warm" else None,
                     "schedule": schedule, "task": task},
        "rows": [asdict(r) for r in rows],
        "not_run": missing,
    }


def _check_protocol(n: int, repeats: int, budget: float, start: str, schedule: str, sigma: float) -> None:
    """Refuse a protocol that cannot run, naming what is valid.

    Raises:
        KinelabError: n or repeats below 1, a budget not > 0 [s], an unknown start or schedule, or sigma outside
            (0, 10) rad.
    """
    if n < 1 or repeats < 1 or not budget > 0:
        raise KinelabError(f"bench needs n ≥ 1, repeats ≥ 1 and a positive budget (got {n}, {repeats}, {budget} s)")
    if start not in STARTS or schedule not in SCHEDULES or not 0 < sigma < 10:
        raise KinelabError(f"bench takes start in {STARTS}, schedule in {SCHEDULES} and 0 < sigma < 10 rad "
                           f"(got {start!r}, {schedule!r}, {sigma})")


def _chosen(table: dict[str, Prepare], missing: dict[str, str], solvers: list[str] | None) -> dict[str, Prepare]:
    """The solvers the user named (all available ones when None), in the order named.

    Raises:
        KinelabError: a name that is not available (the available ones and those not installed named).
    """
    if not solvers:
        return table
    unknown = [s for s in solvers if s not in table]
    if unknown:
        raise KinelabError(f"unknown or unavailable solver {unknown[0]!r}; available: {', '.join(table)}"
                           + (f"; not installed: {', '.join(missing)}" if missing else ""))
    return {k: table[k] for k in solvers}


def header() -> dict[str, Any]:
    """The date, the machine and the libraries' versions every bench result opens with."""
    return {"date": time.strftime("%Y-%m-%d %H:%M:%S"),
            "machine": {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
                        "python": platform.python_version()},
            "versions": _versions()}


def _taking(table: dict[str, Prepare], task: str, missing: dict[str, str]) -> dict[str, Prepare]:
    """The solvers that can be asked ``task`` (the others are listed in ``missing`` with the reason)."""
    if task not in TASKS:
        raise KinelabError(f"bench takes task in {TASKS}, got {task!r}")
    kept = {}
    for name, prepare in table.items():
        takes = peers.TASKS.get(name, ("pose",) if name == "biquat" else ("position",) if name == "fabrik" else TASKS)
        if task in takes:
            kept[name] = prepare
        else:
            missing[name] = f"takes task {', '.join(takes)}, not {task!r}"
    return kept


def _versions() -> dict[str, str]:
    out = {}
    for dist in ("kinelab", "pin", "numpy", "scipy", "roboticstoolbox-python", "pytracik", "ikpy", "pin-pink", "mink",
                 "mujoco", "daqp", "proxsuite"):
        with contextlib.suppress(md.PackageNotFoundError):
            out[dist] = md.version(dist)
    return out
