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

Passages 2 and 3 happen at the arm's two gimbal locks, where a roll axis lines up with another joint
axis. The ERA is redundant (7R), so neither lock costs it a tool direction on its own; what the lock
creates is a spin of a link group that leaves the tool where it is (a null motion). FRDM, warm-started
sample after sample, drifts along that spin as the tool moves, and the angles add up: the paper's
"summing of angles" (Fig. 10) and "linear increase of the angles in opposite joints" (Fig. 13). A
single straight pass through either lock is smooth on this model (the wrist is not spherical: J5 and
J7 are 0.34 m apart), so kinelab moves the tool round a closed path inside the lock, lap after lap,
where the drift shows as a joint path that does not close.

Passage 2, wrist gimbal lock (Fig. 9–11): q6 = 90° puts the tool roll axis J7 parallel to J5 (and to
J3, J4): the wrist circles in the arm's vertical plane (bottom-up and back each lap), tool orientation
fixed. Without bypass q5 and q7 wind in opposite senses lap after lap; with the paper's intervals
q5, q6 < 80° held along the path the joint path closes after the first lap. (The paper's other option,
q1 frozen, does nothing here: q1 takes no part in this spin.)

Passage 3, shoulder (Fig. 12–14): the tool, pointing down, circles the vertical roll axis J1 with the
wrist above the base, so J7 lines up with J1. Without bypass the whole arm turns with the tool: q1 and
q7 climb together, about 81° per lap, until q1 meets its ±180° stop and the arm swings back a full
turn in one sample. With q1 (or q7) frozen the joint path closes every lap.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from kinelab.analysis.families import refine
from kinelab.geometry import wrap_to_pi
from kinelab.ik import solve
from kinelab.ik.api import track
from kinelab.ik.frdm import solver
from kinelab.ik.result import TrackResult
from kinelab.robot import Chain, load

FULL_REACH = 1.228 + 0.340 + 4.072 + 4.072 + 0.340 + 1.228  # [m] joint 1 to the tool, straight
ELBOW_FOLD = np.deg2rad(40.0)  # start: q3 = a, q4 = −2a, q5 = a keeps the tool on the vertical axis
OVERSHOOT = 0.05  # [m] the top of passage 1 lies this far past full reach: the arm ends exactly straight
KICK = 1e-2  # [rad] the paper's δq (> ε) on the central (elbow) joint
WRIST_LOCK = np.deg2rad([0.0, 0.0, 30.0, 60.0, 0.0, 90.0, 0.0])  # q6 = 90°: J7 ∥ J5 ∥ J4 ∥ J3
WRIST_LIMIT = np.deg2rad(80.0)  # the paper's bypass: q5, q6 < 80°
SHOULDER_LOCK = np.deg2rad([0.0, 0.0, -55.0, 110.0, 125.0, 0.0, 0.0])  # tool down on the J1 axis: J7 ∥ J1
# The study tracks with w_p = 10/L² (the solver's one-shot default is 3/L², tuned for speed). The spin
# of passages 2 and 3 grows with the position weight (shoulder, first lap: about 14° at 1/L², 31° at 3/L²,
# 81° at 10/L²): each exact step trades position against orientation, and the heavier the position, the
# further a step turns the arm. The figures in the docs are for this setting. The study is of the paper's
# method: FRDM's sweeps alone (finish="none"; the Newton finish would hide the drift it studies).
# A jump is a joint turning more than 0.3 rad in a sample: the elbow passage turns one 0.21 rad at the straight arm
# with the bypass, which the paper reads as smooth (kinelab's default jump_limit, 0.2 rad, would mark it).
TRACK_OPTIONS = {"w_p_factor": 10.0, "finish": "none", "jump_limit": 0.3}


@dataclass
class Passage:
    """A path for the ERA with its start configuration and the paper's bypass."""

    name: str
    description: str
    targets: list[pin.SE3]
    q0: np.ndarray
    bypass: dict = field(default_factory=dict)
    unreachable: np.ndarray | None = None  # samples that lie beyond reach by design
    lap: int | None = None  # samples per lap of a closed path (sample k·lap is the start pose again)
    q0_bypass: np.ndarray | None = None  # the start under the bypass's restrictions, when q0 breaks them

    @property
    def samples(self) -> int:
        """Path samples."""
        return len(self.targets)


@dataclass
class PassageRun:
    """One passage tracked without and with the paper's bypass."""
    passage: Passage
    without: TrackResult
    with_bypass: TrackResult


def elbow_passage(robot: Chain | None = None, samples: int = 40) -> Passage:
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


def _circle(oMstart: pin.SE3, radius: float, plane: tuple, samples: int, laps: int) -> list[pin.SE3]:
    """Tool poses round a circle of ``radius`` [m] in the plane (u, v) that starts at oMstart, orientation
    fixed; ``samples`` per lap, the last pose closing the last lap."""
    u, v = (np.asarray(a, float) for a in plane)
    phi = np.linspace(0.0, 2 * np.pi * laps, samples * laps + 1)
    centre = oMstart.translation - radius * u
    return [pin.SE3(oMstart.rotation, centre + radius * (np.cos(p) * u + np.sin(p) * v)) for p in phi]


def wrist_passage(robot: Chain | None = None, radius: float = 0.35, samples: int = 60, laps: int = 4) -> Passage:
    """Passage 2: at q6 = 90° the wrist circles in the arm's vertical plane (y, z), tool orientation fixed."""
    robot = robot or load("era")
    targets = _circle(robot.fk(WRIST_LOCK), radius, ((0, 1, 0), (0, 0, 1)), samples, laps)
    j5, j6 = robot.joint_index("joint5"), robot.joint_index("joint6")
    intervals = {"joint5": (robot.lower[j5], WRIST_LIMIT), "joint6": (robot.lower[j6], WRIST_LIMIT)}
    start = solver.attempt(robot, targets[0], WRIST_LOCK, 1e-9, 1e-9, np.inf, intervals=intervals,
                           active=("intervals",), max_sweeps=3000, stall_window=200, stall_rel=1e-9)
    return Passage(
        name="wrist",
        description=f"wrist in the gimbal lock (q6 = 90°) on a {radius} m circle in the arm plane, {laps} laps",
        targets=targets,
        q0=WRIST_LOCK.copy(),
        bypass={"intervals": intervals, "restrict": ("intervals",)},
        lap=samples,
        q0_bypass=start.q,
    )


def shoulder_passage(robot: Chain | None = None, radius: float = 0.5, samples: int = 72, laps: int = 3,
                     frozen: str = "joint1") -> Passage:
    """Passage 3: the tool, pointing down, circles the vertical roll axis J1 (J7 ∥ J1), orientation fixed."""
    robot = robot or load("era")
    oMlock = robot.fk(SHOULDER_LOCK)
    oMstart = pin.SE3(oMlock.rotation, oMlock.translation + np.array([radius, 0.0, 0.0]))
    targets = _circle(oMstart, radius, ((1, 0, 0), (0, 1, 0)), samples, laps)
    start = solver.attempt(robot, targets[0], SHOULDER_LOCK, 1e-9, 1e-9, np.inf, max_sweeps=3000,
                           stall_window=200, stall_rel=1e-9)
    return Passage(
        name="shoulder",
        description=f"tool on a {radius} m circle round the vertical axis J1, {laps} laps, {frozen} frozen",
        targets=targets,
        q0=start.q,
        bypass={"freeze": {frozen: None}, "restrict": ("freeze",)},
        lap=samples,
    )


PASSAGES: dict[str, Callable[..., Passage]] = {"elbow": elbow_passage, "wrist": wrist_passage,
                                               "shoulder": shoulder_passage}


def run(passage: Passage, robot: Chain | None = None, **options) -> PassageRun:
    """Track the passage without bypass and with the paper's bypass (FRDM, warm-started, no restarts).

    ``options`` go to :func:`~kinelab.ik.frdm.tracking.track`; the study's default weighting is
    ``TRACK_OPTIONS`` (see there)."""
    robot = robot or load("era")
    options = {**TRACK_OPTIONS, **options}
    without = track(robot, passage.targets, q0=passage.q0, policy=(), **options)
    q0 = passage.q0 if passage.q0_bypass is None else passage.q0_bypass
    with_bypass = track(robot, passage.targets, q0=q0, **passage.bypass, **options)
    return PassageRun(passage, without, with_bypass)


def lap_changes(result: TrackResult, passage: Passage) -> np.ndarray:
    """q at the end of each lap minus q at its start, one row per lap, each taken modulo 2π into (−π, π] [rad]:
    zero rows = a closed path. (A joint climbing past its ±π limit is turned back by a whole turn: its raw
    difference would read 81.4° − 360° = −278.6°.)"""
    ends = result.q[:: passage.lap]
    return wrap_to_pi(np.diff(ends, axis=0))


def quadrant_violations(result: TrackResult, passage: Passage) -> int:
    """Samples where q3, q4, q5 leave the quadrants of the start fold (q3 ≥ 0, q4 ≤ 0, q5 ≥ 0)."""
    signs = np.sign(passage.q0[2:5])
    tol = 1e-6
    return int(np.sum(np.any(result.q[:, 2:5] * signs < -tol, axis=1)))


# The paper's three kinds of ERA singularity, by the joint whose value defines each (kinelab's frames).
SINGULAR_KINDS = {"elbow reach": ("joint4", 0.0), "wrist gimbal lock": ("joint6", np.pi / 2),
                  "shoulder": ("joint2", np.pi / 2)}


def singular_examples(robot: Chain | None = None, seed: int = 0) -> dict[str, np.ndarray]:
    """One configuration per kind: the defining joint held at its value, the others moved onto the singular
    set (σ_min minimised). A 7R arm needs more than one condition to lose rank; the refinement finds it."""
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


def dls_tracking(passage: Passage, robot: Chain | None = None) -> TrackResult:
    """The Pinocchio DLS reference along the same path, warm-started from the previous sample, no restarts."""
    robot = robot or load("era")
    q = passage.q0
    rows, times, perr, rerr, status, iters = [], [], [], [], [], []
    for target in passage.targets:
        t0 = time.perf_counter()
        res = solve(robot, target, solver="dls", q0=q, max_restarts=0, time_budget=1.0)
        times.append(time.perf_counter() - t0)
        q = res.q
        rows.append(q)
        perr.append(res.position_error)
        rerr.append(res.rotation_error)
        status.append(res.status.code)
        iters.append(res.iterations)
    return TrackResult(np.array(rows), np.array(perr), np.array(rerr), np.array(status, dtype=np.int8),
                       np.array(iters), np.array(times))


def tracking_bench(repeats: int = 3, robot: Chain | None = None) -> dict:
    """Per-sample cost along the three passages: FRDM with the paper's bypass against the Pinocchio DLS
    reference, both warm-started from the previous sample with no restarts. Each run is repeated and
    every sample keeps its fastest time (the runs are deterministic, so the work is the same).

    Returns {"rows": [{"passage", "solver", "samples", "reached", "median_us", "p95_us",
    "max_position_error_m" (reachable samples), "max_joint_step", "max_lap_change"}]}."""
    robot = robot or load("era")
    rows = []
    for name, build in PASSAGES.items():
        passage = build(robot)
        reach = np.ones(passage.samples, bool) if passage.unreachable is None else ~passage.unreachable
        frdm_runs = [run(passage, robot).with_bypass for _ in range(repeats)]
        dls_runs = [dls_tracking(passage, robot) for _ in range(repeats)]
        for label, runs in (("frdm+bypass", frdm_runs), ("dls", dls_runs)):
            last = runs[-1]
            times = np.min([r.wall_time for r in runs], axis=0) * 1e6
            laps = lap_changes(last, passage)[1:] if passage.lap else np.zeros((0, 1))
            reached = (last.position_error <= 1e-6) & (last.rotation_error <= 1e-6) & reach
            rows.append({
                "passage": name, "solver": label, "samples": passage.samples, "reached": int(reached.sum()),
                "reachable": int(reach.sum()),
                "median_us": float(np.median(times)), "p95_us": float(np.percentile(times, 95)),
                "max_position_error_m": float(last.position_error[reach].max()),
                "max_joint_step": last.max_joint_step,
                "max_lap_change": float(np.abs(laps).max()) if laps.size else None,
            })
    return {"rows": rows}


def tracking_markdown(result: dict) -> str:
    """The tracking bench as a Markdown table."""
    lines = ["| ERA passage | solver | reached | median per sample | p95 | worst error | largest joint step | "
             "lap change (after the 1st) |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lap = "—" if r["max_lap_change"] is None else f"{r['max_lap_change']:.1e} rad"
        lines.append(f"| {r['passage']} | {r['solver']} | {r['reached']}/{r['reachable']} | {r['median_us']:.0f} µs | "
                     f"{r['p95_us']:.0f} µs | {r['max_position_error_m']:.1e} m | {r['max_joint_step']:.3f} | {lap} |")
    return "\n".join(lines)
