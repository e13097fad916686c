"""The three whole-body steppers ``kinelab bench --whole-body`` compares (kinelab's step, pink's, mink's), the
scenarios they run (robots, frames, moving targets) and the map between MuJoCo's configuration and Pinocchio's.
Costs, damping, limits and the time step are the same for the three (see :mod:`kinelab.report.bench.wholebody`)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.robot import Chain, load
from kinelab.robot.tree import Robot
from kinelab.wholebody import ComTask, FrameTask, Limits, PostureTask, StepOptions, WholeBody

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


def targets_at(start: list[pin.SE3], t: float, moving: int, radius: float = RADIUS) -> list[pin.SE3]:
    """The frames' targets at time t [s]: the first ``moving`` turning on circles of ``radius`` [m] in their frame's
    y-z plane."""
    out = []
    for k, M in enumerate(start):
        if k < moving:
            a = 2 * np.pi * t / PERIOD + k * np.pi / 2
            offset = M.rotation @ np.array([0.0, radius * (np.cos(a) - 1.0), radius * np.sin(a)])
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
        self.moving = len(scenario.moving)
        self.problem = WholeBody(robot, [*self.frames, *self.extra], limits=Limits(),
                                 options=StepOptions(damping=DAMPING))
        self.v = np.zeros(robot.nv)

    def step(self, targets: list[pin.SE3]) -> None:
        """One step toward the frames' targets (base frame), integrated: the moving frames' targets set, as pink's
        and mink's tasks are given theirs."""
        for i in range(self.moving):
            self.problem.set_target(i, targets[i])
        result = self.problem.step(self.q, DT)
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
    return mujoco_spec(robot).compile()


def mujoco_spec(robot: Robot) -> Any:
    """MuJoCo's spec of :func:`mujoco_model`, to add to before compiling."""
    import mujoco

    assert robot.source is not None
    text = robot.source.read_text()
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S)
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler fusestatic="false" discardvisual="true" '
                  r'balanceinertia="true"/></mujoco>', text, count=1)
    spec = mujoco.MjSpec.from_string(text)
    if robot.floating:
        spec.worldbody.first_body().add_freejoint()
    return spec


class MinkStepper:
    """mink's ``solve_ik`` on the same tasks (mink and mujoco, the bench extra)."""

    name = "mink"

    def __init__(self, robot: Robot, scenario: Scenario, q0: np.ndarray):
        import mink

        self.mink, self.robot = mink, robot
        self.model = self.make_model(robot)
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

    def make_model(self, robot: Robot) -> Any:
        """MuJoCo's model the stepper runs on (:func:`mujoco_model`)."""
        return mujoco_model(robot)

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
    """Pinocchio's q and v ↔ MuJoCo's qpos and qvel, joint by joint by name (a free joint's and a ball joint's
    quaternion reordered: x y z w ↔ w x y z; a free joint's velocity, world-linear in MuJoCo, is left out of
    :meth:`velocity`: its limits are infinite)."""

    def __init__(self, robot: Robot, model: Any):
        self.robot, self.nq = robot, int(model.nq)
        self.free: int | None = None
        self.pairs: list[tuple[int, int, int, int]] = []  # (pinocchio idx_q, idx_v, MuJoCo qpos, qvel address)
        self.balls: list[tuple[int, int]] = []  # (pinocchio idx_q, MuJoCo qpos address) of each ball joint
        for i in range(model.njnt):
            name = model.joint(i).name
            if model.jnt_type[i] == 0:
                self.free = int(model.jnt_qposadr[i])
            elif robot.model.existJointName(name):
                joint = robot.model.joints[robot.model.getJointId(name)]
                if model.jnt_type[i] == 1:
                    self.balls.append((joint.idx_q, int(model.jnt_qposadr[i])))
                    self.pairs += [(joint.idx_v + k, joint.idx_v + k, -1, int(model.jnt_dofadr[i]) + k)
                                   for k in range(3)]
                else:
                    self.pairs.append((joint.idx_q, joint.idx_v, int(model.jnt_qposadr[i]),
                                       int(model.jnt_dofadr[i])))

    def to_mujoco(self, q: np.ndarray) -> np.ndarray:
        """MuJoCo's qpos of Pinocchio's q."""
        out = np.zeros(self.nq)
        if self.free is not None:
            a = self.free
            out[a:a + 3], out[a + 3], out[a + 4:a + 7] = q[:3], q[6], q[3:6]
        for iq, _, adr, _ in self.pairs:
            if adr >= 0:
                out[adr] = q[iq]
        for iq, adr in self.balls:
            out[adr], out[adr + 1:adr + 4] = q[iq + 3], q[iq:iq + 3]
        return out

    def from_mujoco(self, qpos: np.ndarray) -> np.ndarray:
        """Pinocchio's q of MuJoCo's qpos."""
        out = self.robot.neutral()
        if self.free is not None:
            a = self.free
            out[:3], out[3:6], out[6] = qpos[a:a + 3], qpos[a + 4:a + 7], qpos[a + 3]
        for iq, _, adr, _ in self.pairs:
            if adr >= 0:
                out[iq] = qpos[adr]
        for iq, adr in self.balls:
            out[iq:iq + 3], out[iq + 3] = qpos[adr + 1:adr + 4], qpos[adr]
        return out

    def velocity(self, qvel: np.ndarray) -> np.ndarray:
        """Pinocchio's v of MuJoCo's qvel, the joints' (the free-flyer's left zero)."""
        out = np.zeros(self.robot.nv)
        for _, iv, _, dof in self.pairs:
            out[iv] = qvel[dof]
        return out


STEPPERS = {"kinelab": KinelabStepper, "pink": PinkStepper, "mink": MinkStepper}
PEER_MODULES = {"pink": ("pink",), "mink": ("mink", "mujoco")}  # what each peer needs installed (the bench extra)
