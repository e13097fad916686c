"""``kinelab bench --paths``: the path followers on joint-space curves inside the limits.

Per arm (panda, xarm7, era, baxter_left, kinova) 50 paths of 400 samples, straight joint-space lines and cosine
blends in turn (:func:`~kinelab.report.bench.protocol.joint_line`, :func:`~kinelab.report.bench.protocol.cosine_path`;
path k from seed k), feasible by construction; their tool poses are the targets, the path's first configuration the
start. Each follower runs every path, the two in turn per path (which goes first alternating): kinelab's default
(:func:`kinelab.track`, FRDM's compiled follower) and the whole-body step (``follower="step"``). A path counts when
every sample is met (judged as :func:`kinelab.track` judges, within the limits), no joint step is above 3 × the
path's own largest step, and no sample is nearer a joint limit than the path's by more than 0.1 rad. Beside it, the
trust issues' Panda path (a 2,000-sample cosine blend from seed 4, solve seed 3).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from tqdm import tqdm

from kinelab.report.bench.protocol import cosine_path, joint_line
from kinelab.robot import Chain
from kinelab.robot.loading import load
from kinelab.wholebody.api import track

ARMS = ("panda", "xarm7", "era", "baxter_left", "kinova")
FOLLOWERS = {"default": {}, "step": {"follower": "step"}}
STEP_RATIO, CLOSER = 3.0, 0.1  # a jump: a joint step above 3 × the path's; a drift: 0.1 rad nearer a limit


def verdict(robot: Chain, path: np.ndarray, res: Any) -> tuple[bool, float, float]:
    """(every sample met, the largest joint step over the path's, how much nearer a limit than the path [rad])."""
    q = np.nan_to_num(res.q, nan=1e9)
    own = float(np.abs(np.diff(path, axis=0)).max())
    steps = float(np.abs(np.diff(np.vstack([path[:1], q]), axis=0)).max())
    margin = np.minimum(path - robot.lower, robot.upper - path).min(axis=1)
    kept = np.minimum(q - robot.lower, robot.upper - q).min(axis=1)
    return bool(np.all(res.success)), steps / own, float((margin - kept).max())


def run(robots: list[str] | None = None, count: int = 50, samples: int = 400, progress: bool = False
        ) -> dict[str, Any]:
    """Every arm's figures per follower (see the module's docstring)."""
    names = [r for r in (robots or ARMS) if r in ARMS] or list(ARMS)
    rows = [row for name in names for row in _arm(name, count, samples, progress)]
    return {"paths_per_arm": count, "samples": samples, "rows": rows, "trust": _trust()}


def _arm(name: str, count: int, samples: int, progress: bool) -> list[dict[str, Any]]:
    """One arm's rows, a follower each."""
    robot = load(name)
    seen: dict[str, dict[str, list[float]]] = {f: {"good": [], "met": [], "step": [], "closer": [], "us": []}
                                               for f in FOLLOWERS}
    for k in tqdm(range(count), desc=f"paths {name}", disable=not progress, unit="path"):
        rng = np.random.default_rng(k)
        path = joint_line(robot, rng, samples) if k % 2 == 0 else cosine_path(robot, rng, samples)
        targets = robot.fk_batch(path)
        order = list(FOLLOWERS) if k % 2 == 0 else list(FOLLOWERS)[::-1]
        for follower in order:
            t0 = time.perf_counter()
            res = track(robot, targets, q0=path[0], seed=k, **FOLLOWERS[follower])
            us = 1e6 * (time.perf_counter() - t0) / samples
            met, step, closer = verdict(robot, path, res)
            rec = seen[follower]
            rec["good"].append(met and step <= STEP_RATIO and closer <= CLOSER)
            rec["met"].append(met)
            rec["step"].append(step)
            rec["closer"].append(closer)
            rec["us"].append(us)
    return [{"robot": name, "follower": f, "paths": count, "good": int(sum(r["good"])), "met": int(sum(r["met"])),
             "jumps": int(sum(s > STEP_RATIO for s in r["step"])), "drifts": int(sum(c > CLOSER for c in r["closer"])),
             "worst_step": max(r["step"]), "worst_closer": max(r["closer"]), "us_per_sample": float(np.median(r["us"]))}
            for f, r in seen.items()]


def _trust() -> dict[str, Any]:
    """The trust issues' Panda path with each follower: samples met, the step ratio, how much nearer a limit."""
    panda = load("panda")
    path = cosine_path(panda, np.random.default_rng(4))
    out = {}
    for follower, kwargs in FOLLOWERS.items():
        res = track(panda, panda.fk_batch(path), q0=path[0], seed=3, **kwargs)
        _, step, closer = verdict(panda, path, res)
        out[follower] = {"met": int(np.sum(res.success)), "samples": len(path), "step": step, "closer": closer}
    return out


def markdown(result: dict[str, Any]) -> str:
    """The table per arm and follower, then the trust path."""
    lines = [f"Path followers, {result['paths_per_arm']} paths of {result['samples']} samples per arm (lines and "
             "cosine blends); a path is good when every sample is met, no joint step is above 3 × the path's and no "
             "sample is more than 0.1 rad nearer a limit than the path's. Goal: ≥ 99 % good with the default.", "",
             "| arm | follower | good | every sample met | jumps | drifts | worst step | worst drift | µs/sample |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['robot']} | {r['follower']} | {r['good']}/{r['paths']} | {r['met']} | {r['jumps']} | "
                     f"{r['drifts']} | {r['worst_step']:.1f}× | {r['worst_closer']:.2f} rad | "
                     f"{r['us_per_sample']:.0f} |")
    lines += ["", "The trust issues' Panda path (2,000 samples):", ""]
    for follower, t in result["trust"].items():
        lines.append(f"- {follower}: {t['met']}/{t['samples']} samples met, largest step {t['step']:.1f}× the path's, "
                     f"{max(t['closer'], 0.0):.2f} rad nearer a limit at worst")
    return "\n".join(lines)
