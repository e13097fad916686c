from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from helpers import no_hang, revolute, write_urdf

import kinelab
from kinelab.analysis.oracles import pose_error

TWO_LINK = (
    '<link name="base"/><link name="l1"/><link name="l2"/><link name="tool"/>'
    + revolute("j1", "base", "l1")
    + revolute("j2", "l1", "l2", axis="0 1 0")
    + '<joint name="jt" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0 0 0.3"/></joint>'
)


def test_youbot_has_the_papers_eight_coordinates_in_order_with_the_papers_limits():
    robot = kinelab.load("youbot")
    assert robot.joint_names == ["platform_x", "platform_y", "platform_yaw",
                                 "arm_joint_1", "arm_joint_2", "arm_joint_3", "arm_joint_4", "arm_joint_5"]
    assert robot.joint_kinds[:3] == ["prismatic", "prismatic", "continuous"]
    assert (robot.n, robot.nq, robot.nv) == (8, 9, 8)
    np.testing.assert_allclose(np.rad2deg(robot.lower[3:]), [-169, -65, -151, -102.5, -167.5], atol=1e-12)
    np.testing.assert_allclose(np.rad2deg(robot.upper[3:]), [169, 90, 146, 102.5, 167.5], atol=1e-12)


def test_youbot_candle_pose_matches_the_vendor_dimensions():
    robot = kinelab.load("youbot")
    oMtool = robot.fk(np.zeros(8))
    # joint-1 axis 0.167 ahead of C, a1 = 0.033; heights 0.161 + a2 0.155 + a3 0.135 + c 0.2175
    np.testing.assert_allclose(oMtool.translation, [0.2, 0.0, 0.6685], atol=1e-12)
    np.testing.assert_allclose(oMtool.rotation, np.eye(3), atol=1e-12)


def test_youbot_positive_theta2_bends_forward_and_theta1_turns_counter_clockwise():
    robot = kinelab.load("youbot")
    q = np.zeros(8)
    q[4] = 0.3
    assert robot.fk(q).translation[0] > 0.2
    q = np.zeros(8)
    q[3] = 0.3
    assert robot.fk(q).translation[1] > 0.0


def test_era_is_a_7r_chain_about_11_3_m_long():
    robot = kinelab.load("era")
    assert robot.n == 7 and set(robot.joint_kinds) == {"revolute"}
    assert robot.fk(np.zeros(7)).translation[2] == pytest.approx(11.28, abs=1e-12)


def test_continuous_joints_map_to_cos_sin_and_back(robots, rng):
    robot = robots["kinova"]
    assert robot.joint_kinds.count("continuous") == 3 and robot.nq == 9 and robot.nv == 6
    q = robot.random_q(rng)
    q_pin = robot.to_pin_q(q)
    i = robot.joints[0].idx_q
    np.testing.assert_allclose(q_pin[i : i + 2], [np.cos(q[0]), np.sin(q[0])])
    np.testing.assert_allclose(robot.from_pin_q(q_pin), q, atol=1e-15)


def test_random_q_is_seeded_and_within_limits(robots):
    for robot in robots.values():
        qs = robot.random_qs(500, 7)
        assert np.all(qs >= robot.lower) and np.all(qs <= robot.upper)
        np.testing.assert_array_equal(qs, robot.random_qs(500, 7))
        np.testing.assert_array_equal(robot.random_q(3), robot.random_q(3))


def test_fingers_are_locked_and_off_the_chain():
    panda = kinelab.load("panda")
    assert panda.n == 7 and panda.joint_names[-1] == "panda_joint7"
    assert set(panda.locked) == {"panda_finger_joint1", "panda_finger_joint2"}


def test_locking_a_chain_joint_holds_it_at_its_value(robots, rng):
    ur5 = robots["ur5"]
    locked = kinelab.load("ur5", locked={"elbow_joint": 0.7})
    assert locked.n == 5 and "elbow_joint" not in locked.joint_names
    q5 = locked.random_q(rng)
    q6 = np.insert(q5, 2, 0.7)
    dp, dr = pose_error(locked.fk(q5), ur5.fk(q6))
    assert dp < 1e-12 and dr < 1e-12


def test_jacobian_frames_are_related_by_the_tool_pose(robots, rng):
    robot = robots["panda"]
    q = robot.random_q(rng)
    oMtool = robot.fk(q)
    J_local = robot.jacobian_local(q)
    np.testing.assert_allclose(robot.jacobian_world(q), oMtool.action @ J_local, atol=1e-12)
    R = oMtool.rotation
    np.testing.assert_allclose(robot.jacobian_local_world_aligned(q)[:3], R @ J_local[:3], atol=1e-12)


def test_integrate_and_difference_go_through_pinocchio(robots, rng):
    robot = robots["kinova"]
    q0 = robot.random_q(rng)
    dq = rng.normal(size=robot.nv)
    q1 = robot.integrate(q0, dq)
    np.testing.assert_allclose(robot.difference(q0, q1), dq, atol=1e-12)
    expected = robot.from_pin_q(pin.integrate(robot.model, robot.to_pin_q(q0), dq))
    np.testing.assert_allclose(q1, expected)


def test_joint_placements_put_every_joint_on_the_chain(robots):
    robot = robots["era"]
    oMi = robot.joint_placements(np.zeros(7))
    assert list(oMi) == robot.joint_names
    np.testing.assert_allclose(oMi["joint4"].translation, [0, 0, 1.228 + 0.340 + 4.072])


def test_a_urdf_path_loads_with_a_tool_frame_found_by_name(tmp_path):
    robot = kinelab.load(write_urdf(tmp_path, TWO_LINK))
    assert robot.tool == "tool" and robot.joint_names == ["j1", "j2"]
    np.testing.assert_allclose(robot.fk([0, 0]).translation, [0, 0, 1.3])


# -- bad input -----------------------------------------------------------------------------------

def test_missing_file(tmp_path):
    with pytest.raises(kinelab.URDFError, match="not found"):
        kinelab.load(str(tmp_path / "nothing.urdf"))


def test_malformed_xml(tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(kinelab.URDFError, match="malformed"):
        kinelab.load(str(path))


def test_unknown_robot_name_lists_valid_names():
    with pytest.raises(kinelab.RobotNotFoundError, match="stanford, era, youbot"):
        kinelab.load("stanfrod")


def test_unknown_tool_frame_lists_frames():
    with pytest.raises(kinelab.FrameNotFoundError) as err:
        kinelab.load("ur5", tool="flange")
    assert "flange" in str(err.value) and "tool0" in str(err.value)


def test_unknown_locked_joint_lists_chain_joints():
    with pytest.raises(kinelab.JointNotFoundError, match="shoulder_pan_joint"):
        kinelab.load("ur5", locked={"elbow": 0.1})


def test_tree_with_ambiguous_tool_is_refused_with_its_leaves(tmp_path):
    body = ('<link name="base"/><link name="a"/><link name="b"/>'
            + revolute("ja", "base", "a") + revolute("jb", "base", "b"))
    with pytest.raises(kinelab.ChainError, match="ambiguous.*'a'.*'b'|ambiguous.*a, b"):
        kinelab.load(write_urdf(tmp_path, body))
    # naming the tool resolves it: the other branch is locked
    robot = kinelab.load(write_urdf(tmp_path, body), tool="b")
    assert robot.joint_names == ["jb"] and "ja" in robot.locked


def test_closed_loop_is_refused(tmp_path):
    body = ('<link name="base"/><link name="a"/><link name="b"/>'
            + revolute("ja", "base", "a") + revolute("jb", "a", "b") + revolute("jloop", "base", "b"))
    with pytest.raises(kinelab.ChainError, match="closed loop.*'b'"):
        kinelab.load(write_urdf(tmp_path, body))


def test_mimic_joint_on_the_chain_follows_its_leader_and_frdm_refuses_it(tmp_path):
    """(#15: mimic joints load through Pinocchio's model; tests/robot/test_mimic.py checks them.)"""
    body = ('<link name="base"/><link name="a"/><link name="b"/>'
            + revolute("ja", "base", "a")
            + revolute("jb", "a", "b", extra='<mimic joint="ja" multiplier="1"/>'))
    robot = kinelab.load(write_urdf(tmp_path, body))
    assert robot.joint_names == ["ja"] and list(robot.mimics) == ["jb"]
    with pytest.raises(kinelab.ChainError, match="jb.*mimic"):
        kinelab.solve(robot, robot.fk([0.3]))


def test_floating_joint_on_the_chain_is_refused(tmp_path):
    body = ('<link name="base"/><link name="a"/>'
            '<joint name="free" type="floating"><parent link="base"/><child link="a"/></joint>')
    with pytest.raises(kinelab.ChainError, match="free"):
        kinelab.load(write_urdf(tmp_path, body))


@pytest.mark.parametrize("bad, match", [
    ([0.1, 0.2], "must have 6 numbers"),
    ([[0.1] * 6], "must have 6 numbers"),
    ([0, 0, np.nan, 0, 0, 0], r"q\[2\] \(joint3\) is nan"),
    ([0, np.inf, 0.3, 0, 0, 0], "finite"),
    ("abc", "6 numbers"),
])
def test_bad_configurations_are_refused_with_the_reason(bad, match):
    robot = kinelab.load("stanford")
    with pytest.raises(kinelab.ConfigurationError, match=match):
        robot.fk(bad)


def test_limits_are_enforced_where_they_matter_and_name_the_joint():
    robot = kinelab.load("stanford")
    q = [0, 0, 1.5, 0, 0, 0]
    robot.fk(q)  # FK itself is defined outside the limits
    with pytest.raises(kinelab.JointLimitError, match=r"joint3.*1\.5 m.*\[0, 1\] m"):
        robot.check_q(q, limits=True)


# -- visual geometry and mesh paths ----------------------------------------------------------------

def test_panda_visuals_resolve_package_uris_to_existing_meshes():
    panda = kinelab.load("panda")
    geom = panda.visual_model()
    meshes = [g.meshPath for g in geom.geometryObjects if g.meshPath]
    assert len(meshes) >= 8
    assert all(Path(m).is_file() for m in meshes)
    assert all(g.parentJoint < panda.model.njoints for g in geom.geometryObjects)


def test_bundled_robots_draw_primitives_without_any_mesh():
    for name in ("stanford", "era", "youbot"):
        geom = kinelab.load(name).visual_model()
        assert geom.ngeoms >= 5 and not any(g.meshPath.endswith((".dae", ".stl")) for g in geom.geometryObjects)


def test_missing_meshes_leave_kinematics_intact_and_drop_only_those_visuals(tmp_path):
    body = (TWO_LINK.replace('<link name="l1"/>',
                             '<link name="l1"><visual><geometry><mesh filename="package://nowhere/m.stl"/>'
                             '</geometry></visual><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
                             "</link>"))
    robot = kinelab.load(write_urdf(tmp_path, body))
    np.testing.assert_allclose(robot.fk([0, 0]).translation, [0, 0, 1.3])
    with pytest.warns(UserWarning, match="1 visual mesh.*package://nowhere/m.stl"):
        geom = robot.visual_model()
    assert geom.ngeoms == 1


def test_yourdfpy_loads_real_meshes_through_the_same_resolver():
    import yourdfpy

    from kinelab.robot.meshes import yourdfpy_filename_handler

    panda = kinelab.load("panda")
    urdf = yourdfpy.URDF.load(str(panda.urdf_path), load_meshes=True,
                              filename_handler=yourdfpy_filename_handler(panda.urdf_path))
    assert len(urdf.scene.geometry) >= 8


def test_a_robot_from_an_in_memory_model_is_the_robot_of_its_file():
    """Robot.from_model takes the pin.Model a pink or mink user already has; the chain is the file's."""
    loaded = kinelab.load("panda")
    whole = pin.buildModelFromUrdf(str(loaded.urdf_path))
    robot = kinelab.Robot.from_model(whole, tool="panda_hand_tcp")
    assert robot.joint_names == loaded.joint_names and robot.source is None and robot.source_format == "pin.Model"
    rng = np.random.default_rng(4)
    for q in robot.random_qs(20, rng):
        assert np.allclose(robot.fk(q).homogeneous, loaded.fk(q).homogeneous, atol=1e-12)
    assert whole.nq == 9  # the fingers are locked in the robot's copy, not in the caller's model
    target = loaded.fk(loaded.random_q(rng))
    res = kinelab.solve(robot, target, seed=0)
    assert res.success and np.allclose(loaded.fk(res.q).homogeneous, target.homogeneous, atol=1e-6)


@pytest.mark.parametrize("locked", [("panda_finger_joint1", "panda_finger_joint2"),
                                    ("panda_joint7", "panda_finger_joint1", "panda_finger_joint2"), ("panda_joint4",)])
def test_a_reduced_model_is_taken_and_its_locked_joints_stay_locked(locked):
    """#31.2: pin.buildReducedModel gives a locked joint's frame itself as its parent; the walk up the frame
    tree looped forever. The robot's FK is the reduced model's own, at random configurations."""
    whole = pin.buildModelFromUrdf(str(kinelab.load("panda").urdf_path))
    reduced = pin.buildReducedModel(whole, [whole.getJointId(j) for j in locked], pin.neutral(whole))
    assert any(f.parentFrame == i for i, f in enumerate(reduced.frames) if i > 0)  # the model that looped
    with no_hang(10):
        robot = kinelab.Robot.from_model(reduced, tool="panda_hand")
        again = kinelab.Robot.from_model(robot.model, tool=robot.tool)  # kinelab's own reduced model
    assert robot.joint_names == [j for j in (f"panda_joint{k}" for k in range(1, 8)) if j not in locked]
    data, hand = reduced.createData(), reduced.getFrameId("panda_hand")
    for q in robot.random_qs(20, np.random.default_rng(7)):
        pin.framesForwardKinematics(reduced, data, np.concatenate([q, np.zeros(reduced.nq - robot.n)]))
        assert np.allclose(robot.fk(q).homogeneous, data.oMf[hand].homogeneous, atol=1e-12)
        assert np.allclose(again.fk(q).homogeneous, robot.fk(q).homogeneous, atol=1e-12)


def test_from_model_re_roots_at_a_base_and_refuses_what_it_cannot_use():
    loaded = kinelab.load("ur5", base="shoulder_link")
    whole = pin.buildModelFromUrdf(str(loaded.urdf_path))
    robot = kinelab.Robot.from_model(whole, tool=loaded.tool, base="shoulder_link")
    q = loaded.random_q(1)
    assert robot.n == loaded.n and np.allclose(robot.fk(q).homogeneous, loaded.fk(q).homogeneous, atol=1e-12)
    with pytest.raises(kinelab.FrameNotFoundError, match="nosuch"):
        kinelab.Robot.from_model(whole, tool="nosuch")
    with pytest.raises(kinelab.ChainError, match="pinocchio.Model"):
        kinelab.Robot.from_model("panda.urdf", tool="x")


@pytest.mark.parametrize("keyword", ["tool", "base", "group", "srdf", "package_dirs"])
def test_an_empty_name_is_refused_not_read_as_none(keyword):
    """#39 item 10: tool='' read as "the default tool", package_dirs=[''] as the working folder."""
    value = [""] if keyword == "package_dirs" else ""
    with pytest.raises(kinelab.KinelabError, match=f"{keyword}="):
        kinelab.load("ur5", **{keyword: value})


@pytest.mark.parametrize("name", ["kinova", "ur5", "panda"])
def test_fk_and_jacobians_are_pinocchio_s_on_any_array_and_owned_by_the_caller(name):
    """#40 goal 5: fk, jacobian_local and jacobian_world check q and build Pinocchio's q in one compiled pass and
    return what Pinocchio returns. Against Pinocchio at seeded configurations, given as contiguous arrays, strided
    views, integer arrays and lists; and what a call returned is not changed by the next call."""
    robot = kinelab.load(name)
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(11)
    for _ in range(20):
        q = robot.random_q(rng)
        q_pin = pin.neutral(model)
        for value, joint in zip(q, robot.joints, strict=True):
            i = joint.idx_q
            q_pin[i: i + 2 if joint.kind == "continuous" else i + 1] = \
                [np.cos(value), np.sin(value)] if joint.kind == "continuous" else [value]
        pin.framesForwardKinematics(model, data, q_pin)
        oMtool = data.oMf[robot.tool_frame_id].copy()
        J_local = pin.computeFrameJacobian(model, data, q_pin, robot.tool_frame_id, pin.LOCAL)
        J_world = pin.computeFrameJacobian(model, data, q_pin, robot.tool_frame_id, pin.WORLD)
        strided = np.empty(2 * robot.n)
        strided[::2] = q
        for given in (q, strided[::2], q.tolist()):
            mine = robot.fk(given)
            assert np.abs(mine.homogeneous - oMtool.homogeneous).max() <= 1e-14
            assert np.abs(robot.jacobian_local(given) - J_local).max() <= 1e-12
            assert np.abs(robot.jacobian_world(given) - J_world).max() <= 1e-12
        before, J_before = mine.homogeneous.copy(), robot.jacobian_local(q)
        robot.fk(robot.random_q(rng))
        J_copy = J_before.copy()
        robot.jacobian_local(robot.random_q(rng))
        np.testing.assert_array_equal(mine.homogeneous, before)
        np.testing.assert_array_equal(J_before, J_copy)
    np.testing.assert_allclose(robot.fk(np.zeros(robot.n, dtype=int)).homogeneous, robot.fk(np.zeros(robot.n))
                               .homogeneous, rtol=0, atol=0)
    for bad in (np.full(robot.n, np.nan), np.array([0.0] * (robot.n - 1) + [np.inf]), np.zeros(robot.n + 1)):
        with pytest.raises(kinelab.ConfigurationError):
            robot.fk(bad)
