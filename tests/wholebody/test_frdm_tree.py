"""#59: FRDM on the tree keeps its task points current between turns without forward kinematics (each turn moves
its subtree's points, targets carried by a relative task's root, and the subtree centres of mass as one rigid
motion). After a sweep's turns those points must be Pinocchio's: its frame placements and centre of mass at the new
configuration, on a humanoid (free-flyer, centre of mass), a two-armed robot (a relative task) and PR2 (a prismatic
torso, continuous wrists)."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.wholebody import ComTask, FrameTask, PostureTask, RelativeFrameTask
from kinelab.wholebody.frdm import sweep_joints, task_points, tree_joints

HANDS = {"talos": ("gripper_left_base_link", "gripper_right_base_link", "left_sole_link"),
         "baxter": ("left_gripper", "right_gripper", "head"),
         "pr2": ("l_gripper_tool_frame", "r_gripper_tool_frame", "head_plate_frame")}


def tasks_for(robot, rng):
    far = robot.frame_placements(robot.random_q(rng), HANDS[robot.name])
    tasks = [FrameTask(HANDS[robot.name][0], far[0]),
             FrameTask(HANDS[robot.name][2], far[2], task="axis", axis="z"),
             RelativeFrameTask(HANDS[robot.name][1], HANDS[robot.name][0], far[0].actInv(far[1]))]
    if robot.floating:
        tasks.append(ComTask(robot.com(robot.random_q(rng)), axes="xy"))
    return tuple(tasks)


@pytest.mark.parametrize("name", list(HANDS))
def test_a_sweep_keeps_every_task_point_where_pinocchio_puts_it(name):
    robot = kinelab.load(name)
    rng = np.random.default_rng(5)
    joints = tree_joints(robot)
    data = robot.model.createData()
    for _ in range(5):
        tasks, q = tasks_for(robot, rng), robot.random_q(rng)
        before = q.copy()
        swept = sweep_joints(robot, tasks, q, joints, data)
        assert np.abs(pin.difference(robot.model, before, q)).max() > 1e-3  # the sweep turned something
        fresh_data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, fresh_data, q)
        com = pin.centerOfMass(robot.model, fresh_data, q) if robot.floating else None
        fresh = task_points(robot, tasks, fresh_data, com)
        assert np.abs(swept.p - fresh.p).max() <= 1e-10
        assert np.abs(swept.t - fresh.t).max() <= 1e-10
        assert robot.within_limits(q)


def test_a_posture_is_left_to_the_finish_and_frdm_meets_the_tasks():
    baxter = kinelab.load("baxter")
    rng = np.random.default_rng(9)
    q_true = baxter.random_q(rng)
    hands = baxter.frame_placements(q_true, HANDS["baxter"][:2])
    tasks = [FrameTask("left_gripper", hands[0]), FrameTask("right_gripper", hands[1]), PostureTask()]
    res = kinelab.solve(baxter, tasks, solver="frdm", seed=1, time_budget=None, max_restarts=100)
    assert res.success and res.solver == "frdm"
    got = baxter.frame_placements(res.q, HANDS["baxter"][:2])
    for M, T in zip(got, hands, strict=True):
        assert np.linalg.norm(pin.log6(M.actInv(T)).vector) <= 2e-6
