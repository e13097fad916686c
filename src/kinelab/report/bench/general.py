"""``kinelab bench --branches``, the general 6R arms: the compiled elimination against its Python route, the
multistart and ssik.

Per arm the general elimination takes (:mod:`kinelab.ik.analytic.general`: the calibrated UR10e and
``general6r`` by default), the same n seeded poses (the FK of random configurations) go to ``solve_all`` (the
compiled elimination, every branch judged by the certified compiled FK), the same with its certificate read
(``Branches.complete``: the elimination again with the eigenvalues' condition numbers, then Kantorovich's test),
the Python route the elimination took before it was compiled (:func:`~kinelab.ik.analytic.general.roots_within`,
judged as before), the multistart (``solver="frdm"``, seeds changing with the round) and, when installed and
faster than SSIK_CAP a pose on the first one (its second call), ssik's ``solve`` (its own elimination,
unchecked). Rounds alternate interleaved and blocked schedules (:func:`~kinelab.report.bench.protocol.round_plan`);
figures are the median time per call per round, reported as the median over rounds with the spread (lowest,
highest round). The batch
(``solve_all_batch`` on all cores) is timed on BATCH poses, three times, its median and spread in poses per
second.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.ik.analytic.batch import all_branches_batch
from kinelab.ik.analytic.branches import judged_roots
from kinelab.ik.analytic.classify import general_class
from kinelab.ik.analytic.general import roots_within
from kinelab.ik.api import solve_all
from kinelab.ik.request import make_request
from kinelab.report.bench.protocol import Call, figures, warmed_rounds
from kinelab.robot import Chain

GENERAL_ROBOTS = ("ur10e_calibrated", "general6r")
SSIK_CAP = 0.05  # [s] ssik joins the rounds when its first pose took less than this (460 ms on the calibrated UR10e)
BATCH = 2_000  # poses in each timed batch


def general_arm(robot: Chain, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """One arm of the general elimination: times per call (see the module), the batch's poses per second."""
    rng = np.random.default_rng(seed)
    poses = [robot.fk(robot.random_q(rng)) for _ in range(n)]
    calls: dict[str, Call] = {"compiled": lambda t, s: solve_all(robot, t),
                              "compiled + certificate": lambda t, s: solve_all(robot, t).complete,
                              "python route": _python_route(robot),
                              "multistart": lambda t, s: solve_all(robot, t, solver="frdm", seed=s)}
    peer = _ssik(robot, poses[0])
    if peer is not None:
        calls["ssik (unchecked)"] = peer
    timed = figures(warmed_rounds(poses, calls, repeats))
    sets = [solve_all(robot, t) for t in poses]
    return {"robot": robot.name, "poses": n, "branches_mean": float(np.mean([len(s) for s in sets])),
            "certified": float(np.mean([s.complete == "certified" for s in sets])), **timed,
            **_batch(robot, rng)}


def _python_route(robot: Chain) -> Call:
    """The elimination as it ran before it was compiled: NumPy and SciPy's QZ, the set certified on the way,
    each root judged as before (:func:`~kinelab.ik.analytic.branches.judged_roots`)."""
    arm, req = general_class(robot).arm, make_request("frdm", tol_pos=1e-6, tol_rot=1e-6)

    def call(target: pin.SE3, seed: int) -> Any:
        q, found, free, _ = roots_within(arm, target.homogeneous, robot.lower, robot.upper, None, 1e-9)
        return judged_roots(robot, q, found, free, target, req)

    return call


def _ssik(robot: Chain, first: pin.SE3) -> Call | None:
    """ssik's solver for the robot's URDF, or None without ssik or when its second call on the first pose takes
    SSIK_CAP or more."""
    try:
        import ssik
    except ImportError:
        return None
    if robot.urdf_path is None:
        return None
    peer = ssik.Manipulator.from_urdf(str(robot.urdf_path), base=robot.base, ee=robot.tool)

    def call(target: pin.SE3, seed: int) -> Any:
        return peer.solve(target.homogeneous, respect_limits=True, enumerate_windings=False)

    call(first, 0)  # its first call sets the solver up
    t0 = time.perf_counter()
    call(first, 0)
    return call if time.perf_counter() - t0 < SSIK_CAP else None


def _batch(robot: Chain, rng: np.random.Generator) -> dict[str, Any]:
    """``solve_all_batch``'s poses per second on all cores: median of three and (lowest, highest)."""
    H = robot.fk_batch(np.array([robot.random_q(rng) for _ in range(BATCH)]))
    all_branches_batch(robot, H[:2])
    rates = []
    for _ in range(3):
        t0 = time.perf_counter()
        all_branches_batch(robot, H)
        rates.append(BATCH / (time.perf_counter() - t0))
    return {"batch_per_s": float(np.median(rates)), "batch_spread_per_s": (min(rates), max(rates))}


def markdown(rows: list[dict[str, Any]]) -> str:
    """The rows as a Markdown table (times: median over rounds [lowest–highest round])."""
    names = ("compiled", "compiled + certificate", "python route", "multistart", "ssik (unchecked)")

    def shown(row: dict[str, Any], name: str) -> str:
        if name not in row["us"]:
            return "–"
        lo, hi = row["spread_us"][name]
        return f"{row['us'][name]:.4g} µs [{lo:.4g}–{hi:.4g}]"

    lines = ["| arm | branches | certified | " + " | ".join(names) + " | batch, all cores |",
             "|---|---|---|" + "---|" * len(names) + "---|"]
    for r in rows:
        lo, hi = r["batch_spread_per_s"]
        lines.append(f"| {r['robot']} | {r['branches_mean']:.2f} | {100 * r['certified']:.1f} % | "
                     + " | ".join(shown(r, name) for name in names)
                     + f" | {r['batch_per_s']:,.0f}/s [{lo:,.0f}–{hi:,.0f}] |")
    return "\n".join(lines)
