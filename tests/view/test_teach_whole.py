"""#59: the whole robot's teach session without a browser: each hand's target met with the feet held and the centre
of mass kept over them, judged again by Pinocchio; what the page cannot do on a whole robot is said by name."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import assembled_draws

import kinelab
from kinelab.errors import KinelabError, OptionError
from kinelab.view.teach import teach
from kinelab.view.teach.whole import inside_polygon, support_polygon


@pytest.fixture(scope="module")
def talos_page():
    with teach(kinelab.load("talos")) as served:
        yield served


def test_a_moved_hand_is_met_and_the_feet_and_centre_of_mass_stay(talos_page):
    s = talos_page.session
    talos = s.robot
    feet = talos.frame_placements(s.q, talos.feet)
    com = talos.com(s.q)
    goal = pin.SE3(s.targets[1].rotation, s.targets[1].translation + np.array([0.04, -0.03, 0.06]))
    s.set_target(goal, 1)
    assert s.status.startswith("following")
    model, data = talos.model, talos.model.createData()
    pin.framesForwardKinematics(model, data, s.q)
    hand = data.oMf[model.getFrameId(talos.hands[1])]
    assert np.linalg.norm(pin.log6(hand.actInv(goal)).vector) <= 2e-6
    for name, M in zip(talos.feet, feet, strict=True):
        assert np.linalg.norm(pin.log6(data.oMf[model.getFrameId(name)].actInv(M)).vector) <= 2e-6
    assert np.linalg.norm(pin.centerOfMass(model, data, s.q)[:2] - com[:2]) <= 1e-6
    r = s.readout()
    assert r["com_over_support"] and r["hands"][1]["position_error_m"] <= 1e-6


def test_a_hand_out_of_reach_keeps_q_and_names_the_missed_task(talos_page):
    s = talos_page.session
    before = s.q.copy()
    s.set_target(pin.SE3(np.eye(3), np.array([3.0, 0.0, 1.0])), 0)
    assert np.array_equal(s.q, before) and "not reached" in s.status and s.robot.hands[0] in s.status


def test_what_a_whole_robot_s_page_does_not_do_is_said(talos_page):
    s = talos_page.session
    with pytest.raises(KinelabError, match="no branches"):
        s.step_branch(1)
    with pytest.raises(KinelabError, match="true or false"):
        s.set_collisions("yes")
    with pytest.raises(KinelabError, match="from 0 to 1"):
        s.set_target(s.targets[0], 2)
    with pytest.raises(OptionError, match="hands"):
        teach(kinelab.load("talos"), hands=())


def test_the_sliders_name_each_bounded_joint_at_its_place_in_q(talos_page):
    s = talos_page.session
    config = s.page_config()
    model = s.robot.model
    assert config["targets"] == ["target_0", "target_1"] and config["whole"]
    for j in config["joints"]:
        joint = model.joints[model.getJointId(j["name"])]
        assert j["iq"] == joint.idx_q and j["lower"] == s.robot.lower[joint.idx_q]
    assert len(config["joints"]) == model.nq - 7  # every joint of TALOS but the free-flyer


def test_the_support_polygon_holds_both_soles_and_the_test_of_inside_is_right():
    feet = [pin.SE3(np.eye(3), np.array([0.0, 0.1, 0.0])), pin.SE3(np.eye(3), np.array([0.0, -0.1, 0.0]))]
    hull = support_polygon(feet)
    assert np.allclose(sorted(hull[:, 0]), [-0.1, -0.1, 0.1, 0.1]) and np.allclose(sorted(hull[:, 1]),
                                                                                    [-0.15, -0.15, 0.15, 0.15])
    assert inside_polygon(np.array([0.05, 0.0]), hull) and not inside_polygon(np.array([0.15, 0.0]), hull)


def test_a_robot_with_loops_has_a_slider_per_motor_and_stays_on_its_loops():
    """#69: the four-bar's and the delta's teach pages slide their motors only; a motor set from the page moves the
    passive joints to close every loop (1e-10), the motor where it was put; motor values with no assembly (a seeded
    draw of Cassie's) leave the robot where it was and say so."""
    for name in ("fourbar", "delta"):
        robot = kinelab.load(name)
        with teach(robot) as served:
            session = served.session
            assert [j["name"] for j in session.page_config()["joints"]] == list(robot.actuated)
            motor = robot.model.joints[robot.model.getJointId(robot.actuated[0])].idx_q
            q = session.q.copy()
            q[motor] += 0.2
            session.set_q(q)
            assert session.q[motor] == pytest.approx(q[motor], abs=1e-15)
            assert np.abs(robot.closure_error(session.q)).max() <= 1e-10
            assert "loops closed" in session.status
    cassie = kinelab.load("cassie")
    draws = list(assembled_draws(cassie, 6, np.random.default_rng(7)))
    stuck = draws[5][0]  # motors at which Cassie's loops cannot close within its limits
    assert draws[5][1] is None
    with teach(cassie) as served:
        before = served.session.q.copy()
        served.session.set_q(stuck)
        assert np.array_equal(served.session.q, before) and "no assembly" in served.session.status


def test_a_fourbar_s_hand_dragged_off_its_curve_goes_as_near_as_its_loop_lets_it():
    """#69: the four-bar's coupler tip moves on a curve; a target 3 cm off it (along the curve's normal at the tip's
    place with the crank 0.3 rad on, found by differences) is met as nearly as the loop allows: the tip ends 3 cm ±
    1 mm from the target, at the foot of the normal (1 mm), the loop closed (1e-10), the status saying how far."""
    robot = kinelab.load("fourbar")
    with teach(robot) as served:
        session = served.session
        q = session.q.copy()
        q[0] += 0.3
        q = robot.assemble(q)
        tip = robot.frame_placement(q, "coupler_tip").translation
        ahead = q.copy()
        ahead[0] += 1e-4
        tangent = robot.frame_placement(robot.assemble(ahead), "coupler_tip").translation - tip
        tangent /= np.linalg.norm(tangent)
        normal = np.cross([0.0, 0.0, 1.0], tangent)
        target = pin.SE3(np.eye(3), tip + 0.03 * normal)
        session.set_target(target)
        reached = robot.frame_placement(session.q, "coupler_tip").translation
        assert np.linalg.norm(reached - target.translation) == pytest.approx(0.03, abs=1e-3)
        assert np.linalg.norm(reached - tip) <= 1e-3
        assert np.abs(robot.closure_error(session.q)).max() <= 1e-10 and "as near as" in session.status
