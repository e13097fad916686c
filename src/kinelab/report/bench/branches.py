"""``kinelab bench --branches``: every branch of a pose — the closed form against the multistart and EAIK.

Per arm with a closed form or a 1-D search (:mod:`kinelab.ik.analytic`), the same n seeded poses (the FK of random
configurations) go to ``solve_all`` (the closed form, every answer judged by Pinocchio), ``solve_all(...,
solver="frdm")`` (the multistart with its stopping rule) and, when installed, EAIK's ``IK`` (the peer's own
closed form, unchecked). Rounds alternate interleaved (each solver on each pose in turn, the order rotating)
and blocked schedules; the multistart's seeds change with the round. Figures: the median time per call per
round, reported as the median over rounds with the spread (lowest, highest round); how often the multistart
found every closed-form branch; the batch's poses per second on all cores, with and without Pinocchio's check.
The general 6R arms (the calibrated UR10e and ``general6r``) get their own table
(:mod:`kinelab.report.bench.general`). Arms without a closed form (the Stanford arm by default) get the
multistart against a dense reference: the same search without its stopping rule for 0.5 s. A 7R arm with a
swept closed form (the ERA) gets ``solve_all(..., redundancy=K)`` against the multistart, timed alike (its
answers are a continuum: no completeness).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.ik.analytic.batch import all_branches_batch
from kinelab.ik.analytic.branches import LIMIT_SLACK, has_general_form
from kinelab.ik.analytic.branches import SAME as CLOSED_SAME
from kinelab.ik.analytic.classify import classify
from kinelab.ik.analytic.kernel import MAX_ROWS, branches_batch
from kinelab.ik.analytic.redundancy import has_swept_form
from kinelab.ik.api import solve_all
from kinelab.ik.branches import SAME
from kinelab.ik.chain import chain_model
from kinelab.ik.limits import distance
from kinelab.ik.request import make_request
from kinelab.report.bench import general
from kinelab.report.bench.general import GENERAL_ROBOTS, general_arm
from kinelab.report.bench.protocol import Call, figures, warmed_rounds
from kinelab.robot import Chain, load

ANALYTIC_ROBOTS = ("ur3", "ur5", "ur10", "z1", "kinova", "so101", "xarm6", "crx10ia")
NUMERIC_ROBOTS = ("stanford",)
REDUNDANT_ROBOTS = ("era", "panda", "baxter_left")
K = 16  # samples of a 7R arm's swept joint


def _eaik(robot: Chain) -> Call | None:
    """EAIK's solver for the robot (built from kinelab's axes at q = 0), or None when it is not installed."""
    try:
        from eaik.IK_HP import HPRobot
    except ImportError:
        return None
    arm = classify(robot).arm
    if arm is None or arm.mirrored or arm.searched:  # EAIK solves the closed-form classes alone
        return None

    v = chain_model(robot).vectors(np.zeros(robot.n))
    bot = HPRobot(v["e"], np.vstack([v["o"][0], np.diff(v["o"], axis=0), v["N"] - v["o"][-1]]))
    R0 = v["R"]

    def call(target: pin.SE3, seed: int) -> Any:
        H = target.homogeneous.copy()
        H[:3, :3] = H[:3, :3] @ R0.T
        return bot.IK(H)

    return call


def _complete(robot: Chain, found: Sequence[Any], reference: Sequence[Any], same: float) -> bool:
    """Every reference answer has a found answer within ``same`` (joint by joint, modulo 2π)."""
    return all(any(distance(robot, f.q, r.q) <= same for f in found) for r in reference)


def analytic_arm(robot: Chain, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """One arm with a closed form: times per call, the multistart's completeness, the batch's throughput."""
    rng = np.random.default_rng(seed)
    poses = [robot.fk(robot.random_q(rng)) for _ in range(n)]
    calls: dict[str, Call] = {"closed form": lambda t, s: solve_all(robot, t),
                              "multistart": lambda t, s: solve_all(robot, t, solver="frdm", seed=s)}
    peer = _eaik(robot)
    if peer is not None:
        calls["EAIK (unchecked)"] = peer
    timed = _timed(poses, calls, repeats)
    closed = [solve_all(robot, t) for t in poses]
    searched = [solve_all(robot, t, solver="frdm", seed=seed + k) for k, t in enumerate(poses)]
    complete = sum(_complete(robot, s, c, SAME) for s, c in zip(searched, closed, strict=True))
    extra = sum(_complete(robot, c, s, SAME) is False for s, c in zip(searched, closed, strict=True))
    batch = _throughput(robot, rng)
    return {"robot": robot.name, "class": classify(robot).arm.name, "poses": n,  # type: ignore[union-attr]
            "branches_mean": float(np.mean([len(c) for c in closed])), **timed,
            "multistart_complete": complete / n, "multistart_beyond_closed_form": extra, **batch}


def _throughput(robot: Chain, rng: np.random.Generator, count: int = 20_000) -> dict[str, float]:
    """Poses per second of the closed form's batch on all cores: checked by Pinocchio, and the kernel alone."""
    H = robot.fk_batch(np.array([robot.random_q(rng) for _ in range(count)]))
    all_branches_batch(robot, H[:2])
    t0 = time.perf_counter()
    all_branches_batch(robot, H)
    checked = count / (time.perf_counter() - t0)
    arm = classify(robot).arm
    assert arm is not None
    out = np.empty((count, MAX_ROWS, arm.n))
    found, free = np.zeros((count, MAX_ROWS), dtype=np.int64), np.zeros((count, MAX_ROWS), dtype=np.bool_)
    rows = np.zeros(count, dtype=np.int64)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        branches_batch(arm.kind, arm.mirrored, arm.h, arm.o, arm.R0, arm.N0, H, robot.lower, robot.upper,
                       CLOSED_SAME, LIMIT_SLACK, out, found, free, rows)
        best = min(best, time.perf_counter() - t0)
    return {"batch_checked_per_s": checked, "batch_kernel_per_s": count / best}


def numeric_arm(robot: Chain, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """An arm without a closed form: the multistart's time and its completeness against a dense search."""
    rng = np.random.default_rng(seed)
    poses = [robot.fk(robot.random_q(rng)) for _ in range(n)]
    timed = _timed(poses, {"multistart": lambda t, s: solve_all(robot, t, seed=s)}, repeats)
    complete = 0
    for k, target in enumerate(poses):
        dense = solve_all(robot, target, seed=10_000 + k, time_budget=0.5, stop_below=None)
        complete += _complete(robot, solve_all(robot, target, seed=seed + k), dense, SAME)
    return {"robot": robot.name, "class": "none: " + classify(robot).reason, "poses": n, **timed,
            "multistart_complete": complete / n}


def redundant_arm(robot: Chain, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """A 7R arm with a swept closed form: its time and answer count at K samples against the multistart's."""
    rng = np.random.default_rng(seed)
    poses = [robot.fk(robot.random_q(rng)) for _ in range(n)]
    calls: dict[str, Call] = {"closed form": lambda t, s: solve_all(robot, t, redundancy=K),
                              "multistart": lambda t, s: solve_all(robot, t, solver="frdm", seed=s)}
    timed = _timed(poses, calls, repeats)
    found = [solve_all(robot, t, redundancy=K) for t in poses]
    return {"robot": robot.name, "class": f"{found[0][0].mode if found[0] else 'swept'}", "poses": n,
            "branches_mean": float(np.mean([len(f) for f in found])), "samples": K, **timed}


def _timed(poses: list[pin.SE3], calls: dict[str, Call], repeats: int) -> dict[str, Any]:
    """:func:`figures` of :func:`warmed_rounds`."""
    return figures(warmed_rounds(poses, calls, repeats))


def run(robots: list[str] | None = None, n: int = 100, seed: int = 0, repeats: int = 4,
        progress: bool = False) -> list[dict[str, Any]]:
    """Every arm asked for (default: the arms with a closed form or a 1-D search, the Stanford arm, the ERA, the
    Panda and Baxter), a row each."""
    names = list(robots or (*ANALYTIC_ROBOTS, *GENERAL_ROBOTS, *NUMERIC_ROBOTS, *REDUNDANT_ROBOTS))
    rows = []
    for name in tqdm(names, desc="bench --branches", disable=not progress, unit="arm"):
        robot = load(name)
        if classify(robot).arm is None and has_general_form(robot, make_request("frdm")):
            rows.append({"general": True, **general_arm(robot, n, seed, repeats)})
        elif classify(robot).arm is not None:
            rows.append(analytic_arm(robot, n, seed, repeats))
        elif has_swept_form(robot):
            rows.append(redundant_arm(robot, max(10, n // 5), seed, repeats))
        else:
            rows.append(numeric_arm(robot, max(10, n // 5), seed, repeats))
    return rows


def markdown(rows: list[dict[str, Any]]) -> str:
    """The rows as Markdown tables (times: median over rounds [lowest–highest round]): the arms with a class, the
    multistart's and the swept ones; then the general 6R arms' (:mod:`kinelab.report.bench.general`)."""
    generals = [r for r in rows if r.get("general")]
    rows = [r for r in rows if not r.get("general")]

    def shown(row: dict[str, Any], name: str, scale: float, unit: str) -> str:
        if name not in row["us"]:
            return "–"
        lo, hi = row["spread_us"][name]
        return f"{row['us'][name] / scale:.3g} {unit} [{lo / scale:.3g}–{hi / scale:.3g}]"

    lines = ["| arm | branches | closed form | multistart | EAIK (unchecked) | multistart complete | batch checked "
             "| batch kernel |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "samples" in r:
            lines.append(f"| {r['robot']} | {r['branches_mean']:.1f} at {r['samples']} samples | "
                         f"{shown(r, 'closed form', 1e3, 'ms')} | {shown(r, 'multistart', 1e3, 'ms')} "
                         "| – | – | – | – |")
            continue
        closed = "closed form" in r["us"]
        lines.append(
            f"| {r['robot']} | {r['branches_mean']:.2f} | {shown(r, 'closed form', 1, 'µs')} | "
            f"{shown(r, 'multistart', 1e3, 'ms')} | {shown(r, 'EAIK (unchecked)', 1, 'µs')} | "
            f"{100 * r['multistart_complete']:.1f} % | {r['batch_checked_per_s']:,.0f}/s | "
            f"{r['batch_kernel_per_s']:,.0f}/s |" if closed else
            f"| {r['robot']} | – | – | {shown(r, 'multistart', 1e3, 'ms')} | – | "
            f"{100 * r['multistart_complete']:.1f} % (vs dense) | – | – |")
    return "\n".join(lines) + ("\n\n" + general.markdown(generals) if generals else "")
