"""#58 item 1 and goal 5: a Robot is the whole model. For every robot of example-robot-data that Pinocchio loads
(the humanoids, quadrupeds and flying bases with a free-flyer), kinelab's frame placements, centre of mass and the
three Jacobians of every frame equal Pinocchio's own calls on a model built here from the file (1e-12), at 100 seeded
q each; a chain is a view of its robot."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.robot import catalog

ERD = Path(catalog.erd_share_dir() or "/nonexistent") / "example-robot-data" / "robots"
CORPUS = sorted(ERD.rglob("*.urdf"))
FIXED = ("panda", "ur_", "kinova", "xarm", "z1", "so_arm", "finger", "baxter", "pr2", "tiago", "double_pendulum",
         "asr_twodof", "allegro", "talos_left_arm")  # arms and bases bolted to the floor: the rest float
REFERENCES = (pin.LOCAL, pin.WORLD, pin.LOCAL_WORLD_ALIGNED)
NAMES = {pin.LOCAL: "local", pin.WORLD: "world", pin.LOCAL_WORLD_ALIGNED: "local_world_aligned"}
TOL = 1e-12


def floating(path: Path) -> bool:
    return not any(key in str(path.relative_to(ERD)) for key in FIXED)


def pinocchio_model(path: Path, free: bool) -> pin.Model | None:
    """The file as Pinocchio loads it, with its mimic joints where it can (a mimic whose leader the file lacks is a
    plain joint, as kinelab reads it); None where Pinocchio cannot load it (then not in the test's scope)."""
    for mimic in ("<mimic" in path.read_text(), False):
        try:
            return pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer(), mimic=mimic) if free else \
                pin.buildModelFromUrdf(str(path), mimic=mimic)
        except (RuntimeError, ValueError):
            continue
    return None


def assert_equal_to_pinocchio(robot: kinelab.Robot, model: pin.Model, seed: int, count: int) -> None:
    data = model.createData()
    frames = [f.name for f in model.frames]
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = robot.random_q(rng)
        pin.computeJointJacobians(model, data, q)
        pin.framesForwardKinematics(model, data, q)
        placements = robot.frame_placements(q, frames)
        for fid, (name, oMf) in enumerate(zip(frames, placements, strict=True)):
            if robot.frame_id(name) != fid:  # a name two frames share: kinelab takes the first (a body's)
                continue
            assert np.abs(oMf.homogeneous - data.oMf[fid].homogeneous).max() <= TOL
            for ref in REFERENCES:
                J = robot.frame_jacobian(q, name, NAMES[ref])
                assert np.abs(J - pin.getFrameJacobian(model, data, fid, ref)).max() <= TOL, (name, NAMES[ref])
        com = pin.centerOfMass(model, data, q)
        assert np.abs(robot.com(q) - com).max() <= TOL
        assert np.abs(robot.com_jacobian(q) - pin.jacobianCenterOfMass(model, data, q)).max() <= TOL


@pytest.mark.skipif(not CORPUS, reason="example-robot-data not installed")
@pytest.mark.parametrize("path", CORPUS, ids=lambda p: str(p.relative_to(ERD)))
def test_every_loadable_robot_whole_equals_pinocchio(path):
    free = floating(path)
    model = pinocchio_model(path, free)
    if model is None:
        with pytest.raises(kinelab.KinelabError):
            kinelab.load(path, whole=True, floating=free)
        return
    try:
        robot = kinelab.load(path, whole=True, floating=free)
    except kinelab.KinelabError as err:  # kinelab refuses a file Pinocchio reads: the refusal names the file
        assert path.stem in str(err) or "joint" in str(err), err
        return
    assert isinstance(robot, kinelab.Robot) and (robot.nq, robot.nv) == (model.nq, model.nv)
    assert robot.floating == free and robot.model.nframes == model.nframes
    assert_equal_to_pinocchio(robot, model, seed=hash(path.name) % 1000, count=100)


@pytest.mark.parametrize("name", [e.name for e in catalog.ERD_WHOLE])
def test_the_catalog_loads_the_whole_robots_by_name(name):
    robot = kinelab.load(name)
    entry = catalog.ENTRIES[name]
    assert isinstance(robot, kinelab.Robot) and robot.floating == entry.floating and robot.name == name
    q = robot.random_q(0)
    assert robot.within_limits(q) and np.isclose(np.linalg.norm(q[3:7]), 1.0) if robot.floating else True
    assert robot.mass > 0


def test_a_chain_is_a_view_of_its_robot():
    talos = kinelab.load("talos")
    arm = talos.chain("torso_2_link", "gripper_left_base_link")
    assert isinstance(arm, kinelab.Chain) and arm.robot is talos and arm.n == 7
    rng = np.random.default_rng(3)
    for _ in range(20):
        q_whole = talos.random_q(rng)
        q = q_whole[arm.q_index]
        oMb, oMt = talos.frame_placements(q_whole, ["torso_2_link", "gripper_left_base_link"])
        assert np.abs(arm.fk(q).homogeneous - (oMb.inverse() * oMt).homogeneous).max() <= 1e-12
        assert np.array_equal(arm.in_whole(q, q_whole), q_whole)


def test_a_registered_arm_keeps_its_chain_and_reaches_its_whole_robot():
    panda = kinelab.load("panda")
    assert isinstance(panda, kinelab.Chain) and panda.n == 7
    whole = panda.robot
    assert isinstance(whole, kinelab.Robot) and not whole.floating and "panda_hand_tcp" in whole.frame_names
    q = panda.random_q(4)
    assert np.abs(whole.frame_placement(panda.in_whole(q), "panda_hand_tcp").homogeneous
                  - panda.fk(q).homogeneous).max() <= 1e-12


def test_from_model_gives_the_whole_robot_or_a_chain():
    model = kinelab.load("talos").model
    whole = kinelab.Robot.from_model(model)
    assert isinstance(whole, kinelab.Robot) and whole.nq == model.nq and whole.model is not model
    arm = kinelab.Robot.from_model(kinelab.load("panda").robot.model, tool="panda_hand_tcp")
    assert isinstance(arm, kinelab.Chain) and arm.n == 7
    flying = kinelab.Robot.from_model(kinelab.load("panda").robot.model, floating=True)
    assert flying.floating and flying.nq == 8 + 7


@pytest.mark.parametrize("call, error, needle", [
    (lambda r: r.frame_placement(r.neutral(), "nosuch"), kinelab.FrameNotFoundError, "nosuch"),
    (lambda r: r.frame_jacobian(r.neutral(), "left_sole_link", "body"), kinelab.OptionError, "local"),
    (lambda r: r.com(np.zeros(5)), kinelab.ConfigurationError, "nq = 39"),
    (lambda r: r.com(np.zeros(39)), kinelab.ConfigurationError, "unit norm"),
    (lambda r: r.check_q(np.full(39, np.nan)), kinelab.ConfigurationError, "finite"),
    (lambda r: r.random_qs(-1), kinelab.OptionError, "count"),
    (lambda r: kinelab.load("talos", tool="x"), kinelab.OptionError, "whole robot"),
    (lambda r: kinelab.load("ur5", whole="yes"), kinelab.OptionError, "whole"),
])
def test_bad_input_to_the_whole_robot_is_named(call, error, needle):
    with pytest.raises(error, match=needle):
        call(kinelab.load("talos"))


@pytest.mark.parametrize("name", [e.name for e in catalog.BUNDLED + catalog.ERD_ARMS])
def test_a_registered_arm_and_its_view_of_the_whole_robot_answer_alike_bit_for_bit(name):
    """#58: a chain taken from the whole robot (base, tool and the arm's locked joints) is today's chain: the same
    limits, FK and IK answers, bit for bit, at seeded configurations and seeds."""
    arm = kinelab.load(name)
    view = arm.robot.chain(arm.base, arm.tool, locked=dict(arm.locked) or None)
    assert view.n == arm.n and np.array_equal(view.lower, arm.lower) and np.array_equal(view.upper, arm.upper)
    rng = np.random.default_rng(7)
    for seed in range(3):
        q = arm.random_q(rng)
        assert np.array_equal(view.fk(q).homogeneous, arm.fk(q).homogeneous)
        ours, theirs = kinelab.solve(view, arm.fk(q), seed=seed), kinelab.solve(arm, arm.fk(q), seed=seed)
        assert ours.status == theirs.status and np.array_equal(ours.q, theirs.q)
        assert ours.success and max(arm.tool_error(ours.q, arm.fk(q))) <= 1e-6


def test_derived_data_is_built_once_per_key_even_when_it_is_none():
    """A builder that answers None (a tree the compiled step does not take, a chain without compiled arrays) is not
    run again on every call: its None is kept like any other value, on the whole robot and on a chain."""
    for owner in (kinelab.load("panda"), kinelab.load("panda").robot):
        calls = []

        def build(_, calls=calls):
            calls.append(1)
            return None

        assert owner.derived("test: nothing to build", build) is None
        assert owner.derived("test: nothing to build", build) is None
        assert len(calls) == 1
        assert owner.derived("test: a value", lambda _: [3]) == owner.derived("test: a value", lambda _: [4]) == [3]


def test_whole_floats_a_robot_whose_srdf_declares_a_floating_virtual_joint():
    """#72 item 6: ``load(urdf, whole=True, srdf=...)`` of a quadruped whose SRDF declares ``<virtual_joint
    type="floating">`` (go2) gives it a free-flyer (nq 12 + 7); without the SRDF, or with ``floating=False``, the
    base is fixed; a registered arm's SRDF without one leaves it fixed."""
    urdf, srdf = ERD / "go2_description/urdf/go2.urdf", ERD / "go2_description/srdf/go2.srdf"
    walker = kinelab.load(urdf, whole=True, srdf=srdf)
    assert walker.floating and walker.nq == 19 and walker.model.joints[1].shortname() == "JointModelFreeFlyer"
    assert not kinelab.load(urdf, whole=True).floating
    assert not kinelab.load(urdf, whole=True, srdf=srdf, floating=False).floating
    panda = ERD / "panda_description"
    assert not kinelab.load(panda / "urdf/panda.urdf", whole=True, srdf=panda / "srdf/panda.srdf").floating
