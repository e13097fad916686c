"""#39 item 9: calls that once ended in a raw exception or returned nonsense, each now a KinelabError naming what
is valid, or an honest answer judged by Pinocchio."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import write_urdf

import kinelab
from kinelab import maps

ONE = ('<link name="base"/><link name="l"/><joint name="j" type="{kind}"><parent link="base"/>'
       '<child link="l"/><axis xyz="0 0 1"/><origin xyz="0 0 0.3"/>'
       '<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint><link name="tool"/>'
       '<joint name="t" type="fixed"><parent link="l"/><child link="tool"/><origin xyz="0.3 0 0"/></joint>')


def test_a_one_joint_arm_is_solved_by_the_reference_solver(tmp_path):
    """dls on one joint was Boost's ArgumentError (Pinocchio returns a 6 × 1 Jacobian as a flat array)."""
    robot = kinelab.load(write_urdf(tmp_path, ONE.format(kind="revolute", lower=-2, upper=2)), tool="tool")
    target = robot.fk(np.array([0.5]))
    res = kinelab.solve(robot, target, solver="dls", task="position", seed=0)
    assert res.success and abs(res.q[0] - 0.5) < 1e-6 and robot.tool_error(res.q, target)[0] <= 1e-6


def test_a_prismatic_joint_declared_with_1e308_metres_is_sampled_and_solved(tmp_path):
    """Its random configurations overflowed numpy's uniform (OverflowError); the kernel's first start was inf."""
    robot = kinelab.load(write_urdf(tmp_path, ONE.format(kind="prismatic", lower=-1e308, upper=1e308)), tool="tool")
    Q = robot.random_qs(100, 0)
    assert np.isfinite(Q).all() and Q.max() > 1e300 and Q.min() < -1e300  # spread over the whole window
    target = pin.SE3(np.eye(3), np.array([0.3, 0.0, 1.0]))
    res = kinelab.solve(robot, target, task="position", seed=0)
    assert res.success and abs(res.q[0] - 0.7) < 1e-6


def test_a_file_that_is_not_utf8_is_refused_by_name(tmp_path):
    """A latin-1 URDF whose robot name has an é was a UnicodeDecodeError traceback (Pinocchio keeps the bytes)."""
    path = tmp_path / "latin.urdf"
    text = '<?xml version="1.0" encoding="latin-1"?><robot name="\xe9">' + ONE.format(kind="revolute", lower=-2,
                                                                                       upper=2) + "</robot>"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(kinelab.URDFError, match="name is not UTF-8 text"):
        kinelab.load(path, tool="tool")


@pytest.mark.parametrize("call, needle", [
    (lambda: maps.load(None), "must be a path"),
    (lambda: kinelab.Environment.from_file(None), "must be a path"),
    (lambda: maps.reachability(kinelab.load("ur5"), voxel=0.3, orientations=2, out=123), "out=123"),
    (lambda: maps.reachability(kinelab.load("ur5"), voxel=0.3, orientations=2, client=1), "dask.distributed.Client"),
])
def test_arguments_of_the_wrong_kind_are_named(call, needle):
    """These were TypeError and AttributeError tracebacks."""
    pytest.importorskip("zarr")
    with pytest.raises(kinelab.KinelabError, match=needle):
        call()


TWO = ('<link name="base"/><link name="l1"/><link name="l2"/><joint name="j1" type="revolute"><parent link="base"/>'
       '<child link="l1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>'
       '<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/>'
       '<axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>')
GROUP = '<group name="arm"><chain base_link="base" tip_link="l2"/></group>'


@pytest.mark.parametrize("body, error, needle", [
    (GROUP + '<group_state name="s" group="arm"><joint name="j1" value="1e308"/><joint name="j2" value="0"/>'
     '</group_state>', kinelab.JointLimitError, "outside its limits"),
    (GROUP + '<group_state name="s" group="arm"><joint name="j1" value="100"/><joint name="j2" value="0"/>'
     '</group_state>', kinelab.JointLimitError, "outside its limits"),
    (GROUP + GROUP, kinelab.SRDFError, "two group elements are named 'arm'"),
    (GROUP + '<end_effector name="e" parent_link="nolink" group="arm"/>', kinelab.SRDFError, "link 'nolink'"),
])
def test_srdf_nonsense_is_refused(tmp_path, body, error, needle):
    """Named states of 1e308 or 100 rad, a duplicate group and an unknown end-effector link were accepted."""
    srdf = tmp_path / "r.srdf"
    srdf.write_text(f'<?xml version="1.0"?><robot name="t">{body}</robot>')
    with pytest.raises(error, match=needle):
        kinelab.load(write_urdf(tmp_path, TWO), srdf=srdf, tool="l2").named_q("s")


MJCF = ('<mujoco><worldbody><body name="b1" pos="0 0 0.1"><joint name="a" type="hinge" axis="{axis}" ref="{ref}" '
        'range="-1 1" limited="true"/><geom size="0.1"/><body name="b2" pos="0 0 0.3" xyaxes="{xyaxes}">'
        '<joint name="c" type="hinge" axis="0 1 0" range="-1 1" limited="true"/><geom size="0.1"/></body></body>'
        '</worldbody></mujoco>')


@pytest.mark.parametrize("change, needle", [
    ({"xyaxes": "0 0 0 0 0 0"}, "not two independent directions"),
    ({"xyaxes": "1 0 0 2 0 0"}, "not two independent directions"),
    ({"xyaxes": "nan 0 0 0 1 0"}, "6 finite numbers"),
    ({"axis": "1e308 1e308 0"}, "axis is zero or has a component beyond"),
    ({"ref": "1e308"}, r"ref 1e\+308 lies beyond"),
])
def test_mjcf_nonsense_is_refused(tmp_path, change, needle):
    """Zero or NaN xyaxes loaded as a zero or garbage rotation, an axis of 1e308 as a zero axis."""
    fields = {"axis": "0 0 1", "ref": "0", "xyaxes": "1 0 0 0 1 0", **change}
    path = tmp_path / "m.xml"
    path.write_text(MJCF.format(**fields))
    with pytest.raises(kinelab.URDFError, match=needle):
        kinelab.load(path, tool="b2")
    path.write_text(MJCF.format(axis="0 0 1", ref="0", xyaxes="1 0 0 0 1 0"))
    assert kinelab.load(path, tool="b2").n == 2  # the same file, sound, loads


def _stl(path, triangles):
    import struct

    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(triangles)))
        for triangle in triangles:
            f.write(struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *v) for v in triangle) + b"\0\0")


@pytest.mark.parametrize("mesh", ["garbage", "nan"])
def test_a_bad_mesh_is_named_for_collisions_and_the_view(tmp_path, mesh):
    """A mesh coal cannot read was its raw ValueError; a NaN vertex was accepted as collision geometry."""
    if mesh == "garbage":
        (tmp_path / "m.stl").write_text("this is not an STL file")
    else:
        _stl(tmp_path / "m.stl", [[(0, 0, 0), (1, 0, 0), (float("nan"), 1, 0)]])
    body = TWO.replace('<link name="l1"/>', '<link name="l1"><collision><geometry><mesh filename="m.stl"/></geometry>'
                       '</collision><visual><geometry><mesh filename="m.stl"/></geometry></visual></link>')
    robot = kinelab.load(write_urdf(tmp_path, body), tool="l2")
    needle = "cannot be read" if mesh == "garbage" else "not a finite number"
    with pytest.raises(kinelab.URDFError, match=needle):
        kinelab.solve(robot, robot.fk(np.array([0.3, 0.4])), task="position", collisions="self", seed=0)
    with pytest.raises(kinelab.URDFError, match=needle):
        robot.visual_model()
