"""#69 (loading): an MJCF file's <equality> connects and welds are the robot's loops, read through Pinocchio 4's
buildModelAndConstraintsFromMJCF; its actuators name the actuated joints. Each loop's error and Jacobian equal the
constraint models Pinocchio returns for the file (1e-12) at seeded q; the step holds them."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import FrameTask

FOURBAR = """<mujoco model="mjcf_fourbar">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">
      <body name="crank">
        <joint name="crank_joint" type="hinge" axis="0 0 1" range="-6.28 6.28"/>
        <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.005" mass="0.1"/>
        <body name="coupler" pos="0.1 0 0" euler="0 0 1.2">
          <joint name="coupler_joint" type="hinge" axis="0 0 1" range="-6.28 6.28"/>
          <geom type="capsule" fromto="0 0 0 0.28 0 0" size="0.005" mass="0.1"/>
        </body>
      </body>
      <body name="rocker" pos="0.3 0 0" euler="0 0 1.4">
        <joint name="rocker_joint" type="hinge" axis="0 0 1" range="-6.28 6.28"/>
        <geom type="capsule" fromto="0 0 0 0.22 0 0" size="0.005" mass="0.1"/>
      </body>
      <body name="arm_a" pos="0 0.5 0">
        <joint name="a1" type="hinge" axis="0 0 1" range="-3 3"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.005" mass="0.1"/>
        <body name="a2" pos="0.2 0 0">
          <joint name="a2_joint" type="hinge" axis="0 0 1" range="-3 3"/>
          <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.005" mass="0.1"/>
          <body name="a3" pos="0.2 0 0">
            <joint name="a3_joint" type="hinge" axis="0 0 1" range="-3 3"/>
            <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.005" mass="0.1"/>
          </body>
        </body>
      </body>
      <body name="arm_b" pos="0.5 0.55 0" euler="0 0 3.0">
        <joint name="b1" type="hinge" axis="0 0 1" range="-3 3"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.005" mass="0.1"/>
        <body name="b2" pos="0.2 0 0">
          <joint name="b2_joint" type="hinge" axis="0 0 1" range="-3 3"/>
          <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.005" mass="0.1"/>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="knee" body1="coupler" body2="rocker" anchor="0.28 0 0"/>
    <weld name="grip" body1="a3" body2="b2"/>
  </equality>
  <actuator>
    <motor name="drive" joint="crank_joint"/>
    <motor name="shoulder" joint="a1"/>
  </actuator>
</mujoco>
"""


@pytest.fixture()
def mjcf(tmp_path: Path) -> Path:
    path = tmp_path / "loops.xml"
    path.write_text(FOURBAR)
    return path


def test_the_equalities_are_the_loops_and_the_actuators_the_actuated_joints(mjcf: Path) -> None:
    robot = kinelab.load(mjcf, whole=True)
    assert [(c.frame_a, c.frame_b, c.kind) for c in robot.closures] == [("knee_a", "knee_b", "point"),
                                                                          ("grip_a", "grip_b", "frame")]
    assert robot.actuated == ("crank_joint", "a1")
    assert np.abs(robot.closure_error(robot.neutral())).max() <= 1e-12  # MuJoCo's anchors meet at qpos0


@pytest.mark.parametrize("seed", range(10))
def test_each_loop_is_pinocchios_constraint_model(mjcf: Path, seed: int) -> None:
    """kinelab's error and Jacobian per loop against the models Pinocchio builds for the file: a connect's exactly
    (PointAnchor), a weld's rotation error (FrameAnchor's angular part) at any q and its Jacobian where closed."""
    robot = kinelab.load(mjcf, whole=True)
    model, points, frames = pin.buildModelAndConstraintsFromMJCF(str(mjcf))
    q = robot.random_q(seed)
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    point, weld = points[0], frames[0]
    point_data, weld_data = point.createData(), weld.createData()
    point.calc(model, data, point_data)
    weld.calc(model, data, weld_data)
    e, J = robot.closure_error(q), robot.closure_jacobian(q)
    assert np.abs(e[:3] - point_data.constraint_position_error).max() <= 1e-12
    assert np.abs(J[:3] - point.jacobian(model, data, point_data)).max() <= 1e-12
    assert np.abs(e[6:] - weld_data.constraint_position_error[3:]).max() <= 1e-12
    near = robot.neutral() + np.random.default_rng(seed).uniform(-0.3, 0.3, robot.nq)  # a motor pose it assembles
    closed = robot.assemble(near)
    pin.computeJointJacobians(model, data, closed)
    pin.updateFramePlacements(model, data)
    weld.calc(model, data, weld_data)
    assert np.abs(robot.closure_jacobian(closed)[3:] - weld.jacobian(model, data, weld_data)).max() <= 1e-9


def test_the_step_holds_the_files_loops(mjcf: Path) -> None:
    """The knee moved along its coupler curve (its place with the crank 0.3 rad on) in 100 steps: every loop
    closed to 1e-9 after each step, the knee on its target at the end (1e-6 m)."""
    robot = kinelab.load(mjcf, whole=True)
    q = robot.assemble(robot.neutral())
    moved = q.copy()
    moved[0] += 0.3
    target = robot.frame_placement(robot.assemble(moved), "knee_a").translation
    problem = kinelab.WholeBody(robot, [FrameTask("knee_a", target, task="position")])
    for _ in range(100):
        result = problem.step(q, 0.01)
        assert result.solved
        q = result.q
        assert np.abs(robot.closure_error(q)).max() <= 1e-9
    assert np.linalg.norm(robot.frame_placement(q, "knee_a").translation - target) <= 1e-6


def test_an_inactive_equality_is_no_loop(tmp_path: Path) -> None:
    path = tmp_path / "inactive.xml"
    path.write_text(FOURBAR.replace('<weld name="grip"', '<weld name="grip" active="false"'))
    assert [c.frame_a for c in kinelab.load(path, whole=True).closures] == ["knee_a"]


def test_a_file_without_equalities_declares_nothing(tmp_path: Path) -> None:
    path = tmp_path / "open.xml"
    path.write_text(FOURBAR.split("  <equality>")[0] + "</mujoco>\n")
    robot = kinelab.load(path, whole=True)
    assert robot.closures == () and robot.actuated == ()


GRIPPER = """<mujoco model="mjcf_gripper">
  <compiler angle="degree"/>
  <worldbody>
    <body name="palm">
      <body name="left" pos="0 0.02 0">
        <joint name="left_finger" type="hinge" axis="0 0 1" range="-60 60" ref="10"/>
        <geom type="capsule" fromto="0 0 0 0.05 0 0" size="0.005" mass="0.01"/>
      </body>
      <body name="right" pos="0 -0.02 0">
        <joint name="right_finger" type="hinge" axis="0 0 1" range="-60 60" ref="-5"/>
        <geom type="capsule" fromto="0 0 0 0.05 0 0" size="0.005" mass="0.01"/>
      </body>
      <body name="slider" pos="0 0 0.05">
        <joint name="slide" type="slide" axis="1 0 0" range="0 0.04"/>
        <geom type="sphere" size="0.01" mass="0.01"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint name="mirror" joint1="right_finger" joint2="left_finger" polycoef="0.1 -1 0 0 0"/>
    <joint name="drive" joint1="slide" joint2="left_finger" polycoef="0.01 0.02 0 0 0"/>
    <joint name="bent" joint1="slide" joint2="right_finger" polycoef="0 0.01 0.3 0 0" active="false"/>
  </equality>
  <actuator><motor joint="left_finger"/></actuator>
</mujoco>
"""


def test_an_mjcf_joint_equality_is_a_coupling_with_mujocos_meaning(tmp_path: Path) -> None:
    """A mimic gripper written with MJCF joint equalities (refs, a slide driven by a hinge): each linear one is a
    coupling whose residual equals MuJoCo's own equality residual at 20 seeded qpos (1e-12), the inactive one is
    left out; the step holds them while the leader moves."""
    mujoco = pytest.importorskip("mujoco")
    path = tmp_path / "gripper.xml"
    path.write_text(GRIPPER)
    robot = kinelab.load(path, whole=True)
    assert [(m.name, m.leader) for m in robot.mimics] == [("right_finger", "left_finger"), ("slide", "left_finger")]
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(692)
    index = {j.name: robot.model.joints[robot.model.getJointId(j.name)].idx_q for j in robot.mimics}
    index["left_finger"] = robot.model.joints[robot.model.getJointId("left_finger")].idx_q
    for _ in range(20):
        d.qpos[:] = rng.uniform(-1.0, 1.0, m.nq)
        mujoco.mj_forward(m, d)
        residual = [d.qpos[m.joint(c.name).qposadr[0]] - c.multiplier * d.qpos[m.joint(c.leader).qposadr[0]]
                    - c.offset for c in robot.mimics]
        mj = d.efc_pos[:d.nefc][d.efc_type[:d.nefc] == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)]
        assert np.abs(np.array(residual) - mj).max() <= 1e-12
    q = robot.neutral()
    problem = kinelab.WholeBody(robot, [kinelab.PostureTask(q)])
    for k in range(50):
        q = q.copy()
        q[index["left_finger"]] = 0.5 * np.sin(0.05 * k)
        q = problem.step(q, 0.01).q
        for c in robot.mimics:
            assert abs(q[index[c.name]] - c.multiplier * q[index[c.leader]] - c.offset) <= 1e-9
