"""Nonsense models are refused at load, each refusal naming the file, the element and the rule."""

import numpy as np
import pytest
from helpers import no_hang, revolute, write_urdf

import kinelab

LINKS = '<link name="a"/><link name="b"/><link name="c"/>'


def _chain(j1: str, j2: str | None = None) -> str:
    return LINKS + j1 + (j2 or revolute("j2", "b", "c"))


@pytest.mark.parametrize("joint, rule", [
    (revolute("j1", "a", "b", axis="0 0 0"), "axis is zero"),
    (revolute("j1", "a", "b", axis="0 nan 1"), "axis xyz must be 3 finite numbers"),
    (revolute("j1", "a", "b", xyz="1e308 0 0.1"), "more than 10000 m"),
    (revolute("j1", "a", "b", xyz="inf 0 0"), "origin xyz must be 3 finite numbers"),
    (revolute("j1", "a", "b", xyz="0 0"), "origin xyz must be 3 finite numbers"),
    ('<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
     '<limit lower="1" upper="-1" effort="1" velocity="1"/></joint>', "limit lower 1 > upper -1"),
    ('<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
     '<limit lower="nan" upper="1" effort="1" velocity="1"/></joint>', "limit lower must be 1 finite number"),
])
def test_joint_rules(tmp_path, joint, rule):
    path = write_urdf(tmp_path, _chain(joint))
    with pytest.raises(kinelab.URDFError, match=rule) as err:
        kinelab.load(path)
    assert "r.urdf" in str(err.value) and "'j1'" in str(err.value)


def test_a_link_that_is_its_own_parent(tmp_path):
    path = write_urdf(tmp_path, LINKS + revolute("j1", "a", "a") + revolute("j2", "a", "b") + revolute("j3", "b", "c"))
    with pytest.raises(kinelab.URDFError, match="joint 'j1' connects link 'a' to itself"):
        kinelab.load(path)


def test_a_mimic_joint_naming_a_missing_joint(tmp_path):
    j2 = revolute("j2", "b", "c", extra='<mimic joint="nosuch"/>')
    path = write_urdf(tmp_path, _chain(revolute("j1", "a", "b"), j2))
    with pytest.raises(kinelab.URDFError, match="'j2' mimics 'nosuch', which is not a joint of this file; hold it"):
        kinelab.load(path)


def test_a_file_in_another_encoding_without_a_declaration(tmp_path):
    path = tmp_path / "latin.urdf"
    text = '<?xml version="1.0"?>\n<robot name="t"><!-- café -->' + _chain(revolute("j1", "a", "b")) + "</robot>\n"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(kinelab.URDFError, match="latin.urdf"):
        kinelab.load(str(path))


def test_a_file_that_declares_its_encoding_loads(tmp_path):
    path = tmp_path / "latin.urdf"
    text = ('<?xml version="1.0" encoding="ISO-8859-1"?>\n<robot name="t"><!-- café -->'
            + _chain(revolute("j1", "a", "b")) + "</robot>\n")
    path.write_bytes(text.encode("latin-1"))
    assert kinelab.load(str(path)).n == 2


@pytest.mark.parametrize("value, error, words", [
    (float("nan"), kinelab.ConfigurationError, "must be finite"),
    (float("inf"), kinelab.ConfigurationError, "must be finite"),
    (5.0, kinelab.JointLimitError, "outside its limits"),
    ("a lot", kinelab.ConfigurationError, "must be a number"),
])
def test_locked_values_must_be_finite_and_within_limits(tmp_path, value, error, words):
    path = write_urdf(tmp_path, _chain(revolute("j1", "a", "b")))
    with pytest.raises(error, match=words):
        kinelab.load(path, locked={"j2": value})


def test_a_sensible_locked_value_is_kept(tmp_path):
    path = write_urdf(tmp_path, _chain(revolute("j1", "a", "b")))
    robot = kinelab.load(path, locked={"j2": 1.5})
    assert robot.n == 1 and robot.locked["j2"] == 1.5
    np.testing.assert_allclose(robot.fk([0.0]).translation, [0.0, 0.0, 1.0], atol=1e-12)


def test_a_chain_too_long_for_pinocchio_is_refused_at_once_with_the_estimate(tmp_path):
    """Pinocchio's Data grows as nv³ (8 GB at 500 joints): kinelab refuses before allocating it."""
    from kinelab.report.bench import scaling
    from kinelab.robot.build import max_joints

    path = tmp_path / "long.urdf"
    path.write_text(scaling.synthetic_urdf(max_joints() + 200))
    with no_hang(120), pytest.raises(kinelab.ChainError, match=r"would take about \d+\.\d GiB"):
        kinelab.load(str(path))  # refused before any large allocation (which would take minutes and gigabytes)


def test_loading_is_linear_in_the_chain_below_the_data_bound(tmp_path):
    """The load's own work is linear: a 150-link chain loads (its Data is 0.2 GB)."""
    from kinelab.report.bench import scaling

    path = tmp_path / "c150.urdf"
    path.write_text(scaling.synthetic_urdf(150))
    robot = kinelab.load(str(path))
    assert robot.n == 150 and robot.joint_kinds.count("prismatic") == 150 // 4
    from kinelab.ik.chain import chain_model

    for q in robot.random_qs(3, 0):  # the axes read from the joint models give Pinocchio's FK
        np.testing.assert_allclose(chain_model(robot).vectors(q)["N"], robot.fk(q).translation, atol=1e-9)


def test_a_joint_naming_a_link_that_does_not_exist(tmp_path):
    j2 = revolute("j2", "b", "nowhere")
    path = write_urdf(tmp_path, LINKS + revolute("j1", "a", "b") + j2)
    with pytest.raises(kinelab.URDFError, match="names link 'nowhere', which the file does not define"):
        kinelab.load(path)


def test_the_cli_says_one_line_even_when_pinocchios_parser_complains(tmp_path):
    """urdfdom writes its complaints to the process's stderr; kinelab folds them into its one line."""
    import os
    import subprocess
    import sys

    bad_visual = '<link name="b"><visual><geometry><box size="x"/></geometry></visual></link>'
    body = _chain(revolute("j1", "a", "b")).replace('<link name="b"/>', bad_visual)
    path = write_urdf(tmp_path, body)
    proc = subprocess.run([sys.executable, "-m", "kinelab.cli", "info", path], capture_output=True, text=True,
                          env={**os.environ, "PYTHONWARNINGS": "ignore"}, timeout=120)
    assert proc.returncode in (0, 2)
    if proc.returncode == 2:
        assert len(proc.stderr.strip().splitlines()) == 1
    else:
        assert "Error" not in proc.stderr


def test_what_c_code_writes_on_descriptor_2_is_read_back_and_the_descriptor_restored():
    import os

    from kinelab.robot.meshes import c_stderr_captured

    before = os.fstat(2)
    said: list[str] = []
    with c_stderr_captured(said):
        os.write(2, b"Error: first complaint\n\n  second complaint \n")  # as urdfdom writes, below Python
    assert said == ["Error: first complaint", "second complaint"]
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)


# What Pinocchio's parser reads, kinelab loads: each case once, in a file written here.
def test_a_comment_nested_in_a_comment_loads(tmp_path):
    body = "<!-- outer <!-- inner --> tail of the outer -->" + _chain(revolute("j1", "a", "b"))
    robot = kinelab.load(write_urdf(tmp_path, body))
    assert robot.joint_names == ["j1", "j2"]
    np.testing.assert_allclose(robot.fk([0.3, -0.2]).translation, [0, 0, 1.0], atol=1e-12)


def test_an_undeclared_namespace_prefix_loads(tmp_path):
    body = '<xacro:property name="unused" value="1"/>' + _chain(revolute("j1", "a", "b"))
    robot = kinelab.load(write_urdf(tmp_path, body))
    assert robot.n == 2 and robot.tool == "c"


def test_a_mimic_off_the_chain_whose_leader_is_missing_is_locked_with_one_warning(tmp_path):
    finger = '<link name="f"/>' + revolute("jf", "b", "f", extra='<mimic joint="nosuch"/>')
    path = write_urdf(tmp_path, _chain(revolute("j1", "a", "b")) + finger)
    with pytest.warns(UserWarning, match="'jf' mimics 'nosuch'.*off the chain and locked") as said:
        robot = kinelab.load(path, tool="c")
    assert len(said) == 1 and robot.joint_names == ["j1", "j2"] and "jf" in robot.locked


# --- #31.4: files Pinocchio reads load, with the chain Pinocchio builds --------------------------------------


def _same_fk_as_pinocchio(robot, path, tool="c"):
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(path))
    data, fid = model.createData(), model.getFrameId(tool)
    for q in robot.random_qs(10, np.random.default_rng(3)):
        full = np.concatenate([[np.cos(v), np.sin(v)] if k == "continuous" else [v]
                               for v, k in zip(q, robot.joint_kinds, strict=True)])
        pin.framesForwardKinematics(model, data, full)
        assert np.allclose(robot.fk(q).homogeneous, data.oMf[fid].homogeneous, atol=1e-12)


def test_a_continuous_joint_on_a_tilted_axis_loads_and_solves(tmp_path):
    """A raw KeyError: 'd' in the model builder (an unbounded revolute joint off the x, y, z axes has no `axis` in
    Pinocchio's Python API)."""
    j1 = revolute("j1", "a", "b", axis="0 0.6 0.8").replace('type="revolute"', 'type="continuous"')
    path = write_urdf(tmp_path, _chain(j1, revolute("j2", "b", "c", axis="0.48 0.6 0.64")))
    robot = kinelab.load(path)
    assert robot.joint_kinds == ["continuous", "revolute"]
    _same_fk_as_pinocchio(robot, path)
    target = robot.fk(np.array([2.5, 0.4]))
    res = kinelab.solve(robot, target, task="position", seed=0)
    assert res.success and np.linalg.norm(robot.fk(res.q).translation - target.translation) <= 1e-6


def test_a_comment_left_open_past_the_root_loads_as_pinocchio_reads_it(tmp_path):
    """The CoIKS benchmark's Franka, UR5 and UR10 files end so, and were refused with a message about the text
    encoding; Pinocchio reads the first <robot> and stops."""
    path = tmp_path / "r.urdf"
    tail = "</robot>\n  <!-- <transmission name='t'>\n  <!-- a note -->\n  <link name='x'/>\n  </joint>\n</robot> -->\n"
    path.write_text('<robot name="t">' + _chain(revolute("j1", "a", "b")) + tail)
    robot = kinelab.load(path)
    assert robot.joint_names == ["j1", "j2"]
    _same_fk_as_pinocchio(robot, path)
    path.write_text('<robot name="t">' + _chain(revolute("j1", "a", "b")) + "</robot>\n<!-- never closed\n")
    with pytest.raises(kinelab.URDFError, match="Pinocchio cannot read .*XML_ERROR_PARSING_COMMENT"):
        kinelab.load(path)  # Pinocchio's own parser refuses this one: its reason is the one given


def test_a_comment_nested_inside_a_comment_loads_as_pinocchio_reads_it(tmp_path):
    """A comment holding a comment: the first --> ends it, the rest is read (the CoIKS Franka file)."""
    path = tmp_path / "r.urdf"
    body = _chain(revolute("j1", "a", "b"))
    path.write_text(f'<robot name="t">{body}<!-- <link name="x"> <!-- inner --> </robot>')
    assert kinelab.load(path).n == 2


def test_a_file_broken_inside_its_root_is_refused_with_the_parser_s_reason(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text('<robot name="t">' + LINKS + '<joint name="j1" type="revolute"></robot>')
    with pytest.raises(kinelab.URDFError, match=r"malformed URDF .*r.urdf: mismatched tag: line 1") as err:
        kinelab.load(path)
    assert "encoding" not in str(err.value)
