"""Every branch of any 6R arm by the general algebraic elimination, with a certificate (docs/analytic.md, "Any 6R
arm" and "Certificates").

The oracles: the configuration each pose is made from (it must be among the branches), Pinocchio's FK (every
answer meets the pose), and the multistart, which solves the same poses its own way (every branch it finds must be
among the elimination's). Hard poses are built on purpose: a root at a half-angle of ±π, a double root on the
singular surface and close pairs beside it, a wrist-singular pose, the CRX's 16-branch pose.
"""

import numpy as np
import pytest
from helpers import assert_meets_pose, chain_urdf, multistart_gaps, turn_gap, write_urdf

import kinelab
from kinelab.ik.analytic.certify import kantorovich, loop_of
from kinelab.ik.analytic.classify import general_class
from kinelab.report.bench.completeness import random_general_arm

TOL = 1e-6  # [m, rad] the judge's tolerances
FOUND = 1e-9  # [rad] the pose's own configuration is a branch to this, joint by joint, modulo 2π


def wrapped(d):
    return np.arctan2(np.sin(d), np.cos(d))


gap = turn_gap


def general_robot(tmp_path, seed):
    h, o, tool = random_general_arm(np.random.default_rng(seed))
    path = write_urdf(tmp_path, chain_urdf(h, o, tool, np.full(6, -np.pi), np.full(6, np.pi)), f"g{seed}.urdf")
    return kinelab.load(path, tool="tool")


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_random_general_arms_give_the_pose_s_own_configuration_among_certified_judged_branches(tmp_path, seed):
    robot = general_robot(tmp_path, seed)
    rng = np.random.default_rng(seed)
    for _ in range(25):
        q = robot.random_q(rng)
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target)
        assert found.method == "elimination" and "general 6R" in found[0].mode
        assert found.complete == "certified" and found.complete_reason == ""
        assert 2 <= len(found) <= 16 and len(found) % 2 == 0  # real roots of a real degree-16 polynomial pair up
        assert min(gap(s.q, q) for s in found) <= FOUND
        assert_meets_pose(robot, found.q, target, TOL)
        assert min((gap(a.q, b.q) for i, a in enumerate(found) for b in found[i + 1:]), default=1.0) > 1e-6


def test_every_branch_the_multistart_finds_is_among_the_elimination_s(tmp_path):
    for _, found, farthest in multistart_gaps(general_robot(tmp_path, 7), 7):
        assert found >= 1 and farthest <= 1e-5


def test_a_root_at_a_half_angle_of_pi_is_found_and_certified(tmp_path):
    """The elimination's variable is x₃ = tan((q₃ − φ₃)/2): at q₃ = φ₃ + π it is infinite (an eigenvalue at ∞)."""
    robot = general_robot(tmp_path, 11)
    arm = general_class(robot).arm
    g = arm.solver[0]
    q = robot.random_q(np.random.default_rng(11))
    joint = 2 if not arm.mirrored else 3  # the mirrored chain's third joint is the robot's fourth
    q[joint] = wrapped((g.phi[2] + np.pi) * (1 if not arm.mirrored else -1))
    found = kinelab.solve_all(robot, robot.fk(q))
    assert min(gap(s.q, q) for s in found) <= FOUND and found.complete == "certified"


def _singular_q(robot, q, joint=2):
    """q with joint ``joint`` moved onto the singular surface (det J = 0), found by bisection on a sign change."""
    def det(x):
        qq = q.copy()
        qq[joint] = x
        return np.linalg.det(robot.jacobian_world(qq))
    xs = np.linspace(-np.pi, np.pi, 721)
    d = np.array([det(x) for x in xs])
    k = int(np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))[0])
    a, b = xs[k], xs[k + 1]
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if np.sign(det(m)) == np.sign(det(a)) else (a, m)
    out = q.copy()
    out[joint] = 0.5 * (a + b)
    return out


@pytest.mark.parametrize("offset", [0.0, 1e-7, 1e-4])
def test_on_and_beside_the_singular_surface_the_set_holds_the_pose_s_configuration_or_says_it_is_uncertified(
        tmp_path, offset):
    """On the surface det J = 0 two roots meet (a double root): Kantorovich cannot prove it, and the set says so.
    Beside it, two close roots: both are answered, or the set is marked uncertified — never one answer for two
    roots with a certificate."""
    robot = general_robot(tmp_path, 5)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q = _singular_q(robot, robot.random_q(rng))
        q[2] += offset
        found = kinelab.solve_all(robot, robot.fk(q))
        nearest = min(gap(s.q, q) for s in found)
        if offset == 0:
            assert found.complete == "search" and found.complete_reason
        if found.complete == "certified":
            own = [s for s in found if gap(s.q, q) <= 1e-7]
            assert nearest <= 1e-7 and len(own) == 1
        else:  # two roots closer than rounding tells apart may be answered by one between them, said uncertified
            assert "near-double root" in found.complete_reason and nearest <= 1e-6


def test_the_loop_equations_are_pinocchio_s_pose_error_and_their_jacobian_its_derivative():
    """The compiled loop equations F = ((p − p*)/ℓ, ½ Σ_k R*e_k × R e_k) against the same quantities from Pinocchio's
    FK, and F′ against central differences of them (seeded configurations of two arms)."""
    from kinelab.ik.analytic.branches import robot_loop
    from kinelab.ik.analytic.certify import equations

    def pinocchio_F(robot, q, target, scale):
        oM = robot.fk(q)
        g = 0.5 * sum(np.cross(target.rotation[:, k], oM.rotation[:, k]) for k in range(3))
        return np.concatenate([(oM.translation - target.translation) / scale, g])

    for name in ("general6r", "ur5"):
        robot = kinelab.load(name)
        loop = robot_loop(robot)
        rng = np.random.default_rng(6)
        for _ in range(10):
            q, target = robot.random_q(rng), robot.fk(robot.random_q(rng))
            F, J = equations(loop, q[None], target.homogeneous)
            np.testing.assert_allclose(F[0], pinocchio_F(robot, q, target, loop.scale), atol=1e-12)
            step = 1e-6
            for j in range(6):
                dq = np.eye(6)[j] * step
                central = (pinocchio_F(robot, q + dq, target, loop.scale)
                           - pinocchio_F(robot, q - dq, target, loop.scale)) / (2 * step)
                np.testing.assert_allclose(J[0, :, j], central, atol=1e-8)


def test_kantorovich_proves_a_root_and_refuses_a_point_that_is_not_one():
    ur5 = kinelab.load("ur5")
    q = ur5.random_q(np.random.default_rng(3))
    from kinelab.ik.chain import chain_model
    v = chain_model(ur5).vectors(np.zeros(6))
    loop = loop_of(v["e"].copy(), v["o"].copy(), v["R"].copy(), v["N"].copy())
    H = ur5.fk(q).homogeneous
    proof = kantorovich(loop, np.array([q, q + 1e-3]), H)
    assert proof.proved.tolist() == [True, False]
    assert proof.inside[0] < 1e-9 < 1e-3 < proof.alone[0]  # a tiny ball holds the root, a wide one holds no other


def test_closed_form_sets_are_certified_and_a_wrist_singular_pose_is_said_not_to_be():
    ur5 = kinelab.load("ur5")
    rng = np.random.default_rng(4)
    for _ in range(10):
        found = kinelab.solve_all(ur5, ur5.fk(ur5.random_q(rng)))
        assert found.method == "closed form" and found.complete == "certified"
    q = ur5.random_q(rng)
    q[4] = 0.0  # axes 4 and 6 aligned: q4 + q6 is a continuum
    found = kinelab.solve_all(ur5, ur5.fk(q))
    assert found.complete == "search" and "continuum" in found.complete_reason


def test_the_crx_sixteen_branch_pose_is_certified_by_its_count():
    from test_search import CRX_SIXTEEN

    crx = kinelab.load("crx10ia")
    found = kinelab.solve_all(crx, crx.fk(np.array(CRX_SIXTEEN)))
    assert len(found) == 16 and found.method == "search" and found.complete == "certified"
    fewer = kinelab.solve_all(crx, crx.fk(crx.random_q(np.random.default_rng(1))))
    assert len(fewer) < 16 and fewer.complete == "search" and "measured complete" in fewer.complete_reason


def test_the_xarm6_search_sets_are_certified_by_the_elimination_and_the_crx_ones_are_not():
    """Where the general elimination takes a search class's chain (the xArm6's, read from the tool) a search's set
    is certified when the elimination's certified set is the same; the CRX's chain it does not take."""
    xarm, crx = kinelab.load("xarm6"), kinelab.load("crx10ia")
    rng = np.random.default_rng(12)
    for q in xarm.random_qs(8, rng):
        found = kinelab.solve_all(xarm, xarm.fk(q))
        assert found.method == "search" and found.complete == "certified"
    found = kinelab.solve_all(crx, crx.fk(crx.random_q(rng)))
    assert found.complete == "search" and "measured complete" in found.complete_reason


def test_the_elimination_on_the_xarm6_chain_agrees_with_its_1d_search():
    """The xArm6 is a 1-D search class; the elimination takes its chain read from the tool, certified: the two sets
    are equal on every pose where the elimination's is certified."""
    from kinelab.ik.analytic.classify import general_vectors
    from kinelab.ik.analytic.general import roots_within
    from kinelab.ik.chain import chain_model

    xarm = kinelab.load("xarm6")
    v = chain_model(xarm).vectors(np.zeros(6))
    arm = general_vectors(v["e"].copy(), v["o"].copy(), v["R"].copy(), v["N"].copy()).arm
    assert arm is not None and arm.mirrored
    rng = np.random.default_rng(8)
    for _ in range(20):
        q = xarm.random_q(rng)
        searched = kinelab.solve_all(xarm, xarm.fk(q))
        roots, _, _, reason = roots_within(arm, xarm.fk(q).homogeneous, xarm.lower, xarm.upper, None, 1e-6)
        if reason:
            continue
        assert len(roots) == len(searched)
        assert all(min(gap(r, s.q) for s in searched) <= 1e-6 for r in roots)


def test_a_planar_or_special_chain_is_refused_with_its_structure_named():
    from kinelab.ik.analytic.classify import general_vectors

    h = np.tile([0.0, 0.0, 1.0], (6, 1))
    o = np.array([[0.3 * i, 0.0, 0.0] for i in range(6)])
    out = general_vectors(h, o, np.eye(3), np.array([1.9, 0.0, 0.0]))
    assert out.arm is None and "axes 1 and 2 parallel" in out.reason and "degenerates" in out.reason


def test_a_pickled_set_keeps_its_completeness():
    import pickle

    for name in ("general6r", "ur5"):
        robot = kinelab.load(name)
        found = kinelab.solve_all(robot, robot.fk(robot.random_q(np.random.default_rng(2))))
        again = pickle.loads(pickle.dumps(found))
        assert (again.complete, again.complete_reason) == (found.complete, found.complete_reason) == ("certified", "")


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_the_compiled_elimination_finds_the_roots_the_python_one_does(tmp_path, seed):
    """The compiled kernel (eigenvalues only, each root's wrist from the quadratic's null vector) against the
    Python elimination (eigenvectors from QZ): the same roots, to 1e-9 rad, at seeded poses of random arms."""
    from kinelab.core._analytic import general_roots
    from kinelab.ik.analytic.certify import chain_pose
    from kinelab.ik.analytic.general import every_root, packed

    arm = general_class(general_robot(tmp_path, seed)).arm
    g, loop = arm.solver
    data = packed(g, loop)
    rng = np.random.default_rng(seed)
    for q in rng.uniform(-np.pi, np.pi, (25, 6)):
        H = chain_pose(loop.h, loop.o, loop.R0, loop.N0, q)  # the chain as the class solves it
        theirs, ours = every_root(g, loop, H).q, general_roots(data, arm.h, arm.o, arm.R0, arm.N0, H)
        assert len(ours) == len(theirs) and min(gap(row, q) for row in ours) <= FOUND
        assert all(min(gap(row, other) for other in theirs) <= 1e-9 for row in ours)


def test_a_general_arm_s_batch_gives_each_pose_the_set_solve_all_gives():
    robot = kinelab.load("general6r")
    Q = robot.random_qs(60, np.random.default_rng(3))
    batch = kinelab.solve_all_batch(robot, robot.fk_batch(Q))
    assert batch.method == "elimination"
    for b, q in enumerate(Q):
        one = kinelab.solve_all(robot, robot.fk(q))
        k = int(batch.count[b])
        assert k == len(one) and min(gap(row, q) for row in batch.q[b, :k]) <= FOUND
        assert all(min(gap(row, s.q) for s in one) <= 1e-9 for row in batch.q[b, :k])


def test_the_compiled_set_is_certified_only_when_it_is_the_elimination_s_certified_set():
    from kinelab.ik.analytic.branches import certificate_of

    robot = kinelab.load("general6r")
    q = robot.random_q(np.random.default_rng(4))
    found = kinelab.solve_all(robot, robot.fk(q))
    assert found.complete == "certified"
    H, merged, free = robot.fk(q).homogeneous, np.ones(len(found), dtype=np.int64), np.zeros(len(found), dtype=bool)
    assert certificate_of(robot, "elimination", H, found.q, merged, free) == ("certified", "")
    level, why = certificate_of(robot, "elimination", H, found.q[1:], merged[1:], free[1:])
    assert level == "search" and f"{len(found)} branches, this one {len(found) - 1}" in why
