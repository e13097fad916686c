"""``kinelab bench --completeness``: does every-branch IK find every branch?

Two measures, per arm with a class (closed form or 1-D search, docs/analytic.md):

- **the pose's own configuration**: n seeded random configurations within the limits, their poses solved by
  :func:`~kinelab.ik.analytic.batch.all_branches_batch` (every branch judged by Pinocchio); the share of poses
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

from kinelab.errors import OptionError
from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.batch import all_branches_batch
from kinelab.ik.analytic.branches import arm_roots, certificate_of
from kinelab.ik.analytic.certify import chain_pose
from kinelab.ik.analytic.classify import classify, classify_vectors, general_class, general_vectors, line_distance
from kinelab.ik.analytic.general import roots_within
from kinelab.ik.analytic.kernel import GENERAL_6R
from kinelab.ik.analytic.redundancy import at_value, has_swept_form, swept_arm
from kinelab.ik.request import make_request
from kinelab.report.bench import hard_poses, sew
from kinelab.robot import Chain, load

FOUND = 1e-6  # [rad] the pose's own configuration is a branch to this
NEAR = 1e-4  # [rad] a miss nearer than this is a double root met to rounding's square root
SAME_SET = 1e-6  # [rad] two answers this close are one
ROBOTS = ("ur5", "ur10", "kinova", "z1", "xarm6", "crx10ia", "ur10e_calibrated", "general6r", "panda", "baxter_left")
HARD = ("xarm6", "crx10ia", "ur10e_calibrated", "general6r")  # the arms the hard poses are built for
HELD = (("tiago_pro", (0, 1, 2, 3, 4, 5, 6)), ("panda", (3,)), ("xarm7", (3,)))  # 7R arms and the joints held


def own_configuration(robot: Chain, n: int, seed: int) -> dict[str, Any]:
    """The share of n seeded poses whose own configuration is among the branches (6R arms: the batch; 7R arms:
    the branches at the held joint's own value), the share whose set is certified complete, the misses' nearest
    distances, and every missed pose's q."""
    Q = robot.random_qs(n, np.random.default_rng(seed))
    t0 = time.perf_counter()
    if _six(robot) is not None:
        batch = all_branches_batch(robot, robot.fk_batch(Q))
        gaps = np.nanmin(np.abs(wrap_to_pi(batch.q - Q[:, None, :])).max(axis=2), axis=1, initial=np.inf,
                         where=~np.isnan(batch.q[:, :, 0]))
        counts = batch.count
        elapsed = time.perf_counter() - t0
        certified = _certified(robot, Q, batch)
    else:
        sw, req = swept_arm(robot), make_request("frdm")
        found = [at_value(robot, robot.fk(q), req, float(q[sw.joint])) for q in Q]
        gaps = np.array([min((float(np.abs(wrap_to_pi(a[0] - q)).max()) for a in f), default=np.inf)
                         for f, q in zip(found, Q, strict=True)])
        counts = np.array([len(f) for f in found])
        elapsed, certified = time.perf_counter() - t0, None
    missed = gaps > FOUND
    return {"robot": robot.name, "method": _method(robot), "poses": n, "found": float(1 - missed.mean()),
            "misses": int(missed.sum()), "near_misses": int((missed & (gaps <= NEAR)).sum()),
            "certified": certified, "missed": [{"q": Q[k].tolist(), "nearest": float(gaps[k])}
                                               for k in np.flatnonzero(missed)],
            "branches_mean": float(np.mean(counts)), "branches_max": int(np.max(counts)), "seconds": elapsed}


def _six(robot: Chain) -> Any:
    """The 6R arm's class or general elimination, None for a 7R arm swept."""
    return classify(robot).arm or (general_class(robot).arm if not has_swept_form(robot) else None)


def _certified(robot: Chain, Q: np.ndarray, batch: Any) -> float:
    """The share of the poses of Q whose set of branches (``batch``) is certified complete, by the certificate
    ``Branches.complete`` gives the same set (docs/analytic.md, Certificates)."""
    if batch.uncertified is not None:  # the elimination said it per pose
        return sum(why == "" for why in batch.uncertified) / Q.shape[0]
    H, certified = robot.fk_batch(Q), 0
    for b in range(Q.shape[0]):
        k = int(batch.count[b])
        certified += certificate_of(robot, batch.method, H[b], batch.q[b, :k], batch.found[b, :k],
                                    batch.free[b, :k])[0] == "certified"
    return certified / Q.shape[0]


def _method(robot: Chain) -> str:
    arm = _six(robot)
    if arm is not None:
        return str(arm.mode)
    sw = swept_arm(robot)
    return f"joint {sw.joint + 1} held: {sw.arm.mode}"


SSIK_GENERAL = 100  # poses against ssik for an arm of the general elimination: ssik's route there took 40-460 ms


def against_ssik(robot: Chain, n: int, seed: int) -> dict[str, Any] | None:
    """kinelab's branch sets against ssik's for n seeded poses of the same URDF, or None without ssik or a
    6-joint class."""
    try:
        import ssik
    except ImportError:
        return None
    if _six(robot) is None or robot.urdf_path is None:
        return None

    if _six(robot).kind == GENERAL_6R:
        n = min(n, SSIK_GENERAL)
    peer = ssik.Manipulator.from_urdf(str(robot.urdf_path), base=robot.base, ee=robot.tool)
    rng = np.random.default_rng(seed + 1)
    equal, differences, t_ours, t_peer = 0, [], 0.0, 0.0
    for k in range(n):
        ours, theirs, times = _both_sets(robot, peer, robot.fk(robot.random_q(rng)).homogeneous)
        t_ours, t_peer = t_ours + times[0], t_peer + times[1]
        if _same_set(ours, theirs):
            equal += 1
        else:
            differences.append({"pose": k, "kinelab": len(ours), "ssik": len(theirs)})
    return {"robot": robot.name, "poses": n, "equal": equal / n, "differences": differences,
            "kinelab_ms": 1e3 * t_ours / n, "ssik_ms": 1e3 * t_peer / n}


def _both_sets(robot: Chain, peer: Any,
               H: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], tuple[float, float]]:
    """kinelab's branches of the pose H (4 × 4, base frame) and ssik's that Pinocchio confirms to 1e-6 (distinct),
    and the two calls' times [s]."""
    t0 = time.perf_counter()
    ours = [np.asarray(a) for a in all_branches_batch(robot, H[None]).q[0] if not np.isnan(a[0])]
    t1 = time.perf_counter()
    theirs = [np.asarray(s.q, dtype=float) for s in peer.solve(H, respect_limits=True, enumerate_windings=False)]
    times = (t1 - t0, time.perf_counter() - t1)
    return ours, _distinct([t for t in theirs if max(robot.tool_error(t, pin.SE3(H))) <= 1e-6]), times


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
                    H = chain_pose(h, o, tool.rotation, tool.translation, q)
                    Q, _, _ = arm_roots(arm, H, np.full(6, -10.0), np.full(6, 10.0), None)
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


def random_general_arm(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, pin.SE3]:
    """Axes (6, 3), points on them (6, 3) [m] at q = 0 and a tool pose of a random general 6R arm: every axis
    direction uniform on the sphere, every point uniform in a 0.8 m cube, no two axes parallel or meeting (to
    1e-3 rad and 1e-3 m: redrawn otherwise), the tool at a random pose."""
    while True:
        h = rng.normal(size=(6, 3))
        h /= np.linalg.norm(h, axis=1)[:, None]
        o = rng.uniform(-0.4, 0.4, (6, 3))
        pairs = [(i, j) for i in range(6) for j in range(i + 1, 6)]
        if all(np.linalg.norm(np.cross(h[i], h[j])) > 1e-3 and line_distance(o[i], h[i], o[j], h[j]) > 1e-3
               for i, j in pairs):
            return h, o, pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.4, 0.4, 3))


def held_joint(robot: Chain, joint: int, n: int, seed: int) -> dict[str, Any]:
    """n seeded poses of a 7R arm with joint ``joint`` held at the pose's own value: the share whose own
    configuration is among the branches, the poses refused (the six left solved by nothing here at that value),
    and every miss's q."""
    Q, req = robot.random_qs(n, np.random.default_rng(seed + joint)), make_request("frdm")
    found = refused = 0
    missed: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    for q in Q:
        try:
            answers = at_value(robot, robot.fk(q), req, float(q[joint]), None, joint)
        except OptionError:
            refused += 1
            continue
        gap = min((float(np.abs(wrap_to_pi(a[0] - q)).max()) for a in answers), default=np.inf)
        found += gap <= FOUND
        if gap > FOUND:
            missed.append({"q": q.tolist(), "nearest": gap})
    return {"robot": robot.name, "joint": joint + 1, "poses": n, "found": found / n, "refused": refused,
            "missed": missed, "seconds": time.perf_counter() - t0}


def random_general(arms: int, poses: int, seed: int) -> dict[str, Any]:
    """``arms`` random general 6R arms (:func:`random_general_arm`) × ``poses`` seeded configurations in (−π, π]⁶:
    the share whose own configuration is among the elimination's roots (no limits), the certified share, the arms
    the elimination refuses, and every missed pose (arm index, q)."""
    rng = np.random.default_rng(seed + 100)
    found = certified = total = refused = 0
    missed: list[dict[str, Any]] = []
    wide = np.full(6, 10.0)
    for index in range(arms):
        h, o, tool = random_general_arm(rng)
        arm = general_vectors(h, o, tool.rotation, tool.translation).arm
        if arm is None:
            refused += 1
            continue
        for _ in range(poses):
            q = rng.uniform(-np.pi, np.pi, 6)
            H = chain_pose(h, o, tool.rotation, tool.translation, q)
            Q, _, _, reason = roots_within(arm, H, -wide, wide, None, 1e-6)
            gap = float(np.abs(wrap_to_pi(Q - q)).max(axis=1).min()) if len(Q) else np.inf
            total, found, certified = total + 1, found + (gap <= FOUND), certified + (reason == "")
            if gap > FOUND:
                missed.append({"arm": index, "q": q.tolist(), "nearest": gap, "reason": reason})
    return {"arms": arms, "refused": refused, "poses": total, "found": found / max(total, 1),
            "certified": certified / max(total, 1), "missed": missed}


def run(robots: list[str] | None = None, n: int = 10_000, peer_n: int = 1000, arms: int = 30, arm_poses: int = 300,
        seed: int = 0, progress: bool = False, hard: int = 1000, general_poses: int = 1000,
        held_poses: int = 1000, sew_poses: int = 200) -> dict[str, Any]:
    """Every measure for the arms asked for (default ROBOTS), the random arms of each search class and random
    general arms, ``hard`` poses per arm of HARD (:mod:`kinelab.report.bench.hard_poses`), ``held_poses`` per
    joint of HELD and ``sew_poses`` per 7R arm at its SEW angle (:mod:`kinelab.report.bench.sew`)."""
    names = list(robots or ROBOTS)
    own, peers, built = [], [], []
    for name in tqdm(names, desc="bench --completeness", disable=not progress, unit="arm"):
        robot = load(name)
        if _six(robot) is None and not has_swept_form(robot):
            continue
        own.append(own_configuration(robot, n, seed))
        peers += _ssik_rows(robot, peer_n, seed)
        built += [hard_poses.measure(robot, hard, seed)] if hard and name in HARD else []
    return {"own": own, "ssik": peers, "random": random_arms(arms, arm_poses, seed),
            "general": random_general(arms, general_poses, seed), "hard": built,
            "held": _held_rows(robots, held_poses, seed), "sew": _sew_rows(robots, sew_poses, seed)}


def _held_rows(robots: list[str] | None, poses: int, seed: int) -> list[dict[str, Any]]:
    """A row per joint of HELD (its arms among ``robots``, None: all), ``poses`` poses each (0: none)."""
    return [held_joint(load(name), joint, poses, seed) for name, joints in HELD for joint in joints
            if poses and (robots is None or name in robots)]


def _sew_rows(robots: list[str] | None, poses: int, seed: int) -> list[dict[str, Any]]:
    """A row per 7R arm at its SEW angle (its arms among ``robots``, None: all), ``poses`` poses each (0: none)."""
    return [sew.measure(load(name), poses, seed) for name in sew.ARMS if poses and (robots is None or name in robots)]


def _ssik_rows(robot: Chain, n: int, seed: int) -> list[dict[str, Any]]:
    """The robot's row against ssik (:func:`against_ssik`), or none (n = 0, no ssik, no 6-joint class)."""
    found = against_ssik(robot, n, seed) if n else None
    return [] if found is None else [found]


def markdown(result: dict[str, Any]) -> str:
    """The tables."""
    lines = _own_lines(result["own"]) + _ssik_lines(result["ssik"]) + _random_lines(result["random"])
    lines += _general_lines(result.get("general")) + _hard_lines(result.get("hard", []))
    lines += _held_lines(result.get("held", [])) + sew.markdown(result.get("sew", [])) + _missed_lines(result["own"])
    return "\n".join(lines)


def _own_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The registered arms' table: own configuration found, misses, certified share, branches."""
    return ["| arm | method | poses | own configuration found | misses (double roots) | certified complete | "
            "branches mean / max |", "|---|---|---|---|---|---|---|"] + [
        f"| {r['robot']} | {r['method']} | {r['poses']:,} | {100 * r['found']:.3f} % | {r['misses']} "
        f"({r['near_misses']}) | {_share(r.get('certified'))} | {r['branches_mean']:.2f} / {r['branches_max']} |"
        for r in rows]


def _ssik_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The table against ssik (none without rows)."""
    if not rows:
        return []
    lines = ["", "| arm | poses | branch sets equal to ssik's | differences (kinelab, ssik) | kinelab | ssik |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        shown = ", ".join("({kinelab}, {ssik})".format(**d) for d in r["differences"][:8]) or "none"
        lines.append(f"| {r['robot']} | {r['poses']:,} | {100 * r['equal']:.2f} % | {shown} | "
                     f"{r['kinelab_ms']:.2f} ms | {r['ssik_ms']:.1f} ms |")
    return lines


def _random_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The random arms' table, a row per search class (none without rows)."""
    if not rows:
        return []
    return ["", "| random arms of the class | poses | own configuration found | misses (double roots) |",
            "|---|---|---|---|"] + [f"| {r['class']} | {r['poses']:,} | {100 * r['found']:.3f} % | {r['misses']} "
                                    f"({r['near_misses']}) |" for r in rows]


def _general_lines(g: dict[str, Any] | None) -> list[str]:
    """The random general 6R arms' one-row table (none without them)."""
    if not g:
        return []
    return ["", "| random general 6R arms | poses | own configuration found | certified complete | refused |",
            "|---|---|---|---|---|",
            f"| {g['arms']} arms | {g['poses']:,} | {100 * g['found']:.3f} % | {100 * g['certified']:.2f} % | "
            f"{g['refused']} |"]


def _held_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The 7R arms' table, a row per held joint (none without rows)."""
    if not rows:
        return []
    return ["", "| 7R arm | joint held | poses | own configuration found | refused (no solver for the six) |",
            "|---|---|---|---|---|"] + [f"| {r['robot']} | {r['joint']} | {r['poses']:,} | {100 * r['found']:.3f} % "
                                        f"| {r['refused']} |" for r in rows]


def _missed_lines(own: list[dict[str, Any]]) -> list[str]:
    """The first 50 missed poses of the registered arms: each own configuration and its nearest branch [rad]."""
    missed = [(r["robot"], m) for r in own for m in r.get("missed", [])]
    if not missed:
        return []
    return ["", "Missed poses (arm: own configuration q, nearest branch):"] + [
        f"- {name}: q = ({', '.join(f'{v:.6f}' for v in m['q'])}), {m['nearest']:.1e} rad" for name, m in missed[:50]]


def _share(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:.2f} %"


def _hard_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The hard poses' table: per arm and kind, the own configuration found, answered by a neighbouring root only,
    certified and uncertified sets, and the failures (not found, certified or a neighbour's)."""
    if not rows:
        return []
    lines = ["", "| arm | hard poses | own configuration found | answered by a merged root (found ≥ 2) | silently "
             "by a neighbour | certified | said uncertified |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines += [f"| {r['robot']} | {kind}: {k['poses']} | {k['own']} | {k['merged']} | {k['neighbour']} | "
                  f"{k['certified']} | {k['uncertified']} |" for kind, k in r["kinds"].items()]
    for r in rows:
        lines += [f"- {r['robot']} ({f['kind']}): q = ({', '.join(f'{v:.6f}' for v in f['q'])}), nearest answer "
                  f"{f['nearest']:.1e} rad, {'certified' if f['certified'] else 'uncertified'}"
                  for f in r["failures"][:20]]
    return lines
