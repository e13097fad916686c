"""MJCF files: Pinocchio's parser for the kinematics, kinelab's body tree for tool and base; checked against
the same arm written as a URDF (yourdfpy cannot read MJCF)."""

import numpy as np
import pytest

import kinelab
from kinelab import ChainError, load
from kinelab.analysis.oracles import fk_vs_yourdfpy, jacobians_vs_fd

BODIES = """
    <body name="base" pos="0 0 0">{free}
      <body name="l1" pos="0 0 0.3">
        <joint name="j1" type="hinge" axis="0 0 1" range="{r1}" limited="true"/>
        <body name="l2" pos="0 0.1 0.2" axisangle="1 0 0 {tilt}">
          <joint name="j2" type="hinge" axis="0 1 0" range="{r2}" limited="true"/>
          <body name="l3" pos="0 0 0.25">
            <joint name="j3" type="slide" axis="0 0 1" range="0 0.2" limited="true"/>
            <body name="tool" pos="0 0 0.1"/>
          </body>
        </body>
      </body>
    </body>"""
URDF = """<?xml version="1.0"?>
<robot name="arm3"><link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="tool"/>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3"/>
<axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0.1 0.2" rpy="0.3 0 0"/>
<axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
<joint name="j3" type="prismatic"><parent link="l2"/><child link="l3"/><origin xyz="0 0 0.25"/>
<axis xyz="0 0 1"/><limit lower="0" upper="0.2" effort="1" velocity="1"/></joint>
<joint name="jt" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0 0 0.1"/></joint>
</robot>"""


def write_mjcf(tmp_path, degrees=False, free=False, name="arm.xml"):
    compiler = "" if degrees else '<compiler angle="radian"/>'
    r1, r2, tilt = ("-114.59156 114.59156", "-85.943669 85.943669", "17.188734") if degrees else \
        ("-2 2", "-1.5 1.5", "0.3")
    body = BODIES.format(r1=r1, r2=r2, tilt=tilt, free='<freejoint name="float"/>' if free else "")
    path = tmp_path / name
    path.write_text(f'<mujoco model="arm3">{compiler}<worldbody>{body}</worldbody></mujoco>')
    return path


@pytest.mark.parametrize("degrees", [False, True])
def test_an_mjcf_arm_equals_the_same_arm_written_as_a_urdf(tmp_path, degrees):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(URDF)
    mj, ur = load(write_mjcf(tmp_path, degrees)), load(urdf)
    assert (mj.tool, mj.base, mj.joint_names) == ("tool", "base", ["j1", "j2", "j3"])
    np.testing.assert_allclose(mj.lower, ur.lower, atol=1e-6)  # slide range kept in metres in degree mode
    np.testing.assert_allclose(mj.upper, ur.upper, atol=1e-6)
    for q in ur.random_qs(50, 3):
        np.testing.assert_allclose(mj.fk(q).homogeneous, ur.fk(q).homogeneous, atol=1e-7 if degrees else 1e-12)
    agreement = fk_vs_yourdfpy(ur, count=50)  # and the URDF twin against an independent parser
    assert agreement.max_position <= 1e-9 and agreement.max_rotation <= 1e-9
    assert jacobians_vs_fd(mj, count=20).max_rotation <= 1e-6
    target = mj.fk(mj.random_q(5))
    assert kinelab.solve(mj, target, task="position", seed=0).success


def test_a_free_joint_on_the_chain_is_refused_and_a_base_below_it_is_taken(tmp_path):
    path = write_mjcf(tmp_path, free=True)
    with pytest.raises(ChainError, match="'float'"):
        load(path)
    arm = load(path, base="base")
    assert arm.joint_names == ["j1", "j2", "j3"] and arm.base == "base"
    expected = [0.0, 0.1 - 0.35 * np.sin(0.3), 0.5 + 0.35 * np.cos(0.3)]  # by hand: l2 tilted 0.3 rad about x
    np.testing.assert_allclose(arm.fk(np.zeros(3)).translation, expected, atol=1e-12)


def test_the_default_tool_of_an_mjcf_is_its_tip_site(tmp_path):
    """A site on the last body is the tool a MuJoCo user means (the tip site), 5 cm out along z here."""
    tip = '<body name="hand" pos="0 0 0.1"><site name="tip" pos="0 0 0.05"/></body>'
    path = tmp_path / "arm.xml"
    path.write_text('<mujoco model="arm3"><compiler angle="radian"/><worldbody>'
                    + BODIES.format(r1="-2 2", r2="-1.5 1.5", tilt="0.3", free="").replace('<body name="tool" '
                                                                                              'pos="0 0 0.1"/>', tip)
                    + "</worldbody></mujoco>")
    (tmp_path / "plain").mkdir()
    robot, plain = load(str(path)), load(str(write_mjcf(tmp_path / "plain")))
    assert robot.tool == "tip" and plain.tool == "tool"
    q = robot.random_q(3)
    offset = plain.fk(q).rotation @ np.array([0.0, 0.0, 0.05])
    np.testing.assert_allclose(robot.fk(q).translation, plain.fk(q).translation + offset, atol=1e-12)


@pytest.mark.parametrize(("edit", "rule"), [
    (('pos="0 0 0.3"', 'pos="0 0 1e308"'), "more than 10000 m"),
    (('pos="0 0 0.3"', 'pos="0 nan 0.3"'), "pos must be 3 finite numbers"),
    (('axis="0 0 1"', 'axis="0 0 0"'), "axis is zero"),
    (('range="-2 2"', 'range="2 -2"'), "range lower 2 > upper -2"),
    (('name="j2"', 'name="j1"'), "two joint elements are named 'j1'"),
    (('<body name="l1" pos="0 0 0.3">', '<body name="l1" pos="0 0 0.3" quat="nan 0 0 1">'),
     "quat must be 4 finite numbers"),
    (('<body name="l1" pos="0 0 0.3">', '<body name="l1" pos="0 0 0.3" quat="0 0 0 0">'), "quat is zero"),
    (('<worldbody>', '<include file="other.xml"/><worldbody>'), "<include> is not read"),
])
def test_an_mjcf_meets_the_rules_a_urdf_meets(tmp_path, edit, rule):
    """kinelab 0.1 read MJCF without its model rules: inf positions, NaN quaternions, zero axes, lower > upper
    (a raw ValueError in every solve), a duplicate joint name dropping a joint, an ignored include."""
    path = write_mjcf(tmp_path)
    path.write_text(path.read_text().replace(*edit, 1))
    with pytest.raises(kinelab.URDFError, match=rule):
        load(str(path))


def test_a_huge_model_file_is_refused_before_pinocchio_parses_it(tmp_path):
    """A URDF of 4000 links killed the process inside Pinocchio's parser; an MJCF of 2000 bodies ran it out of
    memory: both are counted and refused first."""
    from kinelab.robot.urdf import MAX_LINKS

    links = "".join(f'<link name="l{i}"/>' for i in range(MAX_LINKS + 1))
    joints = "".join(f'<joint name="j{i}" type="fixed"><parent link="l{i}"/><child link="l{i + 1}"/></joint>'
                     for i in range(MAX_LINKS))
    urdf = tmp_path / "long.urdf"
    urdf.write_text(f'<robot name="long">{links}{joints}</robot>')
    with pytest.raises(kinelab.URDFError, match=f"{MAX_LINKS + 1} links"):
        load(str(urdf))
    nested = "".join(f'<body name="b{i}">' for i in range(MAX_LINKS + 1)) + "</body>" * (MAX_LINKS + 1)
    mjcf = tmp_path / "deep.xml"
    mjcf.write_text(f"<mujoco><worldbody>{nested}</worldbody></mujoco>")
    with pytest.raises(kinelab.URDFError, match=f"{MAX_LINKS + 1} bodies"):
        load(str(mjcf))


@pytest.mark.parametrize("tag", ["frame", "replicate", "attach"])
def test_an_element_whose_bodies_pinocchio_drops_is_refused_by_name(tmp_path, tag):
    """#31.6: a <frame>'s bodies were dropped without a word (the model was a wrong, shorter arm)."""
    path = write_mjcf(tmp_path)
    text = path.read_text()
    path.write_text(text.replace("<worldbody>", f'<worldbody><body name="extra"><{tag}>'
                                 f'<body name="inside"/></{tag}></body>', 1))
    with pytest.raises(kinelab.URDFError, match=f"<{tag}> is not read by Pinocchio's MJCF parser"):
        load(path)


def test_a_class_that_no_default_defines_is_refused_by_name(tmp_path):
    """#31.6: a bad childclass gave a raw IndexError from the parser (or a model without the class's values)."""
    path = write_mjcf(tmp_path)
    text = path.read_text().replace('<mujoco model="arm3">',
                                    '<mujoco model="arm3"><default><default class="arm"/></default>')
    path.write_text(text.replace('<body name="base"', '<body name="base" childclass="nosuch"', 1))
    with pytest.raises(kinelab.URDFError, match="childclass='nosuch', which no <default class=...> defines; "
                                                "classes: arm, main"):
        load(path)
    path.write_text(text.replace('<body name="base"', '<body name="base" childclass="arm"', 1))
    assert load(path).joint_names == ["j1", "j2", "j3"]


@pytest.mark.parametrize("degrees", [False, True])
def test_a_hinge_with_a_ref_keeps_the_files_range(tmp_path, degrees):
    """Pinocchio's parser shifts a hinge's range by its ``ref`` while the angle stays MuJoCo's qpos; kinelab puts
    the file's range back (j1's range (-2, 2) rad with ref 0.5: the limits stay (-2, 2), and the placement at
    q = ref is the one written in the file, as in MuJoCo)."""
    path = write_mjcf(tmp_path, degrees=degrees)
    ref = "28.647890" if degrees else "0.5"
    path.write_text(path.read_text().replace('name="j1" type="hinge"', f'name="j1" type="hinge" ref="{ref}"'))
    robot = load(path, whole=True)
    i = robot.model.joints[robot.model.getJointId("j1")].idx_q
    assert robot.model.lowerPositionLimit[i] == pytest.approx(-2.0, abs=1e-6)
    assert robot.model.upperPositionLimit[i] == pytest.approx(2.0, abs=1e-6)
    q = robot.neutral()
    q[i] = 0.5
    assert robot.frame_placement(q, "l2").translation == pytest.approx([0.0, 0.1, 0.5], abs=1e-6)


def test_floating_puts_a_free_flyer_under_an_mjcf_once(tmp_path):
    """``floating=True`` on a file without a free joint adds one (nq 3 + 7); on a file whose root body carries its
    own ``<freejoint>`` none is added twice."""
    fixed = load(write_mjcf(tmp_path), floating=True)
    assert fixed.floating and fixed.nq == 10 and fixed.model.joints[1].shortname() == "JointModelFreeFlyer"
    own = load(write_mjcf(tmp_path, free=True, name="free.xml"), floating=True)
    assert own.floating and own.nq == 10 and own.model.njoints == 5
