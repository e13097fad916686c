"""Tasks: position, axis and orientation targets, judged by Pinocchio on the components they constrain."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import OptionError, load

ARMS = ("so101", "finger_edu", "ur5", "panda", "youbot")
TASKS = ("position", "axis", "orientation")


def task_targets(robot, task, count, seed):
    """FK-generated targets; position targets get random (mostly unreachable) orientations, axis targets a
    random roll about the tool z axis (the free component)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        T = robot.fk(robot.random_q(rng))
        if task == "position":
            T = pin.SE3(pin.exp3(rng.normal(size=3)), T.translation)
        elif task == "axis":
            T = pin.SE3(T.rotation @ pin.exp3(np.array([0.0, 0.0, rng.uniform(-3, 3)])), T.translation)
        out.append(T)
    return out


def judged_here(robot, q, target, task):
    """The test's own verdict from Pinocchio's FK: only the task's components, within the limits."""
    M = robot.fk(q)
    dp = np.linalg.norm(M.translation - target.translation)
    full = np.linalg.norm(pin.log3(target.rotation.T @ M.rotation))
    u, v = M.rotation[:, 2], target.rotation[:, 2]
    axis = np.arctan2(np.linalg.norm(np.cross(u, v)), u @ v)
    within = robot.within_limits(q)
    return within and {"position": dp <= 1e-6, "axis": dp <= 1e-6 and axis <= 1e-6,
                       "orientation": full <= 1e-6}[task]


@pytest.mark.parametrize("solver", ["frdm", "dls"])
@pytest.mark.parametrize("task", TASKS)
@pytest.mark.parametrize("name", ARMS)
def test_each_task_is_solved_and_judged_on_its_components_only(name, task, solver):
    robot = load(name)
    targets = task_targets(robot, task, 12, seed=10 * ARMS.index(name) + TASKS.index(task))
    solved = 0
    for k, target in enumerate(targets):
        res = kinelab.solve(robot, target, solver=solver, task=task, seed=k, time_budget=None, max_restarts=60)
        assert res.success == judged_here(robot, res.q, target, task), (k, res.status, res.message)
        assert res.task == ("axis z" if task == "axis" else task)
        solved += res.success
    assert solved >= 11  # measured: FRDM and DLS miss 2 of 40 axis targets on so101 (FRDM on panda too); bounded
    # by a count of restarts, not a clock: with 0.3 s a solve, a busy machine (two test runs side by side) missed 3


def test_a_position_task_ignores_an_unreachable_orientation_that_the_pose_task_cannot_meet():
    robot = load("so101")
    target = kinelab.target_from_xyz_rpy([0.2, 0.0, 0.15])  # identity rotation: out of a 5-joint arm's reach
    pose = kinelab.solve(robot, target, seed=1, time_budget=0.1)
    assert not pose.success
    assert "so101 has 5 joints" in pose.message and "task='axis'" in pose.message
    position = kinelab.solve(robot, target, task="position", seed=1, time_budget=1.0)
    assert position.success and position.position_error <= 1e-6 and position.rotation_error > 0.1


def test_the_axis_task_leaves_the_roll_free_and_holds_the_other_axes():
    robot = load("ur5")
    q = robot.random_q(3)
    T = robot.fk(q)
    for axis, column in (("x", 0), ("y", 1), ("z", 2)):
        rolled = pin.SE3(T.rotation @ pin.exp3(np.eye(3)[column] * 1.0), T.translation)  # 1 rad about that axis
        res = kinelab.solve(robot, rolled, task="axis", axis=axis, seed=0, time_budget=0.3)
        assert res.success and res.task == f"axis {axis}"
        M = robot.fk(res.q)
        assert np.allclose(M.rotation[:, column], rolled.rotation[:, column], atol=2e-6)


def test_the_biquaternion_solver_and_unknown_tasks_are_refused_with_what_is_valid():
    robot = load("ur5")
    target = robot.fk(robot.random_q(0))
    with pytest.raises(OptionError, match="'pose' for solver 'biquat'"):
        kinelab.solve(robot, target, solver="biquat", task="position")
    with pytest.raises(OptionError, match="pose, position, axis, orientation"):
        kinelab.solve(robot, target, task="reach")
    with pytest.raises(OptionError, match="'x', 'y' or 'z'"):
        kinelab.solve(robot, target, task="axis", axis="w")


def test_a_batch_takes_the_task_and_agrees_with_single_solves():
    robot = load("panda")
    targets = task_targets(robot, "axis", 20, seed=4)
    batch = kinelab.solve_batch(robot, targets, seed=9, task="axis")
    for b in range(20):
        one = kinelab.solve(robot, targets[b], seed=9 + b, task="axis", time_budget=60.0)
        np.testing.assert_array_equal(batch.q[b], one.q)
        assert batch.success[b] == one.success == judged_here(robot, one.q, targets[b], "axis")
        assert batch.rotation_error[b] == pytest.approx(one.rotation_error, abs=1e-9)


def test_a_stalled_attempt_is_finished_by_gauss_newton_steps_on_the_task_components():
    """Near the Stanford arm's retracted-boom singularity FRDM's sweeps stall short of 1e-6 on axis targets;
    the compiled multistart's Gauss-Newton steps finish them (the roll stays free), and stall_polish=0
    gives the paper's FRDM alone."""
    robot = load("stanford")
    rng = np.random.default_rng(0)
    finished = stalled = 0
    for _ in range(400):
        q = robot.random_q(rng)
        if q[2] > 0.02:  # targets with the boom nearly retracted
            continue
        target = pin.SE3(robot.fk(q).rotation @ pin.exp3(np.array([0.0, 0.0, 1.0])), robot.fk(q).translation)
        # the paper's FRDM, whose stalls the polish is for (the Newton finish would mostly pre-empt them)
        pure = kinelab.solve(robot, target, task="axis", seed=0, max_restarts=0, stall_polish=0, finish="none")
        if pure.success:
            continue
        stalled += 1
        assert pure.diagnostics.polished == 0
        res = kinelab.solve(robot, target, task="axis", seed=0, max_restarts=0, finish="none")
        if res.success:
            finished += 1
            assert res.diagnostics.polished == 1 and judged_here(robot, res.q, target, "axis")
        full = kinelab.solve(robot, target, task="axis", seed=0, time_budget=1.0)  # a budget a loaded machine meets
        assert full.success and judged_here(robot, full.q, target, "axis")
    assert stalled >= 5 and finished >= 3  # measured: 12 stalled, 4 finished from the first stall


def test_a_point_is_a_position_target_and_refused_as_a_pose_with_the_task_named():
    robot = load("so101")
    point = robot.fk(robot.random_q(3)).translation
    res = kinelab.solve(robot, list(point), task="position", seed=0)
    assert res.success and np.linalg.norm(robot.fk(res.q).translation - point) <= 1e-6
    assert kinelab.solve_all(robot, tuple(point), task="position", seed=0, max_solutions=1)[0].success
    for task in ("pose", "axis", "orientation"):
        with pytest.raises(kinelab.TargetError, match="task='position'"):
            kinelab.solve(robot, point, task=task)
    with pytest.raises(kinelab.TargetError, match="NaN"):
        kinelab.solve(robot, [0.1, np.inf, 0.0], task="position")
    with pytest.raises(kinelab.TargetError, match="pin.SE3"):
        kinelab.solve(robot, [0.1, 0.2], task="position")


def test_an_orientation_a_three_joint_finger_cannot_make_gets_an_honest_status_and_message():
    robot = load("finger_edu")
    target = pin.SE3(pin.exp3(np.array([2.0, 0.5, 0.3])), np.zeros(3))
    res = kinelab.solve(robot, target, task="orientation", seed=0, time_budget=0.05)
    assert not res.success and res.status in (kinelab.Status.STALLED, kinelab.Status.TIME_BUDGET)
    assert "met the rotation" in res.message and " m " not in res.message  # only the judged component
    assert res.rotation_error == pytest.approx(judged_rotation(robot, res.q, target), abs=1e-12)


def judged_rotation(robot, q, target):
    return float(np.linalg.norm(pin.log3(target.rotation.T @ robot.fk(q).rotation)))
