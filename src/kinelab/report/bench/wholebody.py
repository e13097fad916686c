"""``kinelab bench --whole-body``: the differential step side by side with pink (Pinocchio) and mink (MuJoCo), and
the converged solve against pink iterated.

The step. Each robot follows the same moving targets with the same tasks and limits in the three libraries: the
Panda's tool (frame + posture), Baxter's two grippers (+ posture), TALOS's and G1's two hands with their feet held,
the centre of mass and a posture on a free-flyer. Each hand turns on a 5 cm circle (one turn in 2 s), dt = 5 ms,
from a start within the limits. Costs are pink's (frame 1/m and 1/rad, CoM 1/m, posture 1e-3 per joint; kinelab's
weights are their squares), damping 1e-12, every library's QP DAQP, position and velocity limits (the file's). The
libraries are interleaved per step, in a rotating order; each keeps its own configuration. Per step: the wall time
of the library's step and integration (outside it), its limit violations (a position beyond 1e-9, a velocity beyond
1e-9 of its limit) and its tracking error judged by Pinocchio's FK (mink's configuration mapped by joint name).
MuJoCo's model is compiled from the same URDF with its meshes left out and its fixed links kept as bodies.

The converged solve. Targets from random configurations of the whole robot; kinelab's two solvers and pink's step
iterated at dt = 1 s until every frame is within 1e-6 m / 1e-6 rad (at most 200 steps); success and time.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.errors import KinelabError
from kinelab.robot import Chain, load
from kinelab.robot.tree import Robot
from kinelab.wholebody import ComTask, FrameTask, Limits, PostureTask, StepOptions, step
from kinelab.wholebody.solve import solve

DT = 0.005  # [s]
RADIUS, PERIOD = 0.05, 2.0  # [m], [s] each hand's circle
POSTURE_COST = 1e-3  # pink's cost per joint [1/rad]
DAMPING = 1e-12


@dataclass(frozen=True)
class Scenario:
    """A robot's whole-body task: frames that move, frames held, the CoM held, a posture."""

    robot: str
    moving: tuple[str, ...]
    held: tuple[str, ...] = ()
    com: bool = False


SCENARIOS = {
    "panda": Scenario("panda", ("panda_hand_tcp",)),
    "baxter": Scenario("baxter", ("left_gripper", "right_gripper")),
    "talos": Scenario("talos", ("gripper_left_base_link", "gripper_right_base_link"),
                      ("left_sole_link", "right_sole_link"), True),
    "g1": Scenario("g1", ("left_wrist_yaw_link", "right_wrist_yaw_link"),
                   ("left_ankle_roll_link", "right_ankle_roll_link"), True),
}


def whole(name: str) -> Robot:
    """The scenario's whole robot (an arm's: its file whole)."""
    loaded = load(name)
    return loaded.robot if isinstance(loaded, Chain) else loaded


def start_of(robot: Robot) -> np.ndarray:
    """The start: every bounded joint at the middle of its limits, pulled a quarter of the way to zero (a bent,
    well-inside posture), the base 1 m up."""
    q = robot.neutral()
    b = robot.space.bounded_q
    mid = (robot.lower[b] + robot.upper[b]) / 2
    q[b] = np.clip(0.75 * mid, robot.lower[b], robot.upper[b])
    if robot.floating:
        q[2] = 1.0
    return q


def targets_at(start: list[pin.SE3], t: float, moving: int) -> list[pin.SE3]:
    """The frames' targets at time t [s]: the first ``moving`` turning on circles in their frame's y-z plane."""
    out = []
    for k, M in enumerate(start):
        if k < moving:
            a = 2 * np.pi * t / PERIOD + k * np.pi / 2
            offset = M.rotation @ np.array([0.0, RADIUS * (np.cos(a) - 1.0), RADIUS * np.sin(a)])
            out.append(pin.SE3(M.rotation, M.translation + offset))
        else:
            out.append(M)
    return out


class KinelabStepper:
    """kinelab's step on the scenario."""

    name = "kinelab"

    def __init__(self, robot: Robot, scenario: Scenario, q0: np.ndarray):
        self.robot, self.q = robot, q0.copy()
        frames = scenario.moving + scenario.held
        placed = robot.frame_placements(q0, frames)
        self.frames = [FrameTask(f, M) for f, M in zip(frames, placed, strict=True)]
        self.extra = ([ComTask(robot.com(q0))] if scenario.com else []) + \
            [PostureTask(q0, weight=POSTURE_COST**2)]
        self.options = StepOptions(damping=DAMPING)
        self.limits = Limits()
        self.v = np.zeros(robot.nv)

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets (base frame), integrated."""
        tasks = [t.moved(M) for t, M in zip(self.frames, targets, strict=True)] + self.extra
        result = step(self.robot, self.q, tasks, DT, limits=self.limits, options=self.options)
        self.q, self.v = result.q, result.v

    def pinocchio_q(self) -> np.ndarray:
        """The configuration as Pinocchio's q."""
        return self.q


class PinkStepper:
    """pink's ``solve_ik`` on the same tasks (pin-pink, the bench extra)."""

    name = "pink"

    def __init__(self, robot: Robot, scenario: Scenario, q0: np.ndarray):
        import pink
        from pink.limits import ConfigurationLimit, VelocityLimit
        from pink.tasks import ComTask as PinkCom
        from pink.tasks import FrameTask as PinkFrame
        from pink.tasks import PostureTask as PinkPosture

        self.pink, self.robot = pink, robot
        self.configuration = pink.Configuration(robot.model, robot.model.createData(), q0.copy())
        frames = scenario.moving + scenario.held
        self.frames = [PinkFrame(f, position_cost=1.0, orientation_cost=1.0) for f in frames]
        placed = robot.frame_placements(q0, frames)
        for task, M in zip(self.frames, placed, strict=True):
            task.set_target(M)
        posture = PinkPosture(cost=POSTURE_COST)
        posture.set_target(q0)
        self.tasks: list[Any] = [*self.frames, posture]
        if scenario.com:
            com = PinkCom(cost=1.0)
            com.set_target(robot.com(q0))
            self.tasks.append(com)
        self.limits = [ConfigurationLimit(robot.model), VelocityLimit(robot.model)]
        self.v = np.zeros(robot.nv)

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets (base frame), integrated."""
        for task, M in zip(self.frames, targets, strict=True):
            task.set_target(M)
        self.v = self.pink.solve_ik(self.configuration, self.tasks, DT, solver="daqp", damping=DAMPING,
                                    limits=self.limits, safety_break=False)
        self.configuration.integrate_inplace(self.v, DT)

    def pinocchio_q(self) -> np.ndarray:
        """The configuration as Pinocchio's q."""
        return np.asarray(self.configuration.q, dtype=float)


def mujoco_model(robot: Robot) -> Any:
    """MuJoCo's model of the robot's URDF, meshes left out, fixed links kept as bodies, a free joint at the root of
    a floating robot."""
    import mujoco

    assert robot.source is not None
    text = robot.source.read_text()
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S)
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler fusestatic="false" discardvisual="true" '
                  r'balanceinertia="true"/></mujoco>', text, count=1)
    spec = mujoco.MjSpec.from_string(text)
    if robot.floating:
        spec.worldbody.first_body().add_freejoint()
    return spec.compile()


class MinkStepper:
    """mink's ``solve_ik`` on the same tasks (mink and mujoco, the bench extra)."""

    name = "mink"

    def __init__(self, robot: Robot, scenario: Scenario, q0: np.ndarray):
        import mink

        self.mink, self.robot = mink, robot
        self.model = mujoco_model(robot)
        self.maps = Maps(robot, self.model)
        self.configuration = mink.Configuration(self.model)
        self.configuration.update(self.maps.to_mujoco(q0))
        frames = scenario.moving + scenario.held
        self.frames = [mink.FrameTask(f, "body", position_cost=1.0, orientation_cost=1.0) for f in frames]
        for task, M in zip(self.frames, robot.frame_placements(q0, frames), strict=True):
            task.set_target(mink.SE3.from_matrix(M.homogeneous))
        posture = mink.PostureTask(self.model, cost=POSTURE_COST)
        posture.set_target_from_configuration(self.configuration)
        self.tasks: list[Any] = [*self.frames, posture]
        if scenario.com:
            com = mink.ComTask(cost=1.0)
            com.set_target(robot.com(q0))
            self.tasks.append(com)
        velocities = {self.model.joint(i).name: float(robot.velocity_limit[robot.model.joints[
            robot.model.getJointId(self.model.joint(i).name)].idx_v]) for i in range(self.model.njnt)
            if robot.model.existJointName(self.model.joint(i).name)
            and np.isfinite(robot.velocity_limit[robot.model.joints[robot.model.getJointId(
                self.model.joint(i).name)].idx_v])}
        self.limits = [mink.ConfigurationLimit(self.model), mink.VelocityLimit(self.model, velocities)]

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets (base frame), integrated."""
        for task, M in zip(self.frames, targets, strict=True):
            task.set_target(self.mink.SE3.from_matrix(M.homogeneous))
        qvel = self.mink.solve_ik(self.configuration, self.tasks, DT, "daqp", damping=DAMPING, limits=self.limits)
        self.configuration.integrate_inplace(qvel, DT)
        self.v = self.maps.velocity(qvel)

    def pinocchio_q(self) -> np.ndarray:
        """The configuration as Pinocchio's q."""
        return self.maps.from_mujoco(self.configuration.q)


class Maps:
    """Pinocchio's q and v ↔ MuJoCo's qpos and qvel, joint by joint by name (a free joint's quaternion reordered:
    x y z w ↔ w x y z; its velocity, world-linear in MuJoCo, is left out of :meth:`velocity`: its limits are
    infinite)."""

    def __init__(self, robot: Robot, model: Any):
        self.robot, self.nq = robot, int(model.nq)
        self.free: int | None = None
        self.pairs: list[tuple[int, int, int, int]] = []  # (pinocchio idx_q, idx_v, MuJoCo qpos, qvel address)
        for i in range(model.njnt):
            name = model.joint(i).name
            if model.jnt_type[i] == 0:
                self.free = int(model.jnt_qposadr[i])
            elif robot.model.existJointName(name):
                joint = robot.model.joints[robot.model.getJointId(name)]
                self.pairs.append((joint.idx_q, joint.idx_v, int(model.jnt_qposadr[i]), int(model.jnt_dofadr[i])))

    def to_mujoco(self, q: np.ndarray) -> np.ndarray:
        """MuJoCo's qpos of Pinocchio's q."""
        out = np.zeros(self.nq)
        if self.free is not None:
            a = self.free
            out[a:a + 3], out[a + 3], out[a + 4:a + 7] = q[:3], q[6], q[3:6]
        for iq, _, adr, _ in self.pairs:
            out[adr] = q[iq]
        return out

    def from_mujoco(self, qpos: np.ndarray) -> np.ndarray:
        """Pinocchio's q of MuJoCo's qpos."""
        out = self.robot.neutral()
        if self.free is not None:
            a = self.free
            out[:3], out[3:6], out[6] = qpos[a:a + 3], qpos[a + 4:a + 7], qpos[a + 3]
        for iq, _, adr, _ in self.pairs:
            out[iq] = qpos[adr]
        return out

    def velocity(self, qvel: np.ndarray) -> np.ndarray:
        """Pinocchio's v of MuJoCo's qvel, the joints' (the free-flyer's left zero)."""
        out = np.zeros(self.robot.nv)
        for _, iv, _, dof in self.pairs:
            out[iv] = qvel[dof]
        return out


STEPPERS = {"kinelab": KinelabStepper, "pink": PinkStepper, "mink": MinkStepper}


def run_steps(name: str, steps: int = 1000, rounds: int = 3, progress: bool = False) -> list[dict[str, Any]]:
    """The step protocol on one robot: a row per library with its times (median, p95, p99 over every step of every
    round, and each round's median), its violations and its largest tracking error."""
    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    q0 = start_of(robot)
    frames = scenario.moving + scenario.held
    start = robot.frame_placements(q0, frames)
    records: dict[str, dict[str, list[float]]] = {k: {"times": [], "medians": [], "violations": [], "errors": []}
                                                  for k in STEPPERS}
    for _ in tqdm(range(rounds), desc=f"whole-body {name}", disable=not progress, unit="round"):
        steppers: dict[str, Any] = {}
        for key, make in STEPPERS.items():
            try:
                steppers[key] = make(robot, scenario, q0)
            except ImportError:  # a peer not installed (the bench extra): its rows are left out
                continue
        round_times: dict[str, list[float]] = {k: [] for k in steppers}
        order = list(steppers)
        for k in range(steps):
            targets = targets_at(start, (k + 1) * DT, len(scenario.moving))
            for key in order[k % len(order):] + order[:k % len(order)]:
                s = steppers[key]
                t0 = time.perf_counter()
                s.step(targets)
                round_times[key].append(time.perf_counter() - t0)
                _judge(robot, s, targets, frames, records[key])
        for key, times in round_times.items():
            records[key]["times"] += times
            records[key]["medians"].append(float(np.median(times)))
    return [_row(name, key, rec) for key, rec in records.items() if rec["times"]]


def _judge(robot: Robot, stepper: Any, targets: list[pin.SE3], frames: tuple[str, ...], record: dict[str, Any]) -> None:
    """The stepper's violations and tracking error at its new configuration, by Pinocchio."""
    q = stepper.pinocchio_q()
    past = np.maximum(robot.lower - q, q - robot.upper)
    vmax = robot.velocity_limit
    finite = np.isfinite(vmax)
    v = np.asarray(stepper.v, dtype=float)
    over = np.abs(v[finite]) / vmax[finite] - 1.0 if v.shape == vmax.shape else np.zeros(1)
    record["violations"].append(int((past > 1e-9).sum() + (over > 1e-9).sum()))
    placed = robot.frame_placements(q, frames)
    record["errors"].append(max(float(np.linalg.norm(M.translation - T.translation))
                                for M, T in zip(placed, targets, strict=True)))


def _row(robot: str, key: str, rec: dict[str, Any]) -> dict[str, Any]:
    t = np.array(rec["times"]) * 1e6
    medians = np.array(rec["medians"]) * 1e6
    return {"robot": robot, "library": key, "steps": len(t), "median_us": float(np.median(t)),
            "p95_us": float(np.percentile(t, 95)), "p99_us": float(np.percentile(t, 99)),
            "round_medians_us": medians.tolist(), "violations": int(sum(rec["violations"])),
            "max_tracking_error_m": float(max(rec["errors"]))}


def ratios(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """kinelab's median step against each peer's, round by round: the ratio of the medians and its spread."""
    out = []
    for robot in sorted({r["robot"] for r in rows}):
        mine = next((r for r in rows if r["robot"] == robot and r["library"] == "kinelab"), None)
        for peer in (r for r in rows if r["robot"] == robot and r["library"] != "kinelab"):
            if mine is None:
                continue
            per_round = np.array(mine["round_medians_us"]) / np.array(peer["round_medians_us"])
            out.append({"robot": robot, "peer": peer["library"], "ratio": float(np.median(per_round)),
                        "ratio_min": float(per_round.min()), "ratio_max": float(per_round.max())})
    return out


def converged(name: str, count: int = 50, seed: int = 0, progress: bool = False) -> list[dict[str, Any]]:
    """The converged solve on ``count`` targets from random configurations: kinelab's step and FRDM, pink iterated;
    success (every frame within 1e-6 m, 1e-6 rad, judged by Pinocchio) and the median time."""
    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    frames = scenario.moving + scenario.held
    rng = np.random.default_rng(seed)
    rows: dict[str, dict[str, list[float]]] = {k: {"ok": [], "time": []} for k in ("step", "frdm", "pink iterated")}
    for k in tqdm(range(count), desc=f"solve {name}", disable=not progress, unit="target"):
        q_true = robot.random_q(rng)
        placed = robot.frame_placements(q_true, frames)
        start = start_of(robot)
        if robot.floating:
            start[:7] = q_true[:7]
        tasks: list[Any] = [FrameTask(f, M) for f, M in zip(frames, placed, strict=True)]
        tasks += ([ComTask(robot.com(q_true))] if scenario.com else []) + [PostureTask(start, weight=1e-6)]
        for solver in ("step", "frdm"):
            t0 = time.perf_counter()
            res = solve(robot, tasks, q0=start, solver=solver, seed=k, time_budget=2.0)
            rows[solver]["time"].append(time.perf_counter() - t0)
            rows[solver]["ok"].append(float(res.success))
        ok, seconds = _pink_iterated(robot, frames, placed, tasks, start)
        if ok is not None:
            rows["pink iterated"]["ok"].append(float(ok))
            rows["pink iterated"]["time"].append(seconds)
    return [{"robot": name, "solver": key, "targets": len(r["ok"]), "success_pct": 100.0 * float(np.mean(r["ok"])),
             "median_ms": float(np.median(r["time"]) * 1e3)} for key, r in rows.items() if r["ok"]]


def _pink_iterated(robot: Robot, frames: tuple[str, ...], placed: list[pin.SE3], tasks: list[Any],
                   start: np.ndarray) -> tuple[bool | None, float]:
    """pink's step at dt = 1 s, iterated until every frame is within 1e-6 m / 1e-6 rad (200 steps at most)."""
    try:
        import pink
        from pink.limits import ConfigurationLimit
        from pink.tasks import ComTask as PinkCom
        from pink.tasks import FrameTask as PinkFrame
    except ImportError:
        return None, 0.0
    configuration = pink.Configuration(robot.model, robot.model.createData(), start.copy())
    pink_tasks: list[Any] = []
    for f, M in zip(frames, placed, strict=True):
        task = PinkFrame(f, position_cost=1.0, orientation_cost=1.0)
        task.set_target(M)
        pink_tasks.append(task)
    com = next((t for t in tasks if isinstance(t, ComTask)), None)
    if com is not None:
        task = PinkCom(cost=1.0)
        task.set_target(com.target)
        pink_tasks.append(task)
    limits = [ConfigurationLimit(robot.model)]
    t0 = time.perf_counter()
    for _ in range(200):
        v = pink.solve_ik(configuration, pink_tasks, 1.0, solver="daqp", damping=1e-12, limits=limits,
                          safety_break=False)
        configuration.integrate_inplace(v, 1.0)
        q = np.asarray(configuration.q)
        now = robot.frame_placements(q, frames)
        if all(np.linalg.norm(N.translation - M.translation) <= 1e-6
               and np.linalg.norm(pin.log3(N.rotation.T @ M.rotation)) <= 1e-6
               for N, M in zip(now, placed, strict=True)):
            return True, time.perf_counter() - t0
    return False, time.perf_counter() - t0


def run(robots: list[str] | None = None, steps: int = 1000, rounds: int = 3, solves: int = 50, seed: int = 0,
        progress: bool = False) -> dict[str, Any]:
    """Both protocols on each robot (default: the four scenarios).

    Raises:
        KinelabError: a robot without a whole-body scenario (the valid names listed).
    """
    names = list(robots or SCENARIOS)
    unknown = [n for n in names if n not in SCENARIOS]
    if unknown:
        raise KinelabError(f"no whole-body scenario for {unknown[0]!r}; the scenarios: {', '.join(SCENARIOS)}")
    rows, solved = [], []
    for name in names:
        rows += run_steps(name, steps, rounds, progress)
        if solves:
            solved += converged(name, solves, seed, progress)
    return {"steps": rows, "ratios": ratios(rows), "solves": solved,
            "protocol": {"dt_s": DT, "steps": steps, "rounds": rounds, "radius_m": RADIUS, "period_s": PERIOD}}


def markdown(result: dict[str, Any]) -> str:
    """The tables."""
    lines = ["| robot | library | median | p95 | p99 | violations | largest tracking error |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for r in result["steps"]:
        lines.append(f"| {r['robot']} | {r['library']} | {r['median_us']:.1f} µs | {r['p95_us']:.1f} µs | "
                     f"{r['p99_us']:.1f} µs | {r['violations']} | {r['max_tracking_error_m']:.2e} m |")
    lines += ["", "| robot | kinelab / peer (median step) | spread over rounds |", "|---|---:|---|"]
    for r in result["ratios"]:
        lines.append(f"| {r['robot']} | {r['ratio']:.3f} × {r['peer']} | {r['ratio_min']:.3f}–{r['ratio_max']:.3f} |")
    if result["solves"]:
        lines += ["", "| robot | converged solve | success | median time |", "|---|---|---:|---:|"]
        for r in result["solves"]:
            lines.append(f"| {r['robot']} | {r['solver']} | {r['success_pct']:.1f} % of {r['targets']} | "
                         f"{r['median_ms']:.2f} ms |")
    return "\n".join(lines)
