"""``kinelab bench --completeness``: does every-branch IK find every branch?

Two measures, per arm with a class (closed form or 1-D search, docs/analytic.md):

- **the pose's own configuration**: n seeded random configurations within the limits, their poses solved by
  :func:`~kinelab.ik.analytic.branches.all_branches_batch` (every branch judged by Pinocchio); the share of poses
  whose own configuration is among the branches, to FOUND rad joint by joint (modulo 2π), and the misses named
  by how near the nearest branch came (a double root is met only to about the square root of the rounding);
- **against ssik** (``pip install ssik``): for ``peer_n`` of those poses, ssik's answers for the same URDF
  (``Manipulator.from_urdf``), kept where Pinocchio confirms them, against kinelab's: equal as sets to SAME_SET
  rad, every difference listed with both counts.

7R arms swept at a held joint are measured at the pose's own value of that joint
(:func:`~kinelab.ik.analytic.redundancy.at_value`). Random arms of each search class (axes at random angles,
generated here) give the same first measure without a file.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.branches import all_branches_batch, arm_roots
from kinelab.ik.analytic.classify import classify, classify_vectors
from kinelab.ik.analytic.redundancy import at_value, has_swept_form, swept_arm
from kinelab.ik.request import make_request
from kinelab.robot import Robot, load

FOUND = 1e-6  # [rad] the pose's own configuration is a branch to this
NEAR = 1e-4  # [rad] a miss nearer than this is a double root met to rounding's square root
SAME_SET = 1e-6  # [rad] two answers this close are one
ROBOTS = ("ur5", "ur10", "kinova", "z1", "xarm6", "crx10ia", "panda", "baxter_left")


def own_configuration(robot: Robot, n: int, seed: int) -> dict[str, Any]:
    """The share of n seeded poses whose own configuration is among the branches (6R arms: the batch; 7R arms:
    the branches at the held joint's own value), and the misses' nearest distances."""
    Q = robot.random_qs(n, np.random.default_rng(seed))
    t0 = time.perf_counter()
    if classify(robot).arm is not None:
        batch = all_branches_batch(robot, robot.fk_batch(Q))
        gaps = np.nanmin(np.abs(wrap_to_pi(batch.q - Q[:, None, :])).max(axis=2), axis=1, initial=np.inf,
                         where=~np.isnan(batch.q[:, :, 0]))
        counts = batch.count
    else:
        sw, req = swept_arm(robot), make_request("frdm")
        found = [at_value(robot, robot.fk(q), req, float(q[sw.joint])) for q in Q]
        gaps = np.array([min((float(np.abs(wrap_to_pi(a[0] - q)).max()) for a in f), default=np.inf)
                         for f, q in zip(found, Q, strict=True)])
        counts = np.array([len(f) for f in found])
    elapsed = time.perf_counter() - t0
    missed = gaps > FOUND
    return {"robot": robot.name, "method": _method(robot), "poses": n, "found": float(1 - missed.mean()),
            "misses": int(missed.sum()), "near_misses": int((missed & (gaps <= NEAR)).sum()),
            "branches_mean": float(np.mean(counts)), "branches_max": int(np.max(counts)), "seconds": elapsed}


def _method(robot: Robot) -> str:
    arm = classify(robot).arm
    if arm is not None:
        return arm.mode
    sw = swept_arm(robot)
    return f"joint {sw.joint + 1} held: {sw.arm.mode}"


def against_ssik(robot: Robot, n: int, seed: int) -> dict[str, Any] | None:
    """kinelab's branch sets against ssik's for n seeded poses of the same URDF, or None without ssik or a
    6-joint class."""
    try:
        import ssik
    except ImportError:
        return None
    if classify(robot).arm is None or robot.urdf_path is None:
        return None
    peer = ssik.Manipulator.from_urdf(str(robot.urdf_path), base=robot.base, ee=robot.tool)
    rng = np.random.default_rng(seed + 1)
    equal, differences, t_ours, t_peer = 0, [], 0.0, 0.0
    for k in range(n):
        H = robot.fk(robot.random_q(rng)).homogeneous
        t0 = time.perf_counter()
        ours = [np.asarray(a) for a in all_branches_batch(robot, H[None]).q[0] if not np.isnan(a[0])]
        t1 = time.perf_counter()
        theirs = [np.asarray(s.q, dtype=float) for s in peer.solve(H, respect_limits=True, enumerate_windings=False)]
        t_ours, t_peer = t_ours + t1 - t0, t_peer + time.perf_counter() - t1
        theirs = _distinct([t for t in theirs if max(robot.tool_error(t, pin.SE3(H))) <= 1e-6])
        if _same_set(ours, theirs):
            equal += 1
        else:
            differences.append({"pose": k, "kinelab": len(ours), "ssik": len(theirs)})
    return {"robot": robot.name, "poses": n, "equal": equal / n, "differences": differences,
            "kinelab_ms": 1e3 * t_ours / n, "ssik_ms": 1e3 * t_peer / n}


def _distinct(qs: list[np.ndarray]) -> list[np.ndarray]:
    kept: list[np.ndarray] = []
    for q in qs:
        if not any(np.abs(wrap_to_pi(q - k)).max() <= SAME_SET for k in kept):
            kept.append(q)
    return kept


def _same_set(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) == len(b) and all(any(np.abs(wrap_to_pi(x - y)).max() <= SAME_SET for y in b) for x in a)


def random_arms(arms: int, poses: int, seed: int) -> list[dict[str, Any]]:
    """Per search class, ``arms`` random arms (:func:`random_search_arm`) × ``poses`` seeded configurations in
    (−π, π]⁶: the share whose own configuration is among the kernel's roots (no limits), and the misses."""
    rows = []
    for pair in (0, 1):
        for shoulder in (0, 1, 2):
            rng = np.random.default_rng(seed + 10 * pair + shoulder)
            gaps, name = [], ""
            for _ in range(arms):
                h, o, tool = random_search_arm(rng, pair, shoulder)
                arm = classify_vectors(h, o, tool.rotation, tool.translation).arm
                assert arm is not None
                name = arm.mode
                for _ in range(poses):
                    q = rng.uniform(-np.pi, np.pi, 6)
                    Q, _, _ = arm_roots(arm, poe(h, o, tool, q), np.full(6, -10.0), np.full(6, 10.0), None)
                    gaps.append(float(np.abs(wrap_to_pi(Q - q)).max(axis=1).min()) if len(Q) else np.inf)
            g = np.array(gaps)
            rows.append({"class": name, "poses": g.size, "found": float((g <= FOUND).mean()),
                         "misses": int((g > FOUND).sum()), "near_misses": int(((g > FOUND) & (g <= NEAR)).sum())})
    return rows


def random_search_arm(rng: np.random.Generator, pair: int, shoulder: int) -> tuple[np.ndarray, np.ndarray, pin.SE3]:
    """Axes (6, 3), points on them (6, 3) [m] at q = 0 and a tool pose of a random 6R arm of a search class
    (pair 0: axes 4, 5 meeting; 1: axes 5, 6; shoulder 0: h₂ ∥ h₃; 1: axes 1, 2 meeting; 2: axes 2, 3)."""
    h = rng.normal(size=(6, 3))
    h /= np.linalg.norm(h, axis=1)[:, None]
    o = rng.uniform(-0.4, 0.4, (6, 3))
    if shoulder == 0:
        h[2] = h[1] * (1 if rng.random() < 0.5 else -1)
    else:
        i = shoulder - 1
        o[i + 1] = o[i] + rng.uniform(-0.2, 0.2) * h[i] + rng.uniform(-0.2, 0.2) * h[i + 1]
    a = 3 + pair
    o[a + 1] = o[a] + rng.uniform(-0.2, 0.2) * h[a] + rng.uniform(-0.2, 0.2) * h[a + 1]
    return h, o, pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.4, 0.4, 3))


def poe(h: np.ndarray, o: np.ndarray, tool: pin.SE3, q: np.ndarray) -> np.ndarray:
    """The 4 × 4 tool pose of the chain (axes h through points o at q = 0, tool pose ``tool``) at q [rad]."""
    M = np.eye(4)
    for i in range(len(q)):
        T = np.eye(4)
        T[:3, :3] = pin.exp3(h[i] * q[i])
        T[:3, 3] = o[i] - T[:3, :3] @ o[i]
        M = M @ T
    return np.asarray(M @ tool.homogeneous)


def run(robots: list[str] | None = None, n: int = 10_000, peer_n: int = 1000, arms: int = 30, arm_poses: int = 300,
        seed: int = 0, progress: bool = False) -> dict[str, Any]:
    """Every measure for the arms asked for (default ROBOTS) and the random arms."""
    names = list(robots or ROBOTS)
    own, peers = [], []
    for name in tqdm(names, desc="bench --completeness", disable=not progress, unit="arm"):
        robot = load(name)
        if classify(robot).arm is None and not has_swept_form(robot):
            continue
        own.append(own_configuration(robot, n, seed))
        if peer_n and (found := against_ssik(robot, peer_n, seed)) is not None:
            peers.append(found)
    return {"own": own, "ssik": peers, "random": random_arms(arms, arm_poses, seed)}


def markdown(result: dict[str, Any]) -> str:
    """The three tables."""
    lines = ["| arm | method | poses | own configuration found | misses (double roots) | branches mean / max |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['robot']} | {r['method']} | {r['poses']:,} | {100 * r['found']:.3f} % | {r['misses']} "
              f"({r['near_misses']}) | {r['branches_mean']:.2f} / {r['branches_max']} |" for r in result["own"]]
    if result["ssik"]:
        lines += ["", "| arm | poses | branch sets equal to ssik's | differences (kinelab, ssik) | kinelab | ssik |",
                  "|---|---|---|---|---|---|"]
        for r in result["ssik"]:
            shown = ", ".join("({kinelab}, {ssik})".format(**d) for d in r["differences"][:8]) or "none"
            lines.append(f"| {r['robot']} | {r['poses']:,} | {100 * r['equal']:.2f} % | {shown} | "
                         f"{r['kinelab_ms']:.2f} ms | {r['ssik_ms']:.1f} ms |")
    lines += ["", "| random arms of the class | poses | own configuration found | misses (double roots) |",
              "|---|---|---|---|"]
    lines += [f"| {r['class']} | {r['poses']:,} | {100 * r['found']:.3f} % | {r['misses']} ({r['near_misses']}) |"
              for r in result["random"]]
    return "\n".join(lines)
