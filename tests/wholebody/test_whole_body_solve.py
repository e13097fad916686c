"""#59: the converged multi-frame solve, both solvers: every frame's target from one random configuration of the whole
robot, met within 1e-6 m / 1e-6 rad per frame inside the limits, judged here again by Pinocchio's own FK and centre
of mass; a target set no configuration meets is reported per task, never as a success. The solves are bounded by a
count of restarts, not by a clock: the outcome is the same on a loaded machine (G1's third target with FRDM takes 39
restarts, 3-7 s)."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.wholebody import ComTask, FrameTask, PostureTask, RelativeFrameTask

FRAMES = {"talos": ("left_sole_link", "right_sole_link", "gripper_left_base_link", "gripper_right_base_link"),
          "g1": ("left_ankle_roll_link", "right_ankle_roll_link", "left_wrist_yaw_link", "right_wrist_yaw_link"),
          "baxter": ("left_gripper", "right_gripper")}


def reachable_tasks(robot, rng):
    q = robot.random_q(rng)
    frames = FRAMES[robot.name]
    tasks = [FrameTask(f, T) for f, T in zip(frames, robot.frame_placements(q, frames), strict=True)]
    if robot.floating:
        tasks.append(ComTask(robot.com(q)))
    return q, [*tasks, PostureTask()]


def assert_met_by_pinocchio(robot, tasks, q, tol=1e-6):
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    for task in tasks:
        if isinstance(task, FrameTask):
            M = data.oMf[model.getFrameId(task.frame)]
            assert np.linalg.norm(M.translation - task.target.translation) <= tol
            assert np.linalg.norm(pin.log3(M.rotation.T @ task.target.rotation)) <= tol
        elif isinstance(task, ComTask):
            assert np.linalg.norm(pin.centerOfMass(model, data, q) - task.target) <= tol
    assert np.all(q >= robot.lower - 1e-9) and np.all(q <= robot.upper + 1e-9)
    assert pin.isNormalized(model, q, 1e-9)


@pytest.mark.parametrize("solver", ["step", "frdm"])
@pytest.mark.parametrize("name", list(FRAMES))
def test_reachable_targets_are_met_and_judged(name, solver):
    robot = kinelab.load(name)
    rng = np.random.default_rng(21)
    for k in range(6):
        q_true, tasks = reachable_tasks(robot, rng)
        start = robot.neutral()
        start[:7] = q_true[:7] if robot.floating else start[:7]
        res = kinelab.solve(robot, tasks, q0=start, solver=solver, seed=k, time_budget=None, max_restarts=100)
        assert res.success and res.status == "converged", (k, res.message)
        assert all(v.met for v in res.tasks) and res.judge == "Pinocchio FK"
        assert_met_by_pinocchio(robot, tasks, res.q)


def test_baxter_holds_a_box_with_both_grippers():
    baxter = kinelab.load("baxter")
    box = pin.SE3(pin.rpy.rpyToMatrix(0, 0, 0), np.array([0.75, 0.0, 0.25]))  # the box's frame, base frame
    left = box * pin.SE3(pin.rpy.rpyToMatrix(np.pi / 2, 0, 0), np.array([0, 0.18, 0]))
    right_in_left = (box * pin.SE3(pin.rpy.rpyToMatrix(-np.pi / 2, 0, 0), np.array([0, -0.18, 0]))).inverse() * left
    tasks = [FrameTask("left_gripper", left), RelativeFrameTask("left_gripper", "right_gripper", right_in_left),
             PostureTask()]
    res = kinelab.solve(baxter, tasks, seed=0, time_budget=None, max_restarts=100)
    assert res.success, res.message
    data = baxter.model.createData()
    pin.framesForwardKinematics(baxter.model, data, res.q)
    oMl, oMr = (data.oMf[baxter.model.getFrameId(f)] for f in ("left_gripper", "right_gripper"))
    assert np.abs((oMr.inverse() * oMl).homogeneous - right_in_left.homogeneous).max() <= 1e-6


def test_a_target_no_configuration_meets_is_reported_per_task():
    talos = kinelab.load("talos")
    q = talos.random_q(3)
    feet = talos.frame_placements(q, FRAMES["talos"][:2])
    far = pin.SE3(np.eye(3), feet[0].translation + np.array([3.0, 0.0, 0.0]))  # a hand 3 m from the foot
    tasks = [FrameTask("left_sole_link", feet[0]), FrameTask("right_sole_link", feet[1]),
             FrameTask("gripper_left_base_link", far), PostureTask()]
    res = kinelab.solve(talos, tasks, q0=q, seed=0, max_restarts=2, time_budget=2.0)
    assert not res.success and res.status != "converged"
    verdicts = {v.label: v for v in res.tasks}
    assert not verdicts["pose of gripper_left_base_link"].met
    assert verdicts["pose of gripper_left_base_link"].position_error > 1.0
    assert "gripper_left_base_link" in res.message


def test_a_whole_robot_with_a_pose_is_told_how_to_ask():
    with pytest.raises(kinelab.ChainError, match="FrameTask"):
        kinelab.solve(kinelab.load("talos"), pin.SE3.Identity())


def test_a_chain_takes_tasks_on_its_own_joints():
    """#68: tasks on a chain (its own joints; the rest held as the chain holds them): 10 seeded tool targets as a
    FrameTask with a posture, each met by the converged solve, judged by the chain's own FK (Pinocchio's) within its
    limits; a problem on the chain steps toward one."""
    panda = kinelab.load("panda")
    rng = np.random.default_rng(68)
    for k in range(10):
        T = panda.fk(panda.random_q(rng))
        res = kinelab.solve(panda, [FrameTask(panda.tool, T), PostureTask()], seed=k, time_budget=None,
                            max_restarts=50)
        assert res.success, res.message
        assert np.linalg.norm(pin.log6(panda.fk(res.q).actInv(T)).vector) <= 2e-6 and panda.within_limits(res.q)
    target = panda.fk(panda.random_q(rng))
    q = panda.random_q(rng)
    problem = kinelab.WholeBody(panda, [FrameTask(panda.tool, target)])
    first = np.linalg.norm(pin.log6(panda.fk(q).actInv(target)).vector)
    for _ in range(50):
        q = problem.step(q, 0.05).q
    assert np.linalg.norm(pin.log6(panda.fk(q).actInv(target)).vector) < 0.5 * first
