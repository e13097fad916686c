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
