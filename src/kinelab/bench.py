"""``kinelab bench``: the IK benchmark protocol, kinelab's solvers against the peer libraries.

Protocol (per robot): ``n`` seeded random configurations within the limits give the targets (their
Pinocchio FK); every solver starts from the same seeded random configuration per target. A result
counts as solved only when, checked here with Pinocchio's FK, the position error is below 1e-6 m and
the rotation error below 1e-6 rad, q is within the joint limits, and the call returned within the
budget (5 ms by default; restarts inside it are the solver's business). The solvers take turns over
the whole set ``repeats`` times (3 by default) and per problem the fastest run counts, with its own
verdict: the machines are shared and noisy, and a slow spell should not decide a comparison. Speed
targets live here, never in timed tests.
"""

from __future__ import annotations

import contextlib
import json
import platform
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.robot import Robot, load

TOL_POS = 1e-6  # [m]
TOL_ROT = 1e-6  # [rad]
BUDGET = 0.005  # [s]
REPEATS = 3  # rounds over the problem set; per problem the fastest run counts
DEFAULT_ROBOTS = ("panda", "ur5", "stanford", "era")


@dataclass(frozen=True)
class Case:
    """One benchmark problem: the target is the FK of ``q_target``; every solver starts at ``q_start``."""

    index: int
    q_target: np.ndarray
    q_start: np.ndarray
    oMtarget: pin.SE3


def cases(robot: Robot, n: int, seed: int) -> list[Case]:
    """``n`` seeded problems: targets and starts drawn uniformly within the joint limits."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        q_target, q_start = robot.random_q(rng), robot.random_q(rng)
        out.append(Case(i, q_target, q_start, robot.fk(q_target)))
    return out


def check_solution(robot: Robot, q, oMtarget: pin.SE3, elapsed: float, budget: float = BUDGET,
                   tol_pos: float = TOL_POS, tol_rot: float = TOL_ROT) -> tuple[bool, str]:
    """The protocol's verdict on one answer: (solved, reason). Pinocchio's FK is the judge."""
    if q is None:
        return False, "no answer"
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.n,) or not np.all(np.isfinite(q)):
        return False, "malformed answer"
    if elapsed > budget:
        return False, "over budget"
    if not robot.within_limits(q):
        return False, "outside the joint limits"
    dp, dr = robot.tool_error(q, oMtarget)
    if dp > tol_pos or dr > tol_rot:
        return False, f"pose error {dp:.1e} m, {dr:.1e} rad"
    return True, "solved"


# A solver under test: prepare(robot, budget) → solve(case, seed) → (q or None, iterations or -1)
SolveFn = Callable[[Case, int], tuple[np.ndarray | None, int]]
Prepare = Callable[[Robot, float], SolveFn]


def _kinelab(solver: str, **options) -> Prepare:
    def prepare(robot: Robot, budget: float) -> SolveFn:
        from kinelab.ik import solve

        def run(case: Case, seed: int):
            res = solve(robot, case.oMtarget, solver=solver, q0=case.q_start, seed=seed, time_budget=budget,
                        tol_pos=TOL_POS, tol_rot=TOL_ROT, **options)
            return res.q, res.iterations

        return run

    return prepare


KINELAB_SOLVERS: dict[str, Prepare] = {
    "frdm": _kinelab("frdm"),
    "frdm-plain": _kinelab("frdm", accel="none"),
    "biquat": _kinelab("biquat"),
    "dls": _kinelab("dls"),
}


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

    def __init__(self, robot: Robot, name: str, solve_fn: SolveFn, n: int):
        self.robot, self.name, self.solve_fn = robot, name, solve_fn
        self.best: list[tuple[float, bool, str, int] | None] = [None] * n

    def attempt(self, k: int, case: Case, budget: float, seed: int) -> None:
        t0 = time.perf_counter()
        try:
            q, it = self.solve_fn(case, seed + case.index)
        except Exception:  # noqa: BLE001 - a solver that raises on a problem has failed that problem
            q, it = None, -1
        elapsed = time.perf_counter() - t0
        ok, why = check_solution(self.robot, q, case.oMtarget, elapsed, budget)
        if self.best[k] is None or elapsed < self.best[k][0]:
            self.best[k] = (elapsed, ok, why, it)

    def row(self) -> Row:
        times = np.array([b[0] for b in self.best]) * 1e6
        solved = [b[0] * 1e6 for b in self.best if b[1]]
        failures: dict[str, int] = {}
        for _, ok, why, _ in self.best:
            if not ok:
                key = why.split(" ")[0] if why.startswith("pose") else why
                failures[key] = failures.get(key, 0) + 1
        n = len(self.best)
        return Row(self.robot.name, self.name, n, len(solved), 100.0 * len(solved) / n, float(np.median(times)),
                   float(np.percentile(times, 95)), float(np.median(solved)) if solved else float("nan"),
                   float(np.median([b[3] for b in self.best])), failures)


def run_robot(robot: Robot, solvers: dict[str, Prepare], problems: list[Case], budget: float, seed: int,
              missing: dict[str, str], repeats: int = REPEATS) -> list[Row]:
    """Every solver on every problem of one robot, ``repeats`` times over, the solvers taking turns (the
    order rotating each round); per problem the fastest run counts, with its verdict. A slow spell of a
    shared machine then costs no solver its figures, and each runs its problems back to back, warm."""
    tallies = []
    for name, prepare in solvers.items():
        try:
            solve_fn = prepare(robot, budget)
            for case in problems[:3]:  # warm-up: compilation, caches (an error here shows in the timed loop)
                with contextlib.suppress(Exception):
                    solve_fn(case, seed)
        except Exception as exc:  # noqa: BLE001 - a peer that cannot load this robot is reported, not fatal
            missing[f"{name} on {robot.name}"] = f"{type(exc).__name__}: {exc}"[:200]
            continue
        tallies.append(_Tally(robot, name, solve_fn, len(problems)))
    for r in range(repeats):
        k = r % max(1, len(tallies))
        for tally in tallies[k:] + tallies[:k]:
            for i, case in enumerate(problems):
                tally.attempt(i, case, budget, seed)
    return [t.row() for t in tallies]


def available_solvers() -> tuple[dict[str, Prepare], dict[str, str]]:
    """kinelab's solvers and the peers that are installed; the second dict says why a peer is absent."""
    from kinelab import bench_peers
    from kinelab.ik import _solver

    solvers: dict[str, Prepare] = {}
    for name, prep in KINELAB_SOLVERS.items():
        try:
            _solver("biquat" if name == "biquat" else "frdm" if name.startswith("frdm") else name)
        except Exception:  # noqa: BLE001 - a kinelab solver not built yet is simply not benchmarked
            continue
        solvers[name] = prep
    peers, missing = bench_peers.available()
    solvers.update(peers)
    return solvers, missing


def run(robots=None, n: int = 200, seed: int = 0, solvers: list[str] | None = None, budget: float = BUDGET,
        progress: bool = True, repeats: int = REPEATS) -> dict:
    """Run the protocol; returns a JSON-ready dict with the rows, the machine and the versions."""
    if n < 1 or repeats < 1 or not budget > 0:
        from kinelab.errors import KinelabError

        raise KinelabError(f"bench needs n ≥ 1, repeats ≥ 1 and a positive budget (got {n}, {repeats}, {budget} s)")
    names = list(robots or DEFAULT_ROBOTS)
    loaded = [load(name) for name in names]
    table, missing = available_solvers()
    if solvers:
        unknown = [s for s in solvers if s not in table]
        if unknown:
            from kinelab.errors import KinelabError

            raise KinelabError(f"unknown or unavailable solver {unknown[0]!r}; available: {', '.join(table)}"
                               + (f"; not installed: {', '.join(missing)}" if missing else ""))
        table = {k: table[k] for k in solvers}
    rows = []
    for robot in tqdm(loaded, desc="bench", disable=not progress, unit="robot"):
        rows += run_robot(robot, table, cases(robot, n, seed), budget, seed, missing, repeats)
    return {
        "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        "machine": {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
                    "python": platform.python_version()},
        "versions": _versions(),
        "protocol": {"n": n, "seed": seed, "repeats": repeats, "budget_s": budget, "tol_pos_m": TOL_POS,
                     "tol_rot_rad": TOL_ROT},
        "rows": [asdict(r) for r in rows],
        "not_run": missing,
    }


def _versions() -> dict[str, str]:
    import importlib.metadata as md

    out = {}
    for dist in ("kinelab", "pin", "numpy", "numba", "roboticstoolbox-python", "pytracik", "ikpy", "pin-pink"):
        with contextlib.suppress(md.PackageNotFoundError):
            out[dist] = md.version(dist)
    return out


def markdown(result: dict) -> str:
    """The bench rows as a Markdown table."""
    p = result["protocol"]
    lines = [f"Bench {result['date']}, {result['machine']['processor']}, Python {result['machine']['python']}; "
             f"n = {p['n']} targets per robot, seed {p['seed']}, best of {p.get('repeats', 1)} rounds per target, "
             f"budget {p['budget_s'] * 1e3:g} ms, "
             f"tolerances {p['tol_pos_m']:g} m / {p['tol_rot_rad']:g} rad (Pinocchio-checked).", "",
             "| robot | solver | success | median | p95 | median (solved) | iterations |",
             "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['robot']} | {r['solver']} | {r['success_pct']:.1f} % | {r['median_us']:.0f} µs | "
                     f"{r['p95_us']:.0f} µs | {r['median_solved_us']:.0f} µs | {r['median_iterations']:.0f} |")
    if result.get("not_run"):
        lines += ["", "Not run: " + "; ".join(f"{k} ({v})" for k, v in result["not_run"].items())]
    return "\n".join(lines)


def write(result: dict, out: str | Path) -> Path:
    """bench.json, bench.md and (with matplotlib) bench.png in the folder ``out``."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "bench.json").write_text(json.dumps(result, indent=2))
    sections = [markdown(result)]
    if "scaling" in result:
        from kinelab import scaling

        sections.append(scaling.markdown(result["scaling"]))
    if "tracking" in result:
        from kinelab.studies import era_passages

        sections.append(era_passages.tracking_markdown(result["tracking"]))
    (folder / "bench.md").write_text("\n\n".join(sections) + "\n")
    with contextlib.suppress(ImportError):
        plot(result, folder / "bench.png")
    return folder


def plot(result: dict, path: str | Path) -> None:
    """Success rate and median time per solver and robot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = result["rows"]
    robots = list(dict.fromkeys(r["robot"] for r in rows))
    solvers = list(dict.fromkeys(r["solver"] for r in rows))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    width = 0.8 / max(len(solvers), 1)
    for k, s in enumerate(solvers):
        xs = [i + k * width for i, rb in enumerate(robots)]
        by = {r["robot"]: r for r in rows if r["solver"] == s}
        ax1.bar(xs, [by.get(rb, {}).get("success_pct", 0) for rb in robots], width, label=s)
        ax2.bar(xs, [by.get(rb, {}).get("median_us", 0) for rb in robots], width, label=s)
    for ax, title in ((ax1, "success [%]"), (ax2, "median time [µs]")):
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(robots))], robots)
        ax.set_title(title)
    ax2.set_yscale("log")
    ax1.set_ylim(0, 105)
    handles, labels = ax1.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(solvers), fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
