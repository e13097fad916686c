"""#59: every task's error and rate matrix against Pinocchio, on the whole robots: the error from Pinocchio's own FK
and centre of mass, and ``A v`` against central differences of that error along ``pin.integrate`` (1e-6 relative)."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.wholebody import ComTask, FrameTask, PostureTask, RelativeFrameTask
from kinelab.wholebody import evaluate as ev

ROBOTS = {"talos": ("left_sole_link", "gripper_right_base_link"),
          "g1": ("left_ankle_roll_link", "right_wrist_yaw_link"), "baxter": ("left_gripper", "right_gripper")}


@pytest.fixture(scope="module", params=list(ROBOTS))
def robot(request):
    return kinelab.load(request.param)


def error(robot, task, q):
    """The task's error at q, from a fresh Pinocchio pass."""
    ev.forward(robot, q, com=isinstance(task, ComTask))
    if isinstance(task, PostureTask):
        return ev.posture_error(robot, task, q)
    return ev.task_rows(robot, task)[1]


def tasks_of(robot, rng):
    a, b = ROBOTS[robot.name]
    q = robot.random_q(rng)
    Ta, Tb = robot.frame_placements(q, [a, b])
    tasks = [FrameTask(a, Ta * pin.exp6(rng.normal(size=6) * 0.3), task=kind) for kind in
             ("pose", "position", "orientation")]
    tasks += [FrameTask(b, Tb * pin.exp6(rng.normal(size=6) * 0.3), task="axis", axis=ax) for ax in "xyz"]
    tasks += [RelativeFrameTask(a, b, (Tb.inverse() * Ta) * pin.exp6(rng.normal(size=6) * 0.2)),
              ComTask(robot.com(q) + rng.normal(size=3) * 0.05), ComTask(robot.com(q), axes="xy"),
              PostureTask(robot.random_q(rng))]
    return tasks


def test_each_rate_matrix_is_the_derivative_of_its_error(robot):
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, v = robot.random_q(rng), rng.normal(size=robot.nv)
        for task in tasks_of(robot, rng):
            ev.forward(robot, q, com=True)
            rows = ev.posture_mask(robot, task) if isinstance(task, PostureTask) else slice(None)
            A = np.eye(robot.nv) if isinstance(task, PostureTask) else ev.task_rows(robot, task)[0]
            h = 1e-6
            fd = (error(robot, task, pin.integrate(robot.model, q, h * v))
                  - error(robot, task, pin.integrate(robot.model, q, -h * v))) / (2 * h)
            fd, A = fd[rows], A[rows]  # a posture pulls the joints, not the free-flyer (its rows: the identity)
            assert np.abs(fd - A @ v).max() <= 1e-6 * max(1.0, np.abs(A @ v).max()), task.label


def test_each_error_is_pinocchios_gap_to_the_target(robot):
    rng = np.random.default_rng(8)
    model, data = robot.model, robot.model.createData()
    for task in tasks_of(robot, rng)[:4]:
        q = robot.random_q(rng)
        pin.framesForwardKinematics(model, data, q)
        e = error(robot, task, q)
        oMf = data.oMf[model.getFrameId(task.frame)]
        if task.task == "pose":
            assert np.allclose(e[:3], oMf.translation - task.target.translation, atol=1e-12)
            assert np.allclose(e[3:], pin.log3(oMf.rotation.T @ task.target.rotation), atol=1e-12)
        elif task.task == "position":
            assert np.allclose(e, oMf.translation - task.target.translation, atol=1e-12)
        elif task.task == "orientation":
            assert np.allclose(e, pin.log3(oMf.rotation.T @ task.target.rotation), atol=1e-12)
    com_task = ComTask(np.zeros(3))
    q = robot.random_q(rng)
    assert np.allclose(error(robot, com_task, q), pin.centerOfMass(model, data, q), atol=1e-12)
