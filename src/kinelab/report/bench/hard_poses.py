"""Poses built to be hard for every-branch IK (``kinelab bench --completeness``, #41 goal 5).

Four kinds, n/4 each, from seeded random configurations within the limits:

- **on the singular surface**: one of joints 2, 3, 5 moved onto det J = 0 (the first sign change of det J along it,
  found on a 721-point grid and refined by 60 bisections): the pose has a double root there;
- **beside it**: the same configuration 1e-7 rad and 1e-4 rad off the surface: two roots that close;
- **at a limit**: one joint set at its lower or upper limit.

Each pose is solved by :func:`kinelab.solve_all`. The pose's own configuration must be among the answers — to
FOUND_EXACT rad beside the surface and at a limit (its roots are simple there), to FOUND_HARD on it (a double root
is met to about the square root of rounding) — or the set must say it is not certified
(``complete`` other than "certified", with its reason). A certified set that lacks it is a failure. An own
configuration answered only by a neighbouring root (within FOUND_HARD but not FOUND_EXACT) is counted apart: as
"merged" when that answer says it stands for two roots (``diagnostics.found`` ≥ 2: a pair closer than rounding can
tell apart, docs/analytic.md), else as a failure (two roots silently returned as one).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from kinelab.geometry import wrap_to_pi
from kinelab.ik import solve_all
from kinelab.ik.result import Branches
from kinelab.robot import Chain

FOUND_HARD = 1e-6  # [rad] the own configuration is an answer to this on the surface (a double root: met to ~1e-8)
FOUND_EXACT = 5e-8  # [rad] and to this elsewhere: simple roots, refined to ~1e-8 even 1e-7 rad from a fold, where
# the partner root lies ~2e-7 rad away (an answer that far stands for the partner, not for the own configuration)
OFFSETS = (0.0, 1e-7, 1e-4)  # [rad] off the singular surface
SURFACE_JOINTS = (1, 2, 4)  # joints 2, 3, 5: the shoulder, elbow and wrist singularities of a 6R


def on_surface(robot: Chain, q: np.ndarray, joint: int) -> np.ndarray | None:
    """q with ``joint`` moved onto det J = 0 (world Jacobian of the tool), or None when det J keeps its sign
    along that joint."""
    def det(x: float) -> float:
        moved = q.copy()
        moved[joint] = x
        return float(np.linalg.det(robot.jacobian_world(moved)))

    xs = np.linspace(robot.lower[joint], robot.upper[joint], 721)
    d = np.array([det(x) for x in xs])
    change = np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
    if not change.size:
        return None
    a, b = float(xs[change[0]]), float(xs[change[0] + 1])
    sign_a = np.sign(det(a))
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if np.sign(det(m)) == sign_a else (a, m)
    out = q.copy()
    out[joint] = 0.5 * (a + b)
    return out


def poses(robot: Chain, n: int, seed: int) -> list[tuple[str, np.ndarray]]:
    """n hard configurations (kind, q): a quarter on the surface, a quarter each 1e-7 and 1e-4 rad beside it, a
    quarter with one joint at a limit."""
    rng = np.random.default_rng(seed)
    out: list[tuple[str, np.ndarray]] = []
    while len(out) < 3 * (n // 4):
        q = robot.random_q(rng)
        joint = int(rng.choice(SURFACE_JOINTS))
        on = on_surface(robot, q, joint)
        if on is None:
            continue
        for offset in OFFSETS:
            moved = on.copy()
            moved[joint] = min(max(moved[joint] + offset, robot.lower[joint]), robot.upper[joint])
            out.append((f"{offset:g} rad off det J = 0", moved))
    while len(out) < n:
        q = robot.random_q(rng)
        joint = int(rng.integers(robot.n))
        q[joint] = robot.lower[joint] if rng.random() < 0.5 else robot.upper[joint]
        out.append(("at a limit", q))
    return out[:n]


def measure(robot: Chain, n: int, seed: int) -> dict[str, Any]:
    """Every hard pose solved: per kind, how many had the own configuration among the answers, how many sets were
    certified, how many said they were not (with the reasons counted), and the failures listed with their q."""
    kinds: dict[str, dict[str, Any]] = {}
    failures: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    for kind, q in poses(robot, n, seed):
        row = kinds.setdefault(kind, {"poses": 0, "own": 0, "merged": 0, "neighbour": 0, "certified": 0,
                                      "uncertified": 0, "reasons": {}})
        failed = _tally(row, kind, q, solve_all(robot, robot.fk(q)))
        if failed is not None:
            failures.append(failed)
    return {"robot": robot.name, "poses": n, "kinds": kinds, "failures": failures,
            "seconds": time.perf_counter() - t0}


def _tally(row: dict[str, Any], kind: str, q: np.ndarray, found: Branches) -> dict[str, Any] | None:
    """Count the pose of own configuration q [rad] and its branches ``found`` in its kind's row; the failure (the own
    configuration missed by a certified set, or answered silently by a neighbouring root), or None."""
    row["poses"] += 1
    gap, own, said = _answered(kind, q, found)
    row["own"] += own
    row["merged"] += said  # answered by a root that says it stands for two (diagnostics.found)
    silent = not own and gap <= FOUND_HARD and not said
    row["neighbour"] += silent  # and silently
    certified = found.complete == "certified"
    row["certified" if certified else "uncertified"] += 1
    if not certified:
        reason = found.complete_reason.split(" (")[0]
        row["reasons"][reason] = row["reasons"].get(reason, 0) + 1
    if not own and (certified or silent):
        return {"kind": kind, "q": q.tolist(), "nearest": gap, "certified": certified}
    return None


def _answered(kind: str, q: np.ndarray, found: Branches) -> tuple[float, bool, bool]:
    """The nearest branch's distance to q [rad], whether it is q (to the kind's tolerance), and whether a
    neighbouring root answers it saying it stands for two (``diagnostics.found``)."""
    gaps = np.abs(wrap_to_pi(found.q - q)).max(axis=1) if len(found) else np.array([np.inf])
    gap = float(gaps.min())
    own = gap <= (FOUND_HARD if kind.startswith("0 rad") else FOUND_EXACT)
    said = not own and gap <= FOUND_HARD and (found[int(np.argmin(gaps))].diagnostics.found or 1) > 1
    return gap, own, said
