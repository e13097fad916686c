"""#69: closed loops declared, measured and assembled. Each closure's error and Jacobian against Pinocchio 4's
constraint models (PointAnchorConstraintModel, FrameAnchorConstraintModel) and finite differences at seeded random
q; the four-bar's assembly against its closed form (two circles' intersection); no assembly claimed where the closed
form has none; the declaration file read as data, every malformed one named."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from helpers import planar_fourbar

import kinelab
from kinelab import AssemblyError, Closure, FrameNotFoundError, JointNotFoundError, OptionError, URDFError
from kinelab.robot.closures import read_closures

A, B, C, D = 0.10, 0.28, 0.22, 0.30  # urdf/fourbar.urdf's crank, coupler, rocker and ground [m]
SEEDS = range(20)


def closed_form_c(theta: float, a: float, b: float, c: float, d: float) -> list[np.ndarray]:
    """The two points C (or none) with |BC| = b and |DC| = c, B = a (cos θ, sin θ), D = (d, 0)."""
    Bp, Dp = a * np.array([np.cos(theta), np.sin(theta)]), np.array([d, 0.0])
    gap = Dp - Bp
    r = np.linalg.norm(gap)
    if r > b + c or r < abs(b - c):
        return []
    along = (b * b - c * c + r * r) / (2 * r)
    h = np.sqrt(max(b * b - along * along, 0.0))
    mid, normal = Bp + along * gap / r, np.array([-gap[1], gap[0]]) / r
    return [mid + h * normal, mid - h * normal]


def anchor(robot: kinelab.Robot, kind: type, closure: Closure) -> tuple[object, object]:
    """Pinocchio's constraint model of a closure: the two frames' placements on their parent joints."""
    fa = robot.model.frames[robot.frame_id(closure.frame_a)]
    fb = robot.model.frames[robot.frame_id(closure.frame_b)]
    model = kind(robot.model, fa.parentJoint, fa.placement, fb.parentJoint, fb.placement)
    return model, model.createData()


# -- error and Jacobian against Pinocchio -----------------------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
def test_point_closure_equals_pinocchios_point_anchor(seed: int) -> None:
    """A point closure's error and Jacobian are Pinocchio's PointAnchorConstraintModel's (1e-12), at any q."""
    robot = kinelab.load("fourbar")
    point = Closure("coupler_tip", "rocker_tip", "point")
    robot.declare_closures([point], ["crank_joint"])
    q = robot.random_q(seed)
    cmodel, cdata = anchor(robot, pin.PointAnchorConstraintModel, point)
    data = robot.model.createData()
    pin.computeJointJacobians(robot.model, data, q)
    pin.updateFramePlacements(robot.model, data)
    cmodel.calc(robot.model, data, cdata)
    assert np.abs(robot.closure_error(q) - cdata.constraint_position_error).max() <= 1e-12
    assert np.abs(robot.closure_jacobian(q) - cmodel.jacobian(robot.model, data, cdata)).max() <= 1e-12


@pytest.mark.parametrize("seed", SEEDS)
def test_frame_closure_jacobian_equals_pinocchios_frame_anchor_where_closed(seed: int) -> None:
    """A weld's error is zero where Pinocchio's FrameAnchorConstraintModel's is, its rotation part is log3 as
    Pinocchio's, and where closed its Jacobian is Pinocchio's (1e-12): a frame placed on the rocker where the
    coupler's tip is at a random q."""
    robot = kinelab.load("fourbar")
    q = robot.random_q(seed)
    oMtip = robot.frame_placement(q, "coupler_tip")
    rocker = robot.model.getJointId("rocker_joint")
    pin.forwardKinematics(robot.model, robot.data, q)
    placement = robot.data.oMi[rocker].actInv(oMtip)
    model = pin.Model(robot.model)
    model.addFrame(pin.Frame("weld_b", rocker, placement, pin.FrameType.OP_FRAME))
    welded = kinelab.Robot.from_model(model)
    weld = Closure("coupler_tip", "weld_b", "frame")
    welded.declare_closures([weld])
    assert np.abs(welded.closure_error(q)).max() <= 1e-12
    cmodel, cdata = anchor(welded, pin.FrameAnchorConstraintModel, weld)
    data = welded.model.createData()
    pin.computeJointJacobians(welded.model, data, q)
    pin.updateFramePlacements(welded.model, data)
    cmodel.calc(welded.model, data, cdata)
    assert np.abs(cdata.constraint_position_error).max() <= 1e-12
    assert np.abs(welded.closure_jacobian(q) - cmodel.jacobian(welded.model, data, cdata)).max() <= 1e-12
    moved = welded.random_q(seed + 100)  # off the weld: the rotation error is Pinocchio's log6's angular part
    pin.computeJointJacobians(welded.model, data, moved)
    pin.updateFramePlacements(welded.model, data)
    cmodel.calc(welded.model, data, cdata)
    assert np.abs(welded.closure_error(moved)[3:] - cdata.constraint_position_error[3:]).max() <= 1e-12


@pytest.mark.parametrize("kind", ["point", "frame", (1, 1, 0, 0, 0, 1), (1, 1, 1, 1, 1, 0)])
@pytest.mark.parametrize("seed", range(5))
def test_closure_jacobian_against_finite_differences(kind: object, seed: int) -> None:
    """Every kind's Jacobian is the error's derivative (central differences, 1e-7)."""
    robot = kinelab.load("fourbar")
    robot.declare_closures([Closure("coupler_tip", "rocker_tip", kind)], ["crank_joint"])  # type: ignore[arg-type]
    q = robot.random_q(seed)
    J = robot.closure_jacobian(q)
    h = 1e-6
    numeric = np.column_stack([(robot.closure_error(robot.integrate(q, h * e)) -
                                robot.closure_error(robot.integrate(q, -h * e))) / (2 * h) for e in np.eye(robot.nv)])
    assert J.shape == (len(Closure("a", "b", kind).rows), robot.nv)  # type: ignore[arg-type]
    assert np.abs(J - numeric).max() <= 1e-7


# -- assembly ----------------------------------------------------------------------------------------------------
def test_fourbar_assembly_against_its_closed_form() -> None:
    """From 500 seeded crank angles (a crank-rocker: every one assembles), the assembly closes the loop to 1e-10,
    holds the crank, and puts C where the closed form does (one of its two points, 1e-10)."""
    robot = kinelab.load("fourbar")
    rng = np.random.default_rng(69)
    for theta in rng.uniform(-np.pi, np.pi, 500):
        q = robot.assemble(np.array([theta, 0.0, 0.0]))
        assert q[0] == theta
        assert np.abs(robot.closure_error(q)).max() <= 1e-10
        tip = robot.frame_placement(q, "rocker_tip").translation
        assert min(np.abs(tip[:2] - c).max() for c in closed_form_c(theta, A, B, C, D)) <= 1e-10


def test_no_assembly_is_claimed_where_the_closed_form_has_none() -> None:
    """A four-bar that is not Grashof (crank 0.2, coupler 0.12, rocker 0.1, ground 0.3): where the closed form
    finds no C the assembly is refused with the gap it could not close; everywhere else it closes to 1e-10."""
    a, b, c, d = 0.2, 0.12, 0.1, 0.3
    robot = planar_fourbar(a, b, c, d)
    refused = closed = 0
    for theta in np.linspace(-np.pi, np.pi, 61):
        exists = bool(closed_form_c(theta, a, b, c, d))
        if exists:
            q = robot.assemble(np.array([theta, 0.0, 0.0]))
            assert np.abs(robot.closure_error(q)).max() <= 1e-10
            closed += 1
        else:
            with pytest.raises(AssemblyError, match="no assembly closes every loop") as caught:
                robot.assemble(np.array([theta, 0.0, 0.0]))
            assert caught.value.residual > 1e-3
            refused += 1
    assert closed >= 10 and refused >= 10  # both sides of the geometry tried


def test_assembly_holds_the_named_actuated_joints() -> None:
    """With the rocker named actuated instead, the rocker is held and the crank moves; at a rocker angle the
    rocker cannot reach (1.2 rad puts C 0.432 m from the crank's pivot, past a + b = 0.38) none is claimed."""
    robot = kinelab.load("fourbar")
    q = robot.assemble(np.array([0.0, 0.0, 1.8]), actuated=["rocker_joint"])
    assert q[2] == 1.8 and np.abs(robot.closure_error(q)).max() <= 1e-10
    with pytest.raises(AssemblyError):
        robot.assemble(np.array([0.0, 0.0, 1.2]), actuated=["rocker_joint"])


# -- declarations ----------------------------------------------------------------------------------------------
def test_a_registered_robot_declares_its_loops_and_a_file_declares_them_too(tmp_path: Path) -> None:
    robot = kinelab.load("fourbar")
    assert robot.closures == (Closure("coupler_tip", "rocker_tip", (1, 1, 0, 0, 0, 0)),)
    assert robot.actuated == ("crank_joint",)
    path = Path(robot.source or "")
    declaration = tmp_path / "loops.yaml"
    declaration.write_text("closures:\n  - {frame_a: coupler_tip, frame_b: rocker_tip}\nactuated: [rocker_joint]\n")
    again = kinelab.load(path, closures=declaration)
    assert again.closures == (Closure("coupler_tip", "rocker_tip", "point"),) and again.actuated == ("rocker_joint",)
    listed = kinelab.load(path, closures=[Closure("coupler_tip", "rocker_tip", "frame")], actuated=["crank_joint"])
    assert listed.closures[0].mask == (1, 1, 1, 1, 1, 1)
    assert kinelab.load(path, whole=True).closures == ()  # a file alone declares nothing


@pytest.mark.parametrize("text, words", [
    ("closures: 3\n", "mapping with 'closures'"),
    ("[1, 2]\n", "mapping with 'closures'"),
    ("closures: []\nextra: 1\n", "mapping with 'closures'"),
    ("closures:\n  - {frame_a: a}\n", "closures\\[0\\] must be"),
    ("closures:\n  - {frame_a: a, frame_b: b, kind: line}\n", "Closure kind"),
    ("closures:\n  - {frame_a: a, frame_b: b, kind: [1, 1, 0]}\n", "Closure kind"),
    ("closures:\n  - {frame_a: a, frame_b: a}\n", "two different frame names"),
    ("closures: []\nactuated: crank_joint\n", "'actuated' must be a list"),
    ("closures: [\n", "cannot read"),
    ("closures: !!python/object/apply:os.system ['true']\n", "cannot read"),
])
def test_malformed_declarations_are_named(tmp_path: Path, text: str, words: str) -> None:
    """A declaration is data: YAML's safe loader (no object tags), every bad shape named with the file."""
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(URDFError, match=words):
        read_closures(path)


def test_a_missing_declaration_is_named(tmp_path: Path) -> None:
    with pytest.raises(URDFError, match="cannot read the closures declaration"):
        read_closures(tmp_path / "none.yaml")


@pytest.mark.parametrize("closures, actuated, error, words", [
    ([Closure("coupler_tip", "nowhere")], [], FrameNotFoundError, "nowhere"),
    ([Closure("coupler_tip", "rocker_tip")], ["no_joint"], JointNotFoundError, "no_joint"),
    ("coupler_tip", [], OptionError, "a list of kinelab.Closure"),
    ([Closure("coupler_tip", "rocker_tip")], "crank_joint", OptionError, "a list of joint names"),
])
def test_bad_closures_are_named(closures: object, actuated: object, error: type, words: str) -> None:
    robot = kinelab.load("fourbar")
    with pytest.raises(error, match=words):
        robot.declare_closures(closures, actuated)  # type: ignore[arg-type]


@pytest.mark.parametrize("kind", ["line", (1, 1), (0, 0, 0, 0, 0, 0), (2, 0, 0, 0, 0, 0), (1.0, 1, 0, 0, 0, 0), 3])
def test_bad_closure_kinds_are_named(kind: object) -> None:
    with pytest.raises(OptionError, match="'point', 'frame' or six 0/1 values"):
        Closure("a", "b", kind)  # type: ignore[arg-type]


def test_assembly_without_loops_or_of_a_chain_load_is_refused() -> None:
    robot = kinelab.load(Path(kinelab.load("fourbar").source or ""), whole=True)
    with pytest.raises(OptionError, match="declared loops"):
        robot.assemble(robot.neutral())
    with pytest.raises(OptionError, match="actuated"):
        kinelab.load("ur5", actuated=["shoulder_pan_joint"])
