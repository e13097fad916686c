"""Singularity analysis: rank, lost directions and sweeps, and the youBot against Kapustina (2019)."""

import numpy as np
import pytest

import kinelab
from kinelab.analysis import families, singular
from kinelab.studies import paper003_youbot as yb


@pytest.fixture(scope="module")
def youbot():
    return kinelab.load("youbot")


def independent_rank(robot, q, rtol=1e-6):
    """Rank from numpy's SVD of Pinocchio's WORLD Jacobian, scaled by its own length (a different frame and
    code path from kinelab.analysis.singular)."""
    J = robot.jacobian_world(q)
    J[:3] /= 0.1
    s = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(s > rtol * s[0]))


def test_analysis_of_a_regular_configuration(youbot):
    q = youbot.neutral()
    q[4], q[5], q[6] = 0.4, 0.6, -0.3
    a = singular.analyze(youbot, q)
    assert a.rank == 6 and not a.singular and a.manipulability > 0 and np.isfinite(a.condition)
    assert len(a.null_motions) == 2  # 8 joints, rank 6


def test_the_papers_J_matches_finite_differences_of_X(youbot):
    rng = np.random.default_rng(1)
    for _ in range(20):
        Q = youbot.random_q(rng)
        for b in (1, -1):
            eps = 1e-6
            fd = np.array([(yb.paper_location(Q + eps * e, b) - yb.paper_location(Q - eps * e, b)) / (2 * eps)
                           for e in np.eye(8)]).T
            np.testing.assert_allclose(yb.paper_jacobian(Q, b), fd, atol=1e-6)


def test_the_papers_position_rows_are_pinocchios(youbot):
    rng = np.random.default_rng(2)
    for _ in range(50):
        Q = youbot.random_q(rng)
        np.testing.assert_allclose(yb.paper_location(Q)[:3], youbot.fk(Q).translation, atol=1e-12)
        np.testing.assert_allclose(yb.paper_jacobian(Q)[:3], youbot.jacobian_local_world_aligned(Q)[:3], atol=1e-12)


def test_rank_is_five_at_theta2_theta3_zero_for_the_paper_and_for_pinocchio(youbot):
    rng = np.random.default_rng(3)
    for _ in range(30):
        Q = yb.singular_configuration(rng)
        assert yb.paper_rank(Q, 1) == yb.paper_rank(Q, -1) == 5
        assert singular.analyze(youbot, Q).rank == 5 and independent_rank(youbot, Q) == 5


def test_the_papers_J_is_full_rank_over_the_limit_box(youbot):
    rng = np.random.default_rng(4)
    assert all(yb.paper_rank(youbot.random_q(rng)) == 6 for _ in range(500))


def test_tool_axis_vertical_is_a_family_pinocchio_sees_and_the_papers_J_does_not(youbot):
    """θ2 + θ3 + θ4 = 0: the gripper axis is vertical, parallel to the yaw axes; no joint turns the gripper
    about the horizontal axis of the arm plane — a real loss of motion. The paper's Euler angles are
    degenerate there (θ_E = 0), so its J keeps rank 6: a parameterisation effect."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        Q = youbot.random_q(rng)
        Q[6] = -Q[4] - Q[5]
        if not youbot.within_limits(Q) or abs(Q[4]) < 0.1 or abs(Q[5]) < 0.1:
            continue
        assert yb.paper_rank(Q) == 6
        a = singular.analyze(youbot, Q)
        assert a.rank == 5 and independent_rank(youbot, Q) == 5
        lost = np.array(a.lost_directions[0].twist)
        yaw = Q[2] + Q[3]
        x1 = np.array([np.cos(yaw), np.sin(yaw), 0.0])
        assert abs(abs(lost[3:] @ x1) - np.linalg.norm(lost)) < 1e-6  # pure rotation about x1


def test_equation_7_the_lost_motion_at_theta2_theta3_zero(youbot):
    """Ż_E = ∓c θ̇_E sin θ4: every twist obeys v_z ± c sin θ4 ω_y1 = 0, so the lost constraint is
    (e_z, c sin θ4 · y1) up to sign; C3, C4 cannot move vertically."""
    rng = np.random.default_rng(6)
    c = yb.PARAMS["c"]
    for _ in range(10):
        Q = yb.singular_configuration(rng)
        if abs(Q[6]) < 0.2 or abs(abs(Q[6]) - np.pi / 2) < 0.1:
            continue
        w = yb.lost_constraint(youbot, Q)
        yaw = Q[2] + Q[3]
        y1 = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
        np.testing.assert_allclose(w[:2], 0.0, atol=1e-9)
        assert abs(w[3:] @ y1) == pytest.approx(np.linalg.norm(w[3:]), abs=1e-9)
        assert np.linalg.norm(w[3:]) / abs(w[2]) == pytest.approx(c * abs(np.sin(Q[6])), rel=1e-6)


def test_theta4_zero_special_case_E_cannot_move_vertically(youbot):
    Q = yb.singular_configuration(np.random.default_rng(7), theta4=0.0)
    a = singular.analyze(youbot, Q)
    assert a.rank == 4  # θ2 = θ3 = θ4 = 0 also puts the gripper axis vertical: both families meet
    lost = np.array([d.twist for d in a.lost_directions])
    e_z = np.r_[0, 0, 1.0, 0, 0, 0]
    assert np.linalg.norm(lost @ e_z) == pytest.approx(1.0, abs=1e-9)  # vertical translation is lost


@pytest.fixture(scope="module")
def youbot_sweep(youbot):
    return families.sweep(youbot, samples=4000, seed=0, progress=False)


def test_sweep_finds_the_papers_family_and_the_vertical_gripper_families(youbot_sweep):
    texts = {tuple(r.text for r in f.relations) for f in youbot_sweep.families}
    assert ("arm_joint_2 = 0", "arm_joint_3 = 0") in texts
    # the gripper vertical, pointing down or up: one family of the angle sum modulo π (#60 item 5)
    assert ("arm_joint_2 + arm_joint_3 + arm_joint_4 = 0 or π",) in texts
    assert "platform_yaw is continuous: sampled on [−π, π]" in youbot_sweep.notes


def test_every_family_is_confirmed_by_an_independent_svd(youbot, youbot_sweep):
    for f in youbot_sweep.families:
        assert independent_rank(youbot, f.representative) < 6
        assert all(r.residual(f.representative) < families.RELATION_TOL for r in f.relations)


def test_era_has_the_papers_three_kinds_of_singularity():
    from kinelab.studies import paper000_era as ep

    era = kinelab.load("era")
    for kind, q in ep.singular_examples(era).items():
        joint, value = ep.SINGULAR_KINDS[kind]
        a = singular.analyze(era, q)
        assert a.rank == 5 and independent_rank(era, q) == 5, kind
        assert q[era.joint_index(joint)] == pytest.approx(value)
        assert len(a.lost_directions) == 1 and len(a.null_motions) == 2
    assert singular.analyze(era, [0.3, 0.2, 0.5, -0.8, 0.4, 0.2, 0.4]).rank == 6


@pytest.mark.parametrize("bad, match", [([0.0] * 7, "8 numbers"), ([0.0] * 7 + [np.nan], "finite")])
def test_bad_configurations(youbot, bad, match):
    with pytest.raises(kinelab.ConfigurationError, match=match):
        singular.analyze(youbot, bad)


def test_grid_sweep_on_a_6r_arm_finds_the_wrist_and_elbow_families():
    ur5 = kinelab.load("ur5")
    res = families.sweep(ur5, samples=4096, method="grid", progress=False)
    assert res.samples == 4 ** 6
    texts = [" and ".join(r.text for r in f.relations) for f in res.families]
    assert any("wrist_2_joint" in t for t in texts) and any("elbow_joint" in t for t in texts)
    for f in res.families:
        assert independent_rank(ur5, f.representative) < 6


@pytest.mark.parametrize("name", ["so101", "finger_edu"])
def test_arms_with_fewer_than_six_joints_report_the_twists_they_cannot_make(name):
    """A 5- or 3-joint arm: full rank n at a generic q, and 6 − n lost twists, each orthogonal to every
    column of the scaled Jacobian (checked against Pinocchio's Jacobian)."""
    robot = kinelab.load(name)
    for q in robot.random_qs(10, 4):
        a = singular.analyze(robot, q)
        assert a.full_rank == robot.n and a.rank == robot.n and not a.singular
        assert len(a.lost_directions) == 6 - robot.n
        J = singular.scaled_jacobian(robot, q)
        for d in a.lost_directions:
            assert d.sigma == 0.0
            assert np.max(np.abs(np.array(d.twist) @ J)) < 1e-9


# each angle family once, whatever turn it was found at (#60 item 5): kπ is "0", "π" or "0 or π"
UR_TRUE = {f"{joint} = {v}" for joint in ("wrist_2_joint", "elbow_joint") for v in ("0", "π", "0 or π")}


def test_ur5_sweep_reports_only_relations_that_keep_the_rank_down():
    """The UR5's simple singular families are the wrist (wrist_2 = kπ) and the elbow (elbow = kπ); its
    shoulder singularity (wrist centre over the base axis) has no simple joint relation and says so."""
    ur5 = kinelab.load("ur5")
    res = families.sweep(ur5, samples=2000, method="grid", seed=0)
    assert res.samples == 3 ** 6  # the grid that fits in 2000, reported as run
    for f in res.families:
        assert independent_rank(ur5, f.representative) < 6
        if f.verified:
            assert {r.text for r in f.relations} <= UR_TRUE, f.text
            assert families.holds_along(ur5, f.relations, f.representative, seed=7) == 1.0
        else:
            assert f.text.startswith("(no simple relation")
    assert not any("wrist_3_joint" in f.text and f.verified for f in res.families)  # the last joint never matters


def test_stanford_sweep_finds_the_retracted_boom_the_wrist_and_the_vertical_boom():
    stanford = kinelab.load("stanford")
    res = families.sweep(stanford, samples=3000, seed=0)
    verified = {f.text for f in res.families if f.verified}
    assert {"joint3 = 0", "joint5 = 0"} <= verified  # boom retracted (at its lower limit); wrist axes aligned
    assert verified <= {"joint3 = 0", "joint5 = 0", "joint2 = π/2", "joint2 = −π/2", "joint2 = −π/2 or π/2"}
    q = next(f.representative for f in res.families if f.text == "joint5 = 0").copy()
    q[5] += 1.0  # the relation holds whatever joint6 does
    assert singular.analyze(stanford, q).singular


def test_a_coincidental_relation_is_pruned_and_a_missing_one_is_not_invented():
    ur5 = kinelab.load("ur5")
    q = np.array([0.3, -1.1, 0.7, -0.4, 0.0, np.pi / 2])  # wrist singular, the last joint at π/2 by chance
    relations, verified = families.characterise(ur5, q)
    assert verified and [r.text for r in relations] == ["wrist_2_joint = 0"]
    q = np.array([0.3, -1.1, 0.7, -0.4, 0.9, 0.2])  # regular: nothing to explain
    assert families.holds_along(ur5, families.joint_relations(ur5, q), q) < 1.0
