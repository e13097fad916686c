"""Seed paper 000 (Danilov 2019): the ERA passing its singular points with FRDM, with and without bypass.

The paper's base frame has x0 along the vertical roll axis of the shoulder; in ``era.urdf`` that axis
is z. Each passage is a path of tool poses (base frame), a start configuration on it, and the bypass
the paper prescribes. :func:`run` tracks the path twice, without and with the bypass.

Passage 1, elbow reach (the paper's Fig. 6–8): the tool rises along the vertical axis until the elbow
links align, a little past full reach so that the arm stretches exactly straight, and comes back
down. Straight, with the target on its own line, every FRDM step is zero (Σ|Δq| = 0): the monitor
fires. Without bypass the arm stays straight while the target moves away, and then folds whichever
way rounding lets it; with the paper's bypass, a small δq on the central joint with a minus sign,
the elbow folds back the way it came and q3, q4, q5 stay each in its own quadrant.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from kinelab.ik.frdm.tracking import TrackResult, track
from kinelab.robot import Robot, load

FULL_REACH = 1.228 + 0.340 + 4.072 + 4.072 + 0.340 + 1.228  # [m] joint 1 to the tool, straight
ELBOW_FOLD = np.deg2rad(40.0)  # start: q3 = a, q4 = −2a, q5 = a keeps the tool on the vertical axis
OVERSHOOT = 0.05  # [m] the top of passage 1 lies this far past full reach: the arm ends exactly straight
KICK = 1e-2  # [rad] the paper's δq (> ε) on the central (elbow) joint


@dataclass
class Passage:
    """A path for the ERA with its start configuration and the paper's bypass."""

    name: str
    description: str
    targets: list[pin.SE3]
    q0: np.ndarray
    bypass: dict = field(default_factory=dict)
    unreachable: np.ndarray | None = None  # samples that lie beyond reach by design

    @property
    def samples(self) -> int:
        return len(self.targets)


@dataclass
class PassageRun:
    passage: Passage
    without: TrackResult
    with_bypass: TrackResult


def elbow_passage(robot: Robot | None = None, samples: int = 40) -> Passage:
    """Passage 1: up the vertical axis past full reach and back down, tool orientation fixed."""
    robot = robot or load("era")
    a = ELBOW_FOLD
    q0 = np.array([0.0, 0.0, a, -2 * a, a, 0.0, 0.0])
    z0 = robot.fk(q0).translation[2]
    top = FULL_REACH + OVERSHOOT
    heights = np.r_[np.linspace(z0, top, samples), np.linspace(top, z0, samples)[1:]]
    targets = [pin.SE3(np.eye(3), np.array([0.0, 0.0, z])) for z in heights]
    return Passage(
        name="elbow",
        description="tool up the vertical axis until the elbow links align, then back down",
        targets=targets,
        q0=q0,
        bypass={"kicks": {"joint4": -KICK}, "policy": ("kicks",)},
        unreachable=heights > FULL_REACH + 1e-9,
    )


def run(passage: Passage, robot: Robot | None = None, **options) -> PassageRun:
    """Track the passage without bypass and with the paper's bypass (FRDM, warm-started, no restarts)."""
    robot = robot or load("era")
    without = track(robot, passage.targets, passage.q0, policy=(), **options)
    with_bypass = track(robot, passage.targets, passage.q0, **passage.bypass, **options)
    return PassageRun(passage, without, with_bypass)


def quadrant_violations(result: TrackResult, passage: Passage) -> int:
    """Samples where q3, q4, q5 leave the quadrants of the start fold (q3 ≥ 0, q4 ≤ 0, q5 ≥ 0)."""
    signs = np.sign(passage.q0[2:5])
    tol = 1e-6
    return int(np.sum(np.any(result.q[:, 2:5] * signs < -tol, axis=1)))


# The paper's three kinds of ERA singularity, by the joint whose value defines each (kinelab's frames).
SINGULAR_KINDS = {"elbow reach": ("joint4", 0.0), "wrist gimbal lock": ("joint6", np.pi / 2),
                  "shoulder": ("joint2", np.pi / 2)}


def singular_examples(robot: Robot | None = None, seed: int = 0) -> dict[str, np.ndarray]:
    """One configuration per kind: the defining joint held at its value, the others moved onto the singular
    set (σ_min minimised). A 7R arm needs more than one condition to lose rank; the refinement finds it."""
    from kinelab.singular import refine

    robot = robot or load("era")
    rng = np.random.default_rng(seed)
    out = {}
    for kind, (joint, value) in SINGULAR_KINDS.items():
        j = robot.joint_index(joint)
        q = 0.5 * robot.random_q(rng)
        q[j] = value
        lower, upper = robot.lower.copy(), robot.upper.copy()
        lower[j] = upper[j] = value
        out[kind] = refine(robot, q, lower, upper)
    return out


def dls_tracking(passage: Passage, robot: Robot | None = None) -> dict[str, np.ndarray]:
    """The Pinocchio DLS reference along the same path, warm-started from the previous sample, no restarts."""
    import time

    from kinelab.ik import solve

    robot = robot or load("era")
    q = passage.q0
    rows, times, perr, rerr = [], [], [], []
    for target in passage.targets:
        t0 = time.perf_counter()
        res = solve(robot, target, solver="dls", q0=q, max_restarts=0, time_budget=1.0)
        times.append(time.perf_counter() - t0)
        q = res.q
        rows.append(q)
        perr.append(res.position_error)
        rerr.append(res.rotation_error)
    return {"q": np.array(rows), "wall_time": np.array(times), "position_error": np.array(perr),
            "rotation_error": np.array(rerr)}
