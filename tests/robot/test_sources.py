"""Robots as users have them: any base → tool chain of a tree, SRDF groups and named configurations,
ROS-style packages whose meshes resolve through package_dirs or ROS_PACKAGE_PATH."""

from pathlib import Path

import numpy as np
import pytest
from helpers import ros_package

import kinelab
from kinelab import ChainError, SRDFError, URDFError, load
from kinelab.analysis.oracles import fk_vs_yourdfpy, jacobians_vs_fd
from kinelab.robot import catalog

ERD = Path(catalog.erd_share_dir() or "/nonexistent") / "example-robot-data" / "robots"
TALOS_URDF, TALOS_SRDF = ERD / "talos_data/robots/talos_reduced.urdf", ERD / "talos_data/srdf/talos.srdf"
PANDA_SRDF = ERD / "panda_description/srdf/panda.srdf"


def test_a_chain_from_a_mid_link_is_expressed_in_that_link():
    """panda from link3: FK equals link3's pose inverted times the tool's, both from the whole arm
    (joints 1-3 at zero), and agrees with yourdfpy's transform between the two links."""
    full, sub = load("panda"), load("panda", base="panda_link3")
    assert sub.joint_names == full.joint_names[3:] and sub.base == "panda_link3"
    for q in sub.random_qs(20, 1):
        q_full = np.concatenate([[0.0, 0.0, 0.0], q])
        expected = full.frame_placement(q_full, "panda_link3").inverse() * full.fk(q_full)
        np.testing.assert_allclose(sub.fk(q).homogeneous, expected.homogeneous, atol=1e-12)
    fk = fk_vs_yourdfpy(sub, count=100)
    assert fk.max_position <= 1e-9 and fk.max_rotation <= 1e-9
    assert jacobians_vs_fd(sub, count=20).max_rotation <= 1e-6


@pytest.mark.skipif(not TALOS_URDF.is_file(), reason="example-robot-data without talos")
def test_an_srdf_group_gives_a_humanoids_arm_from_its_torso_held_at_the_named_configuration():
    arm = load(TALOS_URDF, srdf=TALOS_SRDF, group="l_arm")
    assert (arm.base, arm.tool) == ("torso_2_link", "wrist_left_ft_tool_link") and arm.n == 7
    half = arm.srdf.state("half_sitting")
    assert arm.locked["torso_2_joint"] == pytest.approx(half["torso_2_joint"])  # off-chain joints held there
    np.testing.assert_allclose(arm.named_q("half_sitting"), [half[j] for j in arm.joint_names])
    fk = fk_vs_yourdfpy(arm, count=50)
    assert fk.max_position <= 1e-9 and fk.max_rotation <= 1e-9
    target = arm.fk(arm.random_q(3))
    res = kinelab.solve(arm, target, seed=0, time_budget=0.5)
    assert res.success and arm.tool_error(res.q, target)[0] <= 1e-6


def test_an_srdf_group_of_joints_takes_its_end_effector_as_the_tool():
    panda = load("panda", srdf=PANDA_SRDF, group="arm")
    assert panda.tool == "panda_hand_tcp" and panda.n == 7
    np.testing.assert_allclose(panda.named_q("default"), [0, -0.785398, 0, -2.35619, 0, 1.5707, 0.785398])
    assert panda.locked["panda_finger_joint1"] == pytest.approx(0.001)


def test_bad_srdf_uses_and_bad_bases_are_named(tmp_path):
    with pytest.raises(SRDFError, match="no group 'legs'.*arm"):
        load("panda", srdf=PANDA_SRDF, group="legs")
    with pytest.raises(SRDFError, match="no configuration 'home'.*default"):
        load("panda", srdf=PANDA_SRDF).named_q("home")
    with pytest.raises(SRDFError, match="without an SRDF"):
        load("panda").named_q("default")
    with pytest.raises(SRDFError, match="needs srdf="):
        load("panda", group="arm")
    bad = tmp_path / "bad.srdf"
    bad.write_text('<robot name="panda"><group name="arm"><joint name="elbow_of_nobody"/></group></robot>')
    with pytest.raises(SRDFError, match="bad.srdf: group 'arm' names joint 'elbow_of_nobody'"):
        load("panda", srdf=bad)
    with pytest.raises(SRDFError, match="SRDF not found"):
        load("panda", srdf=tmp_path / "missing.srdf")
    with pytest.raises(ChainError, match="not on the path from the root"):
        load("panda", base="panda_leftfinger", tool="panda_hand_tcp")


def _mesh_paths(robot):
    return [g.meshPath for g in robot.visual_model().geometryObjects]


def test_a_ros_package_resolves_through_package_dirs_and_ros_package_path(tmp_path, monkeypatch):
    urdf = ros_package(tmp_path / "ws" / "src")
    moved = tmp_path / "elsewhere.urdf"  # away from its package: the URI must resolve through the search
    moved.write_text(urdf.read_text())
    expected = str((tmp_path / "ws" / "src" / "mypkg" / "meshes" / "box.stl").resolve())
    robot = load(moved, package_dirs=[str(tmp_path / "ws" / "src")])
    assert [str(Path(p).resolve()) for p in _mesh_paths(robot)] == [expected]
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))  # a workspace: the package one level down
    assert [str(Path(p).resolve()) for p in _mesh_paths(load(moved))] == [expected]
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws" / "src" / "mypkg"))  # the package itself
    assert [str(Path(p).resolve()) for p in _mesh_paths(load(moved))] == [expected]


def test_a_missing_package_directory_is_named(tmp_path):
    urdf = ros_package(tmp_path)
    with pytest.raises(URDFError, match="package directory .*nowhere.* does not exist"):
        load(urdf, package_dirs=[str(tmp_path / "nowhere")])


def test_srdf_groups_that_include_each_other_and_non_finite_configurations_are_refused(tmp_path):
    """kinelab 0.1: a group including itself hit Python's recursion limit; NaN named configurations loaded."""
    from kinelab.robot.srdf import read_srdf

    looped = tmp_path / "loop.srdf"
    looped.write_text('<robot name="t"><group name="a"><group name="b"/></group>'
                      '<group name="b"><group name="a"/></group></robot>')
    with pytest.raises(kinelab.SRDFError, match="includes itself"):
        read_srdf(looped).group_joints("a")
    for value in ("nan", "inf"):
        bad = tmp_path / f"{value}.srdf"
        bad.write_text(f'<robot name="t"><group_state name="home" group="a"><joint name="j1" value="{value}"/>'
                       "</group_state></robot>")
        with pytest.raises(kinelab.SRDFError, match="not a finite number"):
            read_srdf(bad)
