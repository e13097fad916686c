"""Shared test helpers: the robots the cross-checks use, and small URDFs written by the tests."""

import contextlib
import signal
import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin

import kinelab
from kinelab import Closure
from kinelab.report.bench.protocol import cosine_path, joint_line  # noqa: F401 - the tests' paths, the bench's

BUNDLED = ("stanford", "era", "youbot")
ERD_ARMS = ("panda", "ur5", "kinova", "xarm7")


def write_urdf(tmp_path, body: str, name: str = "r.urdf") -> str:
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="t">\n{body}\n</robot>\n')
    return str(path)


def revolute(name, parent, child, axis="0 0 1", xyz="0 0 0.5", extra=""):
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-2" upper="2" effort="1" velocity="1"/>'
            f"{extra}</joint>")


ASCII_STL = """solid box
facet normal 0 0 -1
outer loop
vertex 0 0 0
vertex 0.1 0 0
vertex 0 0.1 0
endloop
endfacet
facet normal 0 -1 0
outer loop
vertex 0 0 0
vertex 0 0 0.1
vertex 0.1 0 0
endloop
endfacet
facet normal -1 0 0
outer loop
vertex 0 0 0
vertex 0 0.1 0
vertex 0 0 0.1
endloop
endfacet
facet normal 1 1 1
outer loop
vertex 0.1 0 0
vertex 0 0 0.1
vertex 0 0.1 0
endloop
endfacet
endsolid box
"""


def ros_package(root: Path) -> Path:
    """A ROS-style package mypkg (package.xml, urdf/, meshes/box.stl) under root; returns the URDF."""
    pkg = root / "mypkg"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "package.xml").write_text('<?xml version="1.0"?><package format="2"><name>mypkg</name></package>')
    (pkg / "meshes" / "box.stl").write_text(ASCII_STL)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(
        '<?xml version="1.0"?><robot name="arm"><link name="base"/>'
        '<link name="l1"><visual><geometry><mesh filename="package://mypkg/meshes/box.stl"/></geometry></visual></link>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3"/>'
        '<axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint></robot>')
    return urdf


@contextlib.contextmanager
def no_hang(seconds: int = 30):
    """Fail the test, instead of blocking the run, when the block takes longer than ``seconds`` (a hang, not a
    speed: the bound is many times what the block needs on a loaded machine)."""

    def hang(_signum, _frame):
        raise AssertionError(f"still running after {seconds} s: a hang")

    previous = signal.signal(signal.SIGALRM, hang)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def interruptible(argv, **kwargs) -> subprocess.Popen:
    """A child process that Ctrl-C (SIGINT) reaches whatever its parent does with the signal: a test suite started
    from a background job or under nohup inherits SIGINT ignored, and a child would inherit that too (it would
    then rightly not stop, and a test of kinelab's Ctrl-C would test its caller)."""
    return subprocess.Popen(argv, preexec_fn=_default_sigint, **kwargs)


def turn_gap(a, b):
    """The largest joint difference between a and b [rad], each modulo 2π (by trigonometry, not kinelab's wrap)."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return float(np.max(np.abs(np.arctan2(np.sin(d), np.cos(d)))))


def assert_meets_pose(robot, qs, target, tol):
    """Each configuration of qs meets the target pose by Pinocchio's FK to ``tol`` [m, rad], independently of the
    judge's verdict."""
    for q in qs:
        oMtool = robot.fk(q)
        assert np.linalg.norm(oMtool.translation - target.translation) <= tol
        assert np.linalg.norm(pin.log3(oMtool.rotation.T @ target.rotation)) <= tol


def pinocchio_tool(robot, q):
    """The tool pose at q (rad or m) by Pinocchio's own FK on fresh data: the oracle, apart from kinelab's FK."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.to_pin_q(np.asarray(q, dtype=float)))
    return data.oMf[robot.tool_frame_id]


def pinocchio_axes(robot, q=None):
    """Unit axes, points on them and the tool pose at q (None: q = 0), read from Pinocchio's model and Jacobians."""
    model, data = robot.model, robot.model.createData()
    q0 = pin.neutral(model) if q is None else robot.to_pin_q(q)
    pin.computeJointJacobians(model, data, q0)
    pin.framesForwardKinematics(model, data, q0)
    h = np.array([pin.getJointJacobian(model, data, j, pin.WORLD)[3:, model.joints[j].idx_v]
                  for j in range(1, model.njoints)])
    o = np.array([data.oMi[j].translation for j in range(1, model.njoints)])
    return h, o, data.oMf[robot.tool_frame_id]


def chain_urdf(h, o, M, lower, upper, mount=None):
    """A URDF of revolute joints with axes h_i through points o_i (base frame, q = 0) and the tool at M; links
    are frames without rotation. ``mount``: (xyz, rpy) of the base under a "world" link."""
    rows = ['<link name="base"/>']
    if mount is not None:
        rows += ['<link name="world"/>', f'<joint name="mount" type="fixed"><parent link="world"/><child link="base"/>'
                 f'<origin xyz="{" ".join(map(repr, mount[0]))}" rpy="{" ".join(map(repr, mount[1]))}"/></joint>']
    parent, at = "base", np.zeros(3)
    for i in range(len(h)):
        rows += [f'<link name="l{i + 1}"/>',
                 f'<joint name="j{i + 1}" type="revolute"><parent link="{parent}"/><child link="l{i + 1}"/>'
                 f'<origin xyz="{" ".join(map(repr, (o[i] - at).tolist()))}"/>'
                 f'<axis xyz="{" ".join(map(repr, h[i].tolist()))}"/>'
                 f'<limit lower="{float(lower[i])!r}" upper="{float(upper[i])!r}" effort="1" velocity="1"/></joint>']
        parent, at = f"l{i + 1}", o[i]
    rpy = pin.rpy.matrixToRpy(M.rotation)
    rows += ['<link name="tool"/>', f'<joint name="tool_joint" type="fixed"><parent link="{parent}"/>'
             f'<child link="tool"/><origin xyz="{" ".join(map(repr, (M.translation - at).tolist()))}" '
             f'rpy="{" ".join(map(repr, rpy.tolist()))}"/></joint>']
    return "\n".join(rows)


def multistart_gaps(robot, seed, poses=4):
    """At ``poses`` seeded poses: (``solve_all``'s set, how many branches a dense multistart (0.5 s, no stopping
    rule) found, and the largest distance [rad] from one of them to the nearest branch of the set, joint by joint
    modulo 2π)."""
    import kinelab

    rng = np.random.default_rng(seed)
    out = []
    for k in range(poses):
        target = robot.fk(robot.random_q(rng))
        ours = kinelab.solve_all(robot, target)
        theirs = kinelab.solve_all(robot, target, solver="frdm", seed=k, time_budget=0.5, stop_below=None)
        gaps = [min(np.abs(np.arctan2(np.sin(s.q - a.q), np.cos(s.q - a.q))).max() for a in ours) for s in theirs]
        out.append((ours, len(theirs), max(gaps, default=np.inf)))
    return out


def planar_fourbar(a: float, b: float, c: float, d: float) -> kinelab.Robot:
    """A four-bar of any lengths built here in memory (crank at the origin, rocker pivot at (d, 0, 0)), its loop
    declared at C: a model independent of the bundled file."""
    model = pin.Model()
    z = pin.JointModelRZ()
    crank = model.addJoint(0, z, pin.SE3.Identity(), "crank_joint")
    coupler = model.addJoint(crank, z, pin.SE3(np.eye(3), np.array([a, 0.0, 0.0])), "coupler_joint")
    rocker = model.addJoint(0, z, pin.SE3(np.eye(3), np.array([d, 0.0, 0.0])), "rocker_joint")
    for joint in (crank, coupler, rocker):
        model.appendBodyToJoint(joint, pin.Inertia.FromSphere(0.1, 0.01), pin.SE3.Identity())
    model.lowerPositionLimit[:] = -2 * np.pi
    model.upperPositionLimit[:] = 2 * np.pi
    model.addFrame(pin.Frame("coupler_tip", coupler, pin.SE3(np.eye(3), np.array([b, 0.0, 0.0])),
                             pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("rocker_tip", rocker, pin.SE3(np.eye(3), np.array([c, 0.0, 0.0])),
                             pin.FrameType.OP_FRAME))
    robot = kinelab.Robot.from_model(model, name="fourbar_built")
    robot.declare_closures([Closure("coupler_tip", "rocker_tip", (1, 1, 0, 0, 0, 0))], ["crank_joint"])
    return robot


def lowest_part(robot: kinelab.Chain, q: np.ndarray) -> float:
    """The lowest z [m], in the base frame, of any frame's origin and any collision or visual object's placement
    that the joints move (the base's own shapes, fixed to it, may reach below its plane: a youBot's wheels)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.to_pin_q(q))
    low = min(M.translation[2] for f, M in zip(robot.model.frames, data.oMf, strict=True) if f.parentJoint > 0)
    for kind in ("visual", "collision"):
        geometry = robot.visual_model(kind=kind)
        if geometry.ngeoms:
            gdata = pin.GeometryData(geometry)
            pin.updateGeometryPlacements(robot.model, data, geometry, gdata)
            low = min([low] + [M.translation[2] for g, M in zip(geometry.geometryObjects, gdata.oMg, strict=True)
                               if g.parentJoint > 0])
    return float(low)


def assembled_draws(robot: kinelab.Robot, count: int, rng: np.random.Generator, spread: float | None = None):
    """``count`` motor draws from the robot's standing pose, each assembled (a draw with no assembly yields None):
    the motors uniform within their limits, or moved by up to ``spread`` rad about the standing pose."""
    home = robot.standing()
    motors = [robot.model.joints[robot.model.getJointId(a)].idx_q for a in robot.actuated]
    for _ in range(count):
        q = home.copy()
        if spread is None:
            q[motors] = robot.random_q(rng)[motors]
        else:
            q[motors] += rng.uniform(-spread, spread, len(motors))
        try:
            yield q, robot.assemble(q)
        except kinelab.AssemblyError:
            yield q, None
