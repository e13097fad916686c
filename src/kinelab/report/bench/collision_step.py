"""``kinelab bench --collisions-step``: the whole-body step holding collisions, side by side with mink's
``CollisionAvoidanceLimit`` (MuJoCo's geoms) and pink's ``SelfCollisionBarrier`` (coal through Pinocchio), on the
same robot, obstacles, tasks and limits.

Scenes: the Panda (its whole file) with a table under its hand and a post beside it; TALOS with ten spheres on the
paths of its hands, its feet and centre of mass held. Each hand turns on a 10 cm circle (one turn in 2 s) that runs
into the obstacles, dt = 5 ms, from a start clear of every pair (the Panda's: the whole-body bench's start,
:mod:`kinelab.report.bench.steppers`; TALOS's: standing in its half-sitting configuration); costs,
posture, damping, DAQP and the position and velocity limits as that bench's. Collisions: every robot pair (less
adjacent ones, the SRDF's disabled pairs and those nearer than the margin at the neutral configuration, for kinelab
and pink; mink's own filter — same or welded bodies, parent and child — on every robot geom) and every robot object
against every obstacle, margin 1 cm, detection 5 cm, gain 0.5 (mink's gain and distances the same; pink's barrier
with d_min = the margin, on kinelab's pairs). The geometry: convex hulls of the same meshes (kinelab's and pink's by
qhull, MuJoCo's its own).

Per step: the library's step and integration time; after it, every kinelab pair's distance by coal at the library's
configuration (mink's mapped by joint name), the least less the margin (a penetration: below −1e-4 m), and the
tracking error. The libraries are interleaved per step, in a rotating order; each keeps its own configuration.
"""

from __future__ import annotations

import importlib.util
import re
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.collision import Collisions, Environment, Obstacle
from kinelab.errors import KinelabError
from kinelab.report.bench.peers import PeerFailedError, last_line
from kinelab.report.bench.steppers import (
    DAMPING,
    DT,
    SCENARIOS,
    KinelabStepper,
    MinkStepper,
    PinkStepper,
    start_of,
    targets_at,
    whole,
)
from kinelab.robot.tree import Robot
from kinelab.wholebody import Limits, StepOptions, WholeBody
from kinelab.wholebody.clearance import StepCollisions, step_collisions

MARGIN, DETECTION, GAIN = 0.01, 0.05, 0.5
RADIUS, PERIOD = 0.10, 2.0  # [m], [s] each hand's circle
PENETRATION = 1e-4  # [m] below the margin by more than this: a penetration


@dataclass(frozen=True)
class Scene:
    """A whole-body scenario's robot with obstacles placed about its hands' start."""

    name: str
    spheres_per_hand: int  # spheres on each hand's circle (0: the Panda's table and post)


SCENES = {"panda": Scene("panda", 0), "talos": Scene("talos", 5)}


def obstacles(scene: Scene, robot: Robot, q0: np.ndarray) -> Environment:
    """The scene's obstacles (world frame): the Panda's table 3 cm under its hand and a post 8 cm beside it;
    TALOS's spheres (3 cm) on its hands' circles, spread over the part of the turn 16 cm or more from the start."""
    hands = SCENARIOS[scene.name].moving
    placed = robot.frame_placements(q0, hands)
    if scene.spheres_per_hand == 0:
        p = placed[0].translation
        return Environment((Obstacle("box", (0.6, 0.6, 0.04), xyz=(p[0], p[1], p[2] - 0.07), name="table"),
                            Obstacle("capsule", (0.03, 0.5), xyz=(p[0], p[1] + 0.11, p[2]), name="post")))
    out = []
    for k, M in enumerate(placed):
        for j in range(scene.spheres_per_hand):
            a = np.pi * (0.6 + 0.8 * j / max(scene.spheres_per_hand - 1, 1))
            centre = M.translation + M.rotation @ np.array([0.0, RADIUS * (np.cos(a) - 1.0), RADIUS * np.sin(a)])
            out.append(Obstacle("sphere", (0.03,), xyz=tuple(centre), name=f"ball {k}.{j}"))
    return Environment(tuple(out))


class KinelabCollisionStepper(KinelabStepper):
    """kinelab's step with ``Limits(collisions=...)``."""

    def __init__(self, robot: Robot, scene: Any, q0: np.ndarray, collisions: Collisions):
        super().__init__(robot, scene, q0)
        self.problem = WholeBody(robot, [*self.frames, *self.extra], limits=Limits(collisions=collisions),
                                 options=StepOptions(damping=DAMPING))


class PinkCollisionStepper(PinkStepper):
    """pink's step with its self-collision barrier on kinelab's geometry and pairs (obstacles among them)."""

    def __init__(self, robot: Robot, scene: Any, q0: np.ndarray, collisions: Collisions):
        import pink
        from pink.barriers import SelfCollisionBarrier

        super().__init__(robot, scene, q0)
        geom = step_collisions(robot, collisions).geom.copy()
        self.configuration = pink.Configuration(robot.model, robot.model.createData(), q0.copy(),
                                                collision_model=geom, collision_data=pin.GeometryData(geom))
        self.barriers = [SelfCollisionBarrier(n_collision_pairs=len(geom.collisionPairs), gain=GAIN,
                                              d_min=MARGIN)]
        self.unsolved = 0

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets, integrated (the barrier in the QP); a QP without a solution
        counted, the robot left where it is."""
        for task, M in zip(self.frames, targets, strict=True):
            task.set_target(M)
        try:
            self.v = self.pink.solve_ik(self.configuration, self.tasks, DT, solver="daqp", damping=DAMPING,
                                        limits=self.limits, barriers=self.barriers, safety_break=False)
        except self.pink.exceptions.NoSolutionFound:
            self.unsolved += 1
            self.v = np.zeros(self.robot.nv)
        self.configuration.integrate_inplace(self.v, DT)


class MinkCollisionStepper(MinkStepper):
    """mink's step with its ``CollisionAvoidanceLimit`` on MuJoCo's geoms of the same meshes and obstacles."""

    def __init__(self, robot: Robot, scene: Any, q0: np.ndarray, collisions: Collisions):
        self.environment = collisions.environment
        super().__init__(robot, scene, q0)
        moving = [i for i in range(self.model.ngeom) if self.model.geom_bodyid[i] != 0]
        fixed = [i for i in range(self.model.ngeom) if self.model.geom_bodyid[i] == 0]
        self.limits.append(self.mink.CollisionAvoidanceLimit(
            self.model, [(moving, moving), (moving, fixed)], gain=GAIN, minimum_distance_from_collisions=MARGIN,
            collision_detection_distance=MARGIN + DETECTION))
        self.unsolved = 0

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets, integrated; a QP without a solution counted, the robot left where it
        is."""
        try:
            super().step(targets)
        except self.mink.NoSolutionFound:
            self.unsolved += 1
            self.v = np.zeros(self.robot.nv)

    def make_model(self, robot: Robot) -> Any:
        """MuJoCo's model with the collision meshes and the obstacles."""
        return mujoco_collision_model(robot, self.environment)


def mujoco_collision_model(robot: Robot, environment: Environment | None) -> Any:
    """MuJoCo's model of the robot's URDF with its collision meshes (STL; example-robot-data's package paths made
    absolute) and the obstacles as world geoms; a free joint at the root of a floating robot.

    Raises:
        KinelabError: a robot without a file, or meshes MuJoCo cannot read.
    """
    import mujoco

    if robot.source is None:
        raise KinelabError(f"{robot.name} has no file: MuJoCo's model is compiled from its URDF")
    text = re.sub(r"<visual\b.*?</visual>", "", robot.source.read_text(), flags=re.S)
    share = str(robot.source)[:str(robot.source).find("example-robot-data") + len("example-robot-data")]
    text = text.replace("package://example-robot-data/", share + "/")
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler fusestatic="false" discardvisual="true" '
                  r'balanceinertia="true" strippath="false"/></mujoco>', text, count=1)
    spec = mujoco.MjSpec.from_string(text)
    if robot.floating:
        spec.worldbody.first_body().add_freejoint()
    for obstacle in environment.obstacles if environment is not None else ():
        _add_geom(spec, obstacle)
    return spec.compile()


def _add_geom(spec: Any, obstacle: Obstacle) -> None:
    """An obstacle as a world geom (box half-sizes; capsule radius and half-length; sphere radius)."""
    import mujoco

    kinds = {"box": mujoco.mjtGeom.mjGEOM_BOX, "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
             "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE}
    if obstacle.shape not in kinds:
        raise KinelabError(f"the collision bench places boxes, spheres and capsules, not a {obstacle.shape}")
    size = {"box": [s / 2 for s in obstacle.size], "sphere": [obstacle.size[0], 0.0, 0.0],
            "capsule": [obstacle.size[0], obstacle.size[-1] / 2, 0.0]}[obstacle.shape]
    kind = kinds[obstacle.shape]
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, obstacle.placement.rotation.flatten())
    spec.worldbody.add_geom(name=obstacle.name, type=kind, size=size, pos=list(obstacle.xyz), quat=list(quat))


STEPPERS = {"kinelab": KinelabCollisionStepper, "pink": PinkCollisionStepper, "mink": MinkCollisionStepper}
PEER_MODULES = {"pink": ("pink",), "mink": ("mink", "mujoco")}


def not_installed() -> dict[str, str]:
    """The peers not installed, each with the install hint."""
    return {key: f"not installed ({', '.join(m for m in mods if importlib.util.find_spec(m) is None)}): "
                 "pip install -e '.[bench]'"
            for key, mods in PEER_MODULES.items() if any(importlib.util.find_spec(m) is None for m in mods)}


def run_scene(name: str, steps: int, rounds: int, progress: bool = False) -> list[dict[str, Any]]:
    """The protocol on one scene: a row per library (times, penetrations, least distance less the margin,
    largest tracking error) with each round's median."""
    scene, robot = SCENES[name], whole(SCENARIOS[name].robot)
    q0 = robot.standing() if robot.floating else start_of(robot)
    collisions = Collisions(environment=obstacles(scene, robot, q0), margin=MARGIN, detection=DETECTION,
                            gain=GAIN)
    found = step_collisions(robot, collisions)
    if found.closest(q0)[1] < 0.0:
        raise KinelabError(f"the {name} scene's start is not clear of its pairs: {found.closest(q0)[0]}")
    scenario = SCENARIOS[name]
    frames = scenario.moving + scenario.held
    start = robot.frame_placements(q0, frames)
    records: dict[str, dict[str, Any]] = {k: {"times": [], "medians": [], "slack": [], "errors": []}
                                          for k in STEPPERS}
    for _ in tqdm(range(rounds), desc=f"collision step {name}", disable=not progress, unit="round"):
        steppers = _steppers(robot, scenario, q0, collisions)
        round_times: dict[str, list[float]] = {k: [] for k in steppers}
        order = list(steppers)
        for k in range(steps):
            targets = targets_at(start, (k + 1) * DT, len(scenario.moving), RADIUS)
            for key in order[k % len(order):] + order[:k % len(order)]:
                t0 = time.perf_counter()
                steppers[key].step(targets)
                round_times[key].append(time.perf_counter() - t0)
                _judge(robot, found, steppers[key], targets, frames, records[key])
        for key, times in round_times.items():
            records[key]["times"] += times
            records[key]["medians"].append(float(np.median(times)))
            records[key]["unsolved"] = records[key].get("unsolved", 0) + getattr(steppers[key], "unsolved", 0)
    return [_row(name, key, rec, found) for key, rec in records.items() if rec["times"]]


def _steppers(robot: Robot, scenario: Any, q0: np.ndarray, collisions: Collisions) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, make in STEPPERS.items():
        if key in not_installed():
            continue
        try:
            out[key] = make(robot, scenario, q0, collisions)
        except Exception as exc:  # noqa: BLE001 - an installed peer that breaks stops the bench, named
            if key == "kinelab":
                raise
            raise PeerFailedError(f"{key} failed on {robot.name}: {last_line(exc)}") from exc
    return out


def _judge(robot: Robot, found: StepCollisions, stepper: Any, targets: list[pin.SE3], frames: tuple[str, ...],
           record: dict[str, Any]) -> None:
    """The least distance less the margin over kinelab's pairs (coal) and the tracking error, at the stepper's q."""
    q = stepper.pinocchio_q()
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    near = found.near(data, found.spec.margin)
    record["slack"].append(min((r.min_distance for r in found.distances(data, near)), default=np.inf) - MARGIN)
    placed = robot.frame_placements(q, frames)
    record["errors"].append(max(float(np.linalg.norm(M.translation - T.translation))
                                for M, T in zip(placed, targets, strict=True)))


def _row(scene: str, key: str, rec: dict[str, Any], found: StepCollisions) -> dict[str, Any]:
    t = np.array(rec["times"]) * 1e6
    slack = np.array(rec["slack"])
    return {"scene": scene, "library": key, "steps": len(t), "median_us": float(np.median(t)),
            "p95_us": float(np.percentile(t, 95)), "round_medians_us": rec["medians"],
            "penetrations": int((slack < -PENETRATION).sum()), "least_slack_m": float(slack.min()),
            "max_tracking_error_m": float(max(rec["errors"])), "pairs": len(found.pairs),
            "unsolved": int(rec.get("unsolved", 0))}


def run(scenes: list[str] | None = None, steps: int = 1000, rounds: int = 3, progress: bool = False
        ) -> dict[str, Any]:
    """The protocol on each scene (default: both), with kinelab's median step over each peer's per round.

    Raises:
        KinelabError: an unknown scene (the valid names listed).
    """
    names = list(scenes or SCENES)
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        raise KinelabError(f"no collision scene for {unknown[0]!r}; the scenes: {', '.join(SCENES)}")
    rows = [row for name in names for row in run_scene(name, steps, rounds, progress)]
    mine = {r["scene"]: r for r in rows if r["library"] == "kinelab"}
    ratios = []
    for peer in rows:
        if peer["library"] != "kinelab":
            per_round = np.array(mine[peer["scene"]]["round_medians_us"]) / np.array(peer["round_medians_us"])
            ratios.append({"scene": peer["scene"], "peer": peer["library"], "ratio": float(np.median(per_round)),
                           "ratio_min": float(per_round.min()), "ratio_max": float(per_round.max())})
    return {"steps": rows, "ratios": ratios, "not_run": not_installed(),
            "protocol": {"dt_s": DT, "steps": steps, "rounds": rounds, "radius_m": RADIUS, "period_s": PERIOD,
                         "margin_m": MARGIN, "detection_m": DETECTION, "gain": GAIN}}


def markdown(result: dict[str, Any]) -> str:
    """The tables."""
    lines = ["| scene | library | median step | p95 | penetrations (> 0.1 mm) | least distance − margin | "
             "QP without a solution | largest tracking error |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in result["steps"]:
        lines.append(f"| {r['scene']} | {r['library']} | {r['median_us']:.0f} µs | {r['p95_us']:.0f} µs | "
                     f"{r['penetrations']} of {r['steps']} | {r['least_slack_m'] * 1e3:+.3f} mm | "
                     f"{r['unsolved']} | {r['max_tracking_error_m']:.3f} m |")
    lines += ["", "| scene | kinelab / peer (median step) | spread over rounds |", "|---|---:|---|"]
    for r in result["ratios"]:
        lines.append(f"| {r['scene']} | {r['ratio']:.2f} × {r['peer']} | {r['ratio_min']:.2f}–{r['ratio_max']:.2f} |")
    if result.get("not_run"):
        lines += ["", "Not run: " + "; ".join(f"{k} ({why})" for k, why in result["not_run"].items())]
    return "\n".join(lines)
