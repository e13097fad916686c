"""``kinelab bench --completeness``, the SEW angle's table: does the search find a pose's own configuration
among the branches at the pose's own SEW angle?

Per 7R arm, n seeded configurations within the limits; for each, :func:`kinelab.solve_all` with
``redundancy=SEW(ψ)``, ψ the configuration's own angle: the share whose own configuration is among the answers
(to FOUND rad, joint by joint modulo 2π), the answers per pose, the time per pose (median, 10th and 90th
percentile), and every miss with its q and how far its elbow lies from the shoulder–wrist line (the angle is
ill-conditioned where the elbow is nearly straight).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.sew import SEW, arm7, sew_angle
from kinelab.ik.api import solve_all
from kinelab.robot import Chain

FOUND = 1e-6  # [rad] the pose's own configuration is an answer to this
ARMS = ("panda", "xarm7", "tiago", "tiago_pro", "era", "baxter_left", "pr2_left", "talos_left")


def measure(robot: Chain, n: int, seed: int) -> dict[str, Any]:
    """The SEW table's row of one 7R arm (n seeded poses)."""
    arm = arm7(robot)
    found, counts, seconds = 0, list[int](), list[float]()
    missed: list[dict[str, Any]] = []
    for q in robot.random_qs(n, np.random.default_rng(seed + 7)):
        t0 = time.perf_counter()
        answers = solve_all(robot, robot.fk(q), redundancy=SEW(sew_angle(robot, q)))
        seconds.append(time.perf_counter() - t0)
        gap = min((float(np.abs(wrap_to_pi(r.q - q)).max()) for r in answers), default=np.inf)
        found, counts = found + (gap <= FOUND), [*counts, len(answers)]
        if gap > FOUND:
            S, E, W = arm.points(q)
            w = (W - S) / np.linalg.norm(W - S)
            off = float(np.linalg.norm((E - S) - ((E - S) @ w) * w))
            missed.append({"q": q.tolist(), "nearest": gap, "elbow_off_line": off})
    ms = 1e3 * np.array(seconds)
    return {"robot": robot.name, "poses": n, "found": found / max(n, 1), "branches_median": float(np.median(counts)),
            "branches_max": int(max(counts, default=0)), "ms_median": float(np.median(ms)),
            "ms_p10": float(np.percentile(ms, 10)), "ms_p90": float(np.percentile(ms, 90)), "missed": missed}


def markdown(rows: list[dict[str, Any]]) -> list[str]:
    """The table and its misses."""
    if not rows:
        return []
    lines = ["", "| 7R arm | poses at their own SEW angle | own configuration found | answers median / max | "
             "ms per pose median [p10–p90] |", "|---|---|---|---|---|"]
    lines += [f"| {r['robot']} | {r['poses']:,} | {100 * r['found']:.2f} % | {r['branches_median']:g} / "
              f"{r['branches_max']} | {r['ms_median']:.0f} [{r['ms_p10']:.0f}–{r['ms_p90']:.0f}] |" for r in rows]
    lines += [f"- {r['robot']}: q = ({', '.join(f'{v:.6f}' for v in m['q'])}), elbow {m['elbow_off_line']:.3f} m "
              "from the shoulder–wrist line" for r in rows for m in r["missed"][:10]]
    return lines
