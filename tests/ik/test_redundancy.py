"""7R arms by their redundancy parameter (kinelab.ik.analytic.redundancy), against Pinocchio and against the
closed form of the 6R arm Pinocchio builds with the swept joint locked."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import chain_urdf, write_urdf

import kinelab
from kinelab.ik.analytic.redundancy import samples, swept_arm


@pytest.fixture(scope="module")
def era():
    return kinelab.load("era")


def _same_sets(a: np.ndarray, b: np.ndarray, tol: float = 1e-6) -> bool:
    """Each row of a has a row of b within tol (joint by joint, modulo 2π), and the other way round."""
    def covered(x, y):
        return all(np.min(np.max(np.abs(np.angle(np.exp(1j * (y - row)))), axis=1)) < tol for row in x)
    return len(a) == len(b) and covered(a, b) and covered(b, a)


def _contains(rows: np.ndarray, q: np.ndarray, tol: float = 1e-6) -> bool:
    """One of rows is q within tol [rad], joint by joint modulo 2π."""
    return bool(np.min(np.max(np.abs(np.angle(np.exp(1j * (rows - q)))), axis=1)) < tol)


@pytest.mark.parametrize("name, held", [("era", 0), ("panda", 6), ("xarm7", 6), ("pr2_left", 0)])
def test_every_answer_meets_the_pose_within_the_limits_at_the_sampled_values(name, held):
    robot = kinelab.load(name)
    assert swept_arm(robot).joint == held
    thetas = samples(float(robot.lower[held]), float(robot.upper[held]), 16)
    for seed in range(20):
        target = robot.fk(robot.random_q(seed))
        found = kinelab.solve_all(robot, target, redundancy=16)
        assert found and all(r.success and r.diagnostics.branches == len(found) for r in found)
        for r in found:
            dp, dr = robot.tool_error(r.q, target)  # Pinocchio's FK of the whole 7R chain
            assert dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(r.q)
            assert np.min(np.abs(thetas - r.q[held])) < 1e-12  # the held joint is one of its 16 samples


def test_the_branches_at_each_sample_are_those_of_the_arm_with_that_joint_locked(era):
    """The reference: Pinocchio reduces the model with joint 1 locked at θ, kinelab classifies that 6R arm
    from scratch and returns its branches; the sweep's answers with q1 = θ must be the same set."""
    thetas = samples(float(era.lower[0]), float(era.upper[0]), 4)
    compared = 0
    for seed in range(6):
        target = era.fk(era.random_q(100 + seed))
        swept = np.array([r.q for r in kinelab.solve_all(era, target, redundancy=4)])
        for theta in thetas:
            locked = kinelab.load("era", locked={"joint1": float(theta)})
            reference = np.array([r.q for r in kinelab.solve_all(locked, target, solver="analytic")]).reshape(-1, 6)
            mine = swept[np.abs(swept[:, 0] - theta) < 1e-12][:, 1:] if len(swept) else np.zeros((0, 6))
            assert _same_sets(mine, reference), (seed, theta)
            compared += len(reference)
    assert compared > 20  # the comparison covered answers, not only empty sets


@pytest.mark.parametrize("name, tol, share", [("era", 1e-6, 1.0), ("panda", 1e-6, 1.0), ("xarm7", 1e-4, 0.9)])
def test_the_configuration_a_pose_came_from_is_found_when_its_joint_is_a_sample(name, tol, share):
    """Found to ``tol`` [rad] on ``share`` of 50 poses. The xArm7's file puts its wrist axes 1.1e-6 m from a
    common point: its roots sit ~1e-6 rad from the configuration the pose came from, and near a straight elbow
    (q4 ≈ π, a near double root) up to a few 1e-2 rad, each still meeting the pose (finished by FRDM)."""
    robot = kinelab.load(name)
    held = swept_arm(robot).joint
    thetas = samples(float(robot.lower[held]), float(robot.upper[held]), 8)
    rng = np.random.default_rng(5)
    hits = 0
    for k in range(50):
        q = robot.random_q(200 + k)
        q[held] = thetas[rng.integers(8)]
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target, redundancy=8)
        assert all(max(robot.tool_error(r.q, target)) <= 1e-6 for r in found)
        hits += _contains(np.array([r.q for r in found]), q, tol)
    assert hits >= share * 50


def test_the_panda_s_branches_at_each_sample_are_eaik_s_for_the_arm_locked_there():
    """The reference is independent of kinelab's algebra: Pinocchio reduces the Panda with joint 7 locked at
    each sample and EAIK (Ostermeier et al.; 6R-SPHERICAL_FIRST_TWO_INTERSECTING) solves that 6R arm."""
    from test_analytic import Eaik, confirmed, same_set

    panda = kinelab.load("panda")
    thetas = samples(float(panda.lower[6]), float(panda.upper[6]), 4)
    locked = {float(t): kinelab.load("panda", locked={"panda_joint7": float(t)}) for t in thetas}
    peers = {t: Eaik(arm) for t, arm in locked.items()}
    assert all(p.bot.getKinematicFamily() == "6R-SPHERICAL_FIRST_TWO_INTERSECTING" for p in peers.values())
    agree, compared = 0, 0
    for seed in range(100):
        target = panda.fk(panda.random_q(400 + seed))
        swept = np.array([r.q for r in kinelab.solve_all(panda, target, redundancy=4)]).reshape(-1, 7)
        for t, arm in locked.items():
            mine = swept[np.abs(swept[:, 6] - t) < 1e-12][:, :6]
            reference = confirmed(arm, target, peers[t](target))
            agree += same_set(list(mine), reference)
            compared += 1
    assert agree >= 0.99 * compared


def test_holding_the_last_joint_solves_the_same_poses(era):
    """The ERA is analytic with either end held; the sweep uses the first. Held at its last joint instead,
    the six others' branches at the pose's own q7 contain the q the pose came from, and all meet the pose."""
    from kinelab.ik.analytic import redundancy
    from kinelab.ik.chain import chain_model

    v = chain_model(era).vectors(np.zeros(7))
    end = redundancy.holding(v["e"], v["o"], v["R"], v["N"], 6)
    assert isinstance(end, redundancy.SweptArm) and swept_arm(era).joint == 0
    for seed in range(20):
        q = era.random_q(300 + seed)
        target = era.fk(q)
        q6, _, _ = redundancy.arm_roots(end.arm, end.sub_target(target.homogeneous, float(q[6])), era.lower[:6],
                                        era.upper[:6], None)
        answers = np.array([np.append(r, q[6]) for r in q6])
        assert len(answers) and all(max(era.tool_error(a, target)) < 1e-6 for a in answers)
        assert _contains(answers, q)


def test_arms_that_cannot_be_swept_are_refused_by_name(era, tmp_path):
    # seven parallel axes: holding an end joint leaves a planar six that nothing here solves
    planar = kinelab.load(write_urdf(tmp_path, chain_urdf(np.tile([0.0, 0.0, 1.0], (7, 1)),
                                                          np.array([[0.2 * i, 0.03 * i, 0.1 * i] for i in range(7)]),
                                                          pin.SE3(np.eye(3), np.array([1.5, 0.2, 0.7])),
                                                          np.full(7, -3.0), np.full(7, 3.0))), tool="tool")
    ur5 = kinelab.load("ur5")
    with pytest.raises(kinelab.OptionError, match=r"t's is not: joint 1 held .*joint 7 held.*general 6R elimination "
                                                  r"degenerates"):
        kinelab.solve_all(planar, planar.fk(planar.random_q(1)), redundancy=8)
    with pytest.raises(kinelab.OptionError, match="6 joints"):
        kinelab.solve_all(ur5, ur5.fk(ur5.random_q(1)), redundancy=8)
    target = era.fk(era.random_q(1))
    for bad in (0, -1, True, 2.0, "8", 10**6):
        with pytest.raises(kinelab.OptionError, match="redundancy"):
            kinelab.solve_all(era, target, redundancy=bad)
    with pytest.raises(kinelab.OptionError, match="solver='frdm'"):
        kinelab.solve_all(era, target, redundancy=8, solver="frdm")
    with pytest.raises(kinelab.OptionError, match="task"):
        kinelab.solve_all(era, pin.SE3(np.eye(3), np.array([1.0, 2.0, 6.0])), redundancy=8, task="position")


def test_frdm_answers_on_the_era_are_closed_form_branches_and_the_kick_does_not_pick_the_elbow(era):
    """The FRDM paper (seed 000) calls its answer unique and bends the ERA's straight elbow with a signed kick
    (δq4 < 0). Against the swept closed form: every FRDM answer is one of the branches at its own q1 (FRDM
    returns one of several, chosen by its start) and, started from the target's own configuration with the
    elbow straightened, the kick's sign gives the answer's elbow sign about as often as a coin would.

    An answer within the tolerances may sit at (or 1e-6 rad inside) a joint limit whose exact root lies beyond
    it (up to 3e-5 rad here, near a singular wrist, where the other joints make up the difference to 1e-7):
    such an answer is no exact branch, and the test names that as the only way to miss one."""
    from kinelab.ik.analytic.redundancy import at_value
    from kinelab.ik.request import make_request

    rng = np.random.default_rng(1)
    req = make_request("frdm")
    solved, agree, counts, at_limit = 0, 0, [], 0
    for k in range(150):
        q = era.random_q(rng)
        if abs(q[3]) < 0.3:  # an elbow clearly bent one way or the other
            continue
        target, q0 = era.fk(q), q.copy()
        q0[3] = 0.0
        for kick in (-0.01, 0.01):
            res = kinelab.solve(era, target, q0=q0, seed=k, max_restarts=0, kicks={"joint4": kick})
            if not res.success:
                continue
            solved += 1
            agree += int(np.sign(res.q[3]) == np.sign(kick))
            branches = np.array([a[0] for a in at_value(era, target, req, float(res.q[0]))])
            counts.append(len(branches))
            if not (len(branches) and _contains(branches, res.q, 1e-4)):
                assert np.min(np.minimum(res.q - era.lower, era.upper - res.q)) < 1e-4, res.q
                at_limit += 1
    assert solved >= 150 and at_limit <= 0.03 * solved and 0.35 <= agree / solved <= 0.65
    assert np.mean(counts) > 2  # several branches at each answer's own q1


@pytest.mark.parametrize(("name", "joint"), [("tiago_pro", 0), ("tiago_pro", 3), ("xarm7", 3), ("baxter_left", 2)])
def test_any_joint_of_a_7r_arm_held_gives_every_branch_with_the_pose_s_own_configuration(name, joint):
    """#41 item 4: with one joint held at a value, the six left are solved by a class or the general 6R elimination
    (TIAGo Pro's six are in no class at either end; the middle joints leave no class either)."""
    robot = kinelab.load(name)
    held = robot.joints[joint].name
    rng = np.random.default_rng(joint)
    for q in robot.random_qs(6, rng):
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target, redundancy={held: float(q[joint])})
        assert f"joint {joint + 1} held at {q[joint]:.6g} rad" in found[0].mode
        assert all(abs(s.q[joint] - q[joint]) <= 1e-12 and max(robot.tool_error(s.q, target)) <= 1e-6
                   and robot.within_limits(s.q) for s in found)
        assert min(np.abs(np.arctan2(np.sin(s.q - q), np.cos(s.q - q))).max() for s in found) <= 1e-6
