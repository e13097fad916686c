"""#69: Cassie (urdf/cassie.xml, MuJoCo Menagerie's model reduced to its kinematics), loaded through Pinocchio 4's
MJCF loader with its four <connect> loops. Pinocchio places every body where MuJoCo does (1e-12) with the file's
joint ranges; each loop's error and Jacobian are Pinocchio's PointAnchor models and central differences; the
assembly closes the loops within the limits with the motors held; the step holds the loops; the converged solve
places both feet and the pelvis with every loop closed (judged by Pinocchio's FK)."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import assembled_draws

import kinelab
from kinelab import AssemblyError, FrameTask
from kinelab.wholebody import constraints
from kinelab.wholebody.tasks import TaskError

FEET = ("left-foot", "right-foot")


@pytest.fixture(scope="module")
def cassie() -> kinelab.Robot:
    return kinelab.load("cassie")


def motors(robot: kinelab.Robot) -> list[int]:
    return [robot.model.joints[robot.model.getJointId(a)].idx_q for a in robot.actuated]


def mujoco_to_pinocchio(robot: kinelab.Robot, qpos: np.ndarray) -> np.ndarray:
    """MuJoCo's qpos in Pinocchio's order: quaternions (w, x, y, z) → (x, y, z, w), the free joint's and the balls'."""
    q = qpos.copy()
    for j in range(1, robot.model.njoints):
        if robot.model.joints[j].nq == 4 or robot.model.joints[j].nq == 7:
            i = robot.model.joints[j].idx_q + (3 if robot.model.joints[j].nq == 7 else 0)
            q[i:i + 4] = qpos[i + 1], qpos[i + 2], qpos[i + 3], qpos[i]
    return q


def test_pinocchio_places_every_body_where_mujoco_does() -> None:
    """20 seeded qpos (every hinge in [-1, 1] rad, random quaternions): each body's placement by Pinocchio equals
    MuJoCo's (1e-12), and every bounded joint's limits are MuJoCo's ranges (the knee's and the tarsus's ``ref``)."""
    mujoco = pytest.importorskip("mujoco")
    robot = kinelab.load("cassie")
    m = mujoco.MjModel.from_xml_path(str(robot.source))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(690)
    for _ in range(20):
        qpos = rng.uniform(-1.0, 1.0, m.nq)
        free, ball = int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL)
        for j in range(m.njnt):
            a = m.jnt_qposadr[j] + (3 if m.jnt_type[j] == free else 0)
            if m.jnt_type[j] in (free, ball):
                quat = rng.normal(size=4)
                qpos[a:a + 4] = quat / np.linalg.norm(quat)
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, mujoco_to_pinocchio(robot, qpos))
        for b in range(1, m.nbody):
            oMb = data.oMf[robot.model.getFrameId(m.body(b).name, pin.FrameType.BODY)]
            assert np.abs(oMb.translation - d.xpos[b]).max() <= 1e-12
            assert np.abs(oMb.rotation - d.xmat[b].reshape(3, 3)).max() <= 1e-12
    for j in range(m.njnt):
        if m.jnt_limited[j] and m.jnt_type[j] == int(mujoco.mjtJoint.mjJNT_HINGE):
            i = robot.model.joints[robot.model.getJointId(m.joint(j).name)].idx_q
            assert robot.model.lowerPositionLimit[i] == pytest.approx(m.jnt_range[j][0], abs=1e-12)
            assert robot.model.upperPositionLimit[i] == pytest.approx(m.jnt_range[j][1], abs=1e-12)


def test_the_four_connects_are_its_loops_and_the_ten_motors_its_actuated_joints(cassie: kinelab.Robot) -> None:
    assert cassie.floating and (cassie.nq, cassie.nv) == (35, 32)
    assert {c.frame_a for c in cassie.closures} == {f"{side}-{rod}-rod_a" for side in ("left", "right")
                                                   for rod in ("plantar", "achilles")}
    assert all(c.kind == "point" for c in cassie.closures)
    assert cassie.actuated == tuple(f"{side}-{j}" for side in ("left", "right")
                                    for j in ("hip-roll", "hip-yaw", "hip-pitch", "knee", "foot"))


@pytest.mark.parametrize("seed", range(8))
def test_each_loop_is_pinocchios_point_anchor_and_its_jacobian_the_difference(cassie: kinelab.Robot,
                                                                             seed: int) -> None:
    """At a seeded q (off the loops): the errors and Jacobians equal the PointAnchor models Pinocchio builds for the
    file (1e-12), and each Jacobian the central difference through pin.integrate (h = 1e-5; 1e-7)."""
    model, points, _ = pin.buildModelAndConstraintsFromMJCF(str(cassie.source))
    q = cassie.random_q(seed)
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    e, J = cassie.closure_error(q), cassie.closure_jacobian(q)
    for k, point in enumerate(points):
        point_data = point.createData()
        point.calc(model, data, point_data)
        assert np.abs(e[3 * k:3 * k + 3] - point_data.constraint_position_error).max() <= 1e-12
        assert np.abs(J[3 * k:3 * k + 3] - point.jacobian(model, data, point_data)).max() <= 1e-12
    h = 1e-5  # the unbounded joints' random angles reach hundreds of rad: a smaller h meets their rounding
    for i in range(cassie.nv):
        dv = np.zeros(cassie.nv)
        dv[i] = h
        ahead, behind = cassie.integrate(q, dv), cassie.integrate(q, -dv)
        rate = (cassie.closure_error(ahead) - cassie.closure_error(behind)) / (2 * h)
        assert np.abs(rate - J[:, i]).max() <= 1e-7


def test_the_assembly_closes_the_loops_within_the_limits_with_the_motors_held(cassie: kinelab.Robot) -> None:
    """60 seeded motor draws within the limits, from the standing pose: each assembly claimed has every loop closed
    to 1e-10, every joint within its limits and the motors exactly where they were put; a refusal leaves no
    assembly found from 21 starts. At least 50 are claimed (a shin spring at its stop, the tarsus and the heel
    spring take up the rest)."""
    index = motors(cassie)
    claimed = 0
    for q, found in assembled_draws(cassie, 60, np.random.default_rng(69)):
        if found is None:
            continue
        claimed += 1
        assert np.abs(cassie.closure_error(found)).max() <= 1e-10
        assert cassie.within_limits(found)
        assert np.array_equal(found[index], q[index]) and np.array_equal(found[:7], q[:7])
    assert claimed >= 50


def test_it_stands_on_the_files_home_keyframe(cassie: kinelab.Robot) -> None:
    """standing(): the file's "home" keyframe (MuJoCo's loops open there by 1.5 mm) with its loops closed (1e-10),
    within 0.05 rad of the keyframe, the pelvis at its height."""
    q = cassie.standing()
    assert np.abs(cassie.closure_error(q)).max() <= 1e-10 and cassie.within_limits(q)
    assert cassie.frame_placement(q, "cassie-pelvis").translation == pytest.approx([0.0, 0.0, 1.0059301], abs=1e-9)
    keyframe = np.array([e.data() for e in cassie.model.referenceConfigurations if e.key() == "home"][0])
    assert np.abs(cassie.difference(keyframe, q)).max() <= 0.05


def lift(cassie: kinelab.Robot, steps: int) -> tuple[float, float]:
    """The left foot moved to where the left hip pitch 0.3 rad and the knee -0.3 rad further put it (assembled), in
    ``steps`` steps of 10 ms, the right foot and the pelvis held: (largest loop error after a step, last left-foot
    error) [m]."""
    q = cassie.standing()
    bent = q.copy()
    for joint, turn in (("left-hip-pitch", 0.3), ("left-knee", -0.3)):
        bent[cassie.model.joints[cassie.model.getJointId(joint)].idx_q] += turn
    goal = cassie.frame_placement(cassie.assemble(bent), "left-foot")
    problem = kinelab.WholeBody(cassie, [FrameTask("left-foot", goal), FrameTask("right-foot", cassie.frame_placement(
        q, "right-foot")), FrameTask("cassie-pelvis", cassie.frame_placement(q, "cassie-pelvis"))])
    worst = 0.0
    for _ in range(steps):
        result = problem.step(q, 0.01)
        assert result.solved, result.status
        q = result.q
        worst = max(worst, float(np.abs(cassie.closure_error(q)).max()))
    reached = cassie.frame_placement(q, "left-foot")
    return worst, float(np.linalg.norm(reached.translation - goal.translation))


def test_the_step_holds_its_loops_and_fails_without_them(cassie: kinelab.Robot,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """200 steps: every loop closed to 1e-9 after each, the foot there at the end (1e-6 m). Without the closure
    rows the legs move as if open and the loops come apart (> 1e-3 m)."""
    worst, foot = lift(cassie, 200)
    assert worst <= 1e-9 and foot <= 1e-6
    monkeypatch.setattr(constraints.ClosureTask, "add_to",
                        lambda self, rows, robot, q, dt: TaskError(self.label, 0.0, 0.0))
    monkeypatch.setattr(constraints.ClosureTask, "project", lambda self, robot, q: None)
    open_worst, _ = lift(cassie, 50)
    assert open_worst > 1e-3


@pytest.mark.parametrize("seed", range(6))
def test_the_solve_places_both_feet_and_the_pelvis_with_its_loops_closed(cassie: kinelab.Robot, seed: int) -> None:
    """A target from a seeded motor draw and base pose (assembled): the solve from the standing pose converges,
    both feet and the pelvis within 1e-6 m / 1e-6 rad of their targets by Pinocchio's FK, every loop closed to
    1e-10, every joint within its limits."""
    rng = np.random.default_rng(6900 + seed)
    home = cassie.standing()
    while True:
        q = home.copy()
        q[motors(cassie)] = cassie.random_q(rng)[motors(cassie)]
        q = cassie.integrate(q, np.r_[rng.uniform(-0.2, 0.2, 6), np.zeros(cassie.nv - 6)])
        try:
            pose = cassie.assemble(q)
            break
        except AssemblyError:
            continue
    frames = (*FEET, "cassie-pelvis")
    targets = {f: cassie.frame_placement(pose, f) for f in frames}
    result = kinelab.solve(cassie, [FrameTask(f, targets[f]) for f in frames], q0=home, seed=seed)
    assert result.success, result.status
    data = cassie.model.createData()
    pin.framesForwardKinematics(cassie.model, data, result.q)
    for f in frames:
        error = pin.log6(targets[f].actInv(data.oMf[cassie.model.getFrameId(f, pin.FrameType.BODY)])).vector
        assert np.abs(error).max() <= 1e-6
    assert np.abs(cassie.closure_error(result.q)).max() <= 1e-10 and cassie.within_limits(result.q)


@pytest.mark.parametrize("name, frame", [("delta", "platform_centre"), ("fourbar", "coupler_tip"), ("ankle", "sole")])
def test_the_actuated_jacobian_is_the_motion_of_the_assemblies(name: str, frame: str) -> None:
    """robot.actuated_jacobian(q, frame): each motor's column against the central difference of the frame's place
    and turn between the assemblies with that motor ±1e-4 rad (each assembled from q, the loops to 1e-10), at the
    assemblies of 8 seeded motor draws within 0.3 rad of the standing pose (at least 5): within 1e-5 (m, rad per
    rad) of the largest column. Not Cassie: its springs let the foot move without a motor, so its motors do not
    decide the foot's motion (the least-norm one is a choice). A robot without loops is refused."""
    robot = kinelab.load(name)
    h = 1e-4
    checked = 0
    for _, closed in assembled_draws(robot, 8, np.random.default_rng(6901), spread=0.3):
        if closed is None:
            continue
        checked += 1
        G = robot.actuated_jacobian(closed, frame)
        for k, motor in enumerate(robot.actuated):
            iq = robot.model.joints[robot.model.getJointId(motor)].idx_q
            ends = []
            for sign in (1.0, -1.0):
                moved = closed.copy()
                moved[iq] += sign * h
                ends.append(robot.frame_placement(robot.assemble(moved), frame))
            rate = np.r_[(ends[0].translation - ends[1].translation) / (2 * h),
                         pin.log3(ends[0].rotation @ ends[1].rotation.T) / (2 * h)]
            assert np.abs(rate - G[:, k]).max() <= 1e-5 * max(1.0, np.abs(G).max())
    assert checked >= 5
    with pytest.raises(kinelab.OptionError):
        kinelab.load("ur5").robot.actuated_jacobian(kinelab.load("ur5").robot.neutral(), "tool0")
