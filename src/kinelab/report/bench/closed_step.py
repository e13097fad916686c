"""``kinelab bench --closed``: the whole-body step on robots that close loops, side by side with mink's
``EqualityConstraintTask`` on the same model, targets and limits.

Robots: the four-bar (its coupler tip) and the parallel ankle (its sole), whose loops are point closures that MuJoCo
writes as ``connect`` equalities between two sites (the delta's third loop holds an orientation alone, which
MuJoCo's equalities cannot say: it is left out), and Cassie (both feet and the pelvis as poses, its four loops).
MuJoCo's model of a URDF is compiled from the same file (the whole-body bench's,
:func:`kinelab.report.bench.steppers.mujoco_spec`) with a site at each closure frame and a connect between each
loop's two sites; an MJCF robot (Cassie) is the file itself, whose connects are the loops kinelab read. The
targets: the tasks' frames along the robot's own motion (its motors swept by sines, each sample assembled), one
per step of 5 ms, from the assembled start. kinelab holds each loop as an
equality of its QP; mink asks it as a task of cost 1e3 (its equalities are soft). Position limits only, DAQP for
both, a posture of weight 1e-3. Per step: the library's step and integration time, the loops' largest error by
Pinocchio at its configuration (mink's mapped by joint name), and the tool's distance to its target. The two are
interleaved per step, in turn; each keeps its own configuration.
"""

from __future__ import annotations

import importlib.util
import time
from typing import Any

import numpy as np

from kinelab.errors import KinelabError
from kinelab.report.bench.steppers import Maps, mujoco_spec
from kinelab.robot import load
from kinelab.robot.assembly import actuated_indices
from kinelab.robot.mjcf import is_mjcf
from kinelab.robot.tree import Robot
from kinelab.wholebody import FrameTask, Limits, PostureTask, StepOptions, WholeBody

DT = 0.005
ROBOTS = ("fourbar", "ankle", "cassie")
EQUALITY_COST = 1e3  # mink's loops, asked far above its tool's cost 1
POSTURE = 1e-3
POSES = {"cassie": ("left-foot", "right-foot", "cassie-pelvis")}  # frames held as whole poses (else: the tool's place)


def frames(robot: Robot) -> list[tuple[str, str]]:
    """The bench's tasks: (frame, "pose" or "position")."""
    return [(f, "pose") for f in POSES[robot.name]] if robot.name in POSES else [(robot.hands[0], "position")]


def targets(robot: Robot, steps: int) -> tuple[np.ndarray, list[list[Any]]]:
    """The assembled start and each task's target at each step (an SE3 for a pose, a point for a position): the
    motors swept by sines (0.3 rad, periods of 2-3 s, within their limits) about the start, each sample assembled
    from the one before."""
    home = robot.standing()
    motors = actuated_indices(robot)[0]
    lower, upper = robot.model.lowerPositionLimit[motors], robot.model.upperPositionLimit[motors]
    periods = 2.0 + np.arange(len(motors)) / max(len(motors) - 1, 1)
    q, out = home.copy(), []
    for k in range(steps):
        q = q.copy()
        q[motors] = np.clip(home[motors] + 0.3 * np.sin(2 * np.pi * k * DT / periods), lower, upper)
        q = robot.assemble(q)
        out.append([robot.frame_placement(q, f) if kind == "pose" else robot.frame_placement(q, f).translation
                    for f, kind in frames(robot)])
    return home, out


def tool_error(robot: Robot, q: np.ndarray, goal: list[Any]) -> float:
    """The largest distance of a task's frame from its target's place [m]."""
    return max(float(np.linalg.norm(robot.frame_placement(q, f).translation
                                    - (g.translation if kind == "pose" else g)))
               for (f, kind), g in zip(frames(robot), goal, strict=True))


class KinelabLoops:
    """kinelab's step, the loops equalities of its QP."""

    name = "kinelab"

    def __init__(self, robot: Robot, home: np.ndarray):
        self.robot, self.q = robot, home.copy()
        tasks: list[Any] = [FrameTask(f, robot.frame_placement(home, f) if kind == "pose"
                                      else robot.frame_placement(home, f).translation, task=kind)
                            for f, kind in frames(robot)]
        self.problem = WholeBody(robot, [*tasks, PostureTask(home, weight=POSTURE)], limits=Limits(velocity=None),
                                 options=StepOptions(damping=1e-12))

    def step(self, goal: list[Any]) -> None:
        """One step toward the tasks' targets, integrated."""
        for i, target in enumerate(goal):
            self.problem.set_target(i, target)
        self.q = self.problem.step(self.q, DT).q

    def pinocchio_q(self) -> np.ndarray:
        """The configuration as Pinocchio's q."""
        return self.q


class MinkLoops:
    """mink's step, the loops an ``EqualityConstraintTask`` on MuJoCo's connect equalities (an MJCF robot's own)."""

    name = "mink"

    def __init__(self, robot: Robot, home: np.ndarray):
        import mink

        self.mink, self.robot = mink, robot
        self.model = loop_model(robot)
        self.maps = Maps(robot, self.model)
        self.configuration = mink.Configuration(self.model)
        self.configuration.update(self.maps.to_mujoco(home))
        self.frames = [mink.FrameTask(f, "body", position_cost=1.0, orientation_cost=1.0 if kind == "pose" else 0.0)
                       for f, kind in frames(robot)]
        posture = mink.PostureTask(self.model, cost=np.sqrt(POSTURE))
        posture.set_target_from_configuration(self.configuration)
        self.tasks = [*self.frames, posture, mink.EqualityConstraintTask(self.model, cost=EQUALITY_COST)]
        self.limits = [mink.ConfigurationLimit(self.model)]

    def step(self, goal: list[Any]) -> None:
        """One step toward the tasks' targets, integrated."""
        for task, target in zip(self.frames, goal, strict=True):
            if isinstance(target, np.ndarray):
                task.set_target(self.mink.SE3.from_translation(np.asarray(target, dtype=float)))
            else:
                task.set_target(self.mink.SE3.from_rotation_and_translation(
                    self.mink.SO3.from_matrix(target.rotation), target.translation))
        qvel = self.mink.solve_ik(self.configuration, self.tasks, DT, "daqp", damping=1e-12, limits=self.limits)
        self.configuration.integrate_inplace(qvel, DT)

    def pinocchio_q(self) -> np.ndarray:
        """The configuration as Pinocchio's q (mapped by joint name)."""
        return self.maps.from_mujoco(self.configuration.q)


def loop_model(robot: Robot) -> Any:
    """MuJoCo's model of the robot's URDF with a site at each closure frame's body and a connect equality between
    each point loop's two sites.

    Raises:
        KinelabError: a loop that is not a point closure (MuJoCo's connect holds three translations).
    """
    import mujoco

    if robot.source is not None and is_mjcf(robot.source):
        return mujoco.MjModel.from_xml_path(str(robot.source))  # the file's own equalities, the loops kinelab read
    if any(tuple(c.mask) != (1, 1, 1, 0, 0, 0) and tuple(c.mask) != (1, 1, 0, 0, 0, 0) for c in robot.closures):
        raise KinelabError(f"{robot.name} holds a loop that is not a point closure: MuJoCo's connect cannot say it")
    spec = mujoco_spec(robot)
    bodies = {b.name: b for b in spec.bodies}
    for k, closure in enumerate(robot.closures):
        for end, frame in (("a", closure.frame_a), ("b", closure.frame_b)):
            bodies[frame].add_site(name=f"loop{k}{end}", pos=[0.0, 0.0, 0.0])
        equality = spec.add_equality()
        equality.type, equality.objtype = mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtObj.mjOBJ_SITE
        equality.name1, equality.name2 = f"loop{k}a", f"loop{k}b"
    return spec.compile()


def not_installed() -> dict[str, str]:
    """mink and mujoco, where they are not installed, with the install hint."""
    missing = [m for m in ("mink", "mujoco") if importlib.util.find_spec(m) is None]
    return {"mink": f"not installed ({', '.join(missing)}): pip install -e '.[bench]'"} if missing else {}


def run_robot(name: str, steps: int, rounds: int) -> list[dict[str, Any]]:
    """The protocol on one robot: a row per library (median step, p95, largest loop error, largest tool error)."""
    robot = load(name)
    home, path = targets(robot, steps)
    makers = [KinelabLoops] + ([] if not_installed() else [MinkLoops])
    rec: dict[str, dict[str, list[float]]] = {m.name: {"t": [], "medians": [], "loop": [], "tool": []} for m in makers}
    for _ in range(rounds):
        steppers = [m(robot, home) for m in makers]
        times: dict[str, list[float]] = {s.name: [] for s in steppers}
        for k, target in enumerate(path):
            for s in steppers[k % len(steppers):] + steppers[:k % len(steppers)]:
                t0 = time.perf_counter()
                s.step(target)
                times[s.name].append(time.perf_counter() - t0)
                q = s.pinocchio_q()
                rec[s.name]["loop"].append(float(np.abs(robot.closure_error(q)).max()))
                rec[s.name]["tool"].append(tool_error(robot, q, target))
        for key, t in times.items():
            rec[key]["t"] += t
            rec[key]["medians"].append(float(np.median(t)))
    return [{"robot": name, "library": key, "steps": len(r["t"]), "median_us": float(np.median(r["t"]) * 1e6),
             "p95_us": float(np.percentile(r["t"], 95) * 1e6), "round_medians_us": [m * 1e6 for m in r["medians"]],
             "max_loop_error": max(r["loop"]), "max_tool_error_m": max(r["tool"])} for key, r in rec.items()]


def run(robots: list[str] | None = None, steps: int = 1000, rounds: int = 3) -> dict[str, Any]:
    """The protocol on each robot (default: the four-bar, the ankle and Cassie), kinelab's median over mink's per
    round.

    Raises:
        KinelabError: a robot without a loop bench (the valid names listed).
    """
    names = list(robots or ROBOTS)
    unknown = [n for n in names if n not in ROBOTS]
    if unknown:
        raise KinelabError(f"no loop bench for {unknown[0]!r}; the robots: {', '.join(ROBOTS)} (the delta's "
                           "orientation loop has no MuJoCo equality)")
    rows = [row for name in names for row in run_robot(name, steps, rounds)]
    mine = {r["robot"]: r for r in rows if r["library"] == "kinelab"}
    ratios = []
    for peer in (r for r in rows if r["library"] != "kinelab"):
        per = np.array(mine[peer["robot"]]["round_medians_us"]) / np.array(peer["round_medians_us"])
        ratios.append({"robot": peer["robot"], "peer": peer["library"], "ratio": float(np.median(per)),
                       "ratio_min": float(per.min()), "ratio_max": float(per.max())})
    return {"steps": rows, "ratios": ratios, "not_run": not_installed(),
            "protocol": {"dt_s": DT, "steps": steps, "rounds": rounds, "equality_cost": EQUALITY_COST}}


def markdown(result: dict[str, Any]) -> str:
    """The tables."""
    lines = ["| robot | library | median step | p95 | largest loop error | largest tool error |",
             "|---|---|---:|---:|---:|---:|"]
    for r in result["steps"]:
        lines.append(f"| {r['robot']} | {r['library']} | {r['median_us']:.0f} µs | {r['p95_us']:.0f} µs | "
                     f"{r['max_loop_error']:.1e} m | {r['max_tool_error_m']:.1e} m |")
    lines += ["", "| robot | kinelab / peer (median step) | spread over rounds |", "|---|---:|---|"]
    for r in result["ratios"]:
        lines.append(f"| {r['robot']} | {r['ratio']:.2f} × {r['peer']} | {r['ratio_min']:.2f}–{r['ratio_max']:.2f} |")
    if result.get("not_run"):
        lines += ["", "Not run: " + "; ".join(f"{k} ({why})" for k, why in result["not_run"].items())]
    return "\n".join(lines)
