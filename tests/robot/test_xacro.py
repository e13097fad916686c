"""xacro sources, expanded by xacrodoc: arguments, macros, and the errors a bad file gets."""

import numpy as np
import pytest

import kinelab
from kinelab import URDFError, load

pytest.importorskip("xacrodoc")

XACRO = """<?xml version="1.0"?>
<robot name="two_links" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="reach" default="0.3"/>
  <xacro:property name="L" value="$(arg reach)"/>
  <xacro:macro name="link_and_joint" params="i parent">
    <link name="l${i}"/>
    <joint name="j${i}" type="revolute"><parent link="${parent}"/><child link="l${i}"/>
      <origin xyz="0 0 ${L}"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  </xacro:macro>
  <link name="base"/>
  <xacro:link_and_joint i="1" parent="base"/>
  <xacro:link_and_joint i="2" parent="l1"/>
</robot>
"""


def test_a_xacro_expands_with_its_arguments_and_solves(tmp_path):
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO)
    default, longer = load(path), load(path, xacro_args={"reach": "0.5"})
    assert default.joint_names == ["j1", "j2"] and default.source == path
    np.testing.assert_allclose(default.fk(np.zeros(2)).translation, [0, 0, 0.6], atol=1e-12)  # two 0.3 m steps
    np.testing.assert_allclose(longer.fk(np.zeros(2)).translation, [0, 0, 1.0], atol=1e-12)
    q = np.array([0.4, -0.7])  # by hand: the tool is l2's origin, L above j2, which j1 turns about y
    np.testing.assert_allclose(longer.fk(q).translation, [0.5 * np.sin(0.4), 0.0, 0.5 + 0.5 * np.cos(0.4)],
                               atol=1e-12)
    res = kinelab.solve(longer, longer.fk(q), task="position", seed=0)
    assert res.success
    assert not any(p.suffix == ".urdf" for p in tmp_path.iterdir())  # the expansion is not written beside it


def test_a_bad_xacro_is_named_with_xacros_reason(tmp_path):
    bad = tmp_path / "bad.xacro"
    bad.write_text('<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${nowhere}"/></robot>')
    with pytest.raises(URDFError, match=r"xacro cannot expand .*bad.xacro: name 'nowhere' is not defined"):
        load(bad)
    with pytest.raises(URDFError, match="no such xacro file"):
        load(tmp_path / "missing.urdf.xacro")
