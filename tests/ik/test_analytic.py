"""Every branch in closed form (kinelab.ik.analytic) against two references per arm, as sets, on 1000 poses per
arm including singular and joint-limit ones: the UR arms' closed form of tests/closed_forms.py, and EAIK
(Ostermeier et al., an independent implementation of the subproblems, built here from Pinocchio's own axes
and points, not from kinelab's chain model); for the SO-101 EAIK and FRDM's dense multistart. Every answer is
confirmed by Pinocchio within the limits. Mirrored and re-rooted chains are written as URDF files here."""

import zlib

import numpy as np
import pinocchio as pin
import pytest
from closed_forms import BASE, UR_DH, ur_inverse
from eaik.IK_HP import HPRobot
from helpers import chain_urdf, pinocchio_axes, write_urdf

import kinelab
from kinelab import OptionError, load
from kinelab.ik.analytic.classify import CLASSES, classify
from kinelab.ik.analytic.kernel import SEARCH_6R
from kinelab.ik.chain import chain_model

SAME = 1e-4  # [rad] two answers this close joint by joint (modulo 2π) are one branch (double roots split by rounding)
POSES = 1000


def wrapped(d):
    return np.arctan2(np.sin(d), np.cos(d))


def merged(qs):
    out = []
    for q in qs:
        if all(np.max(np.abs(wrapped(q - o))) > SAME for o in out):
            out.append(np.asarray(q, dtype=float))
    return out


def has_copy_within(robot, q):
    """Some θ + 2πk of every joint lies within its limits (the test's own reading of the limits)."""
    k = np.arange(-3, 4)[:, None] * 2 * np.pi
    return all(((q[j] + k >= robot.lower[j] - 1e-9) & (q[j] + k <= robot.upper[j] + 1e-9)).any()
               for j in range(robot.n))


def confirmed(robot, target, qs, tol=1e-9):
    """The references' answers that Pinocchio confirms and that have a copy within the limits, merged."""
    keep = []
    for q in qs:
        placed = q + 2 * np.pi * np.round((np.clip(q, robot.lower, robot.upper) - q) / (2 * np.pi))
        if has_copy_within(robot, q) and max(robot.tool_error(placed, target)) <= tol:
            keep.append(q)
    return merged(keep)


def same_set(a, b, tol=SAME):
    return all(any(np.max(np.abs(wrapped(x - y))) <= tol for y in b) for x in a) and \
        all(any(np.max(np.abs(wrapped(x - y))) <= tol for x in a) for y in b)


class Eaik:
    """EAIK's solver for a robot, fed Pinocchio's axes; its tool frame at q = 0 is the base's orientation."""

    def __init__(self, robot):
        h, o, M = pinocchio_axes(robot)
        self.R0 = M.rotation
        self.bot = HPRobot(h, np.vstack([o[0], np.diff(o, axis=0), M.translation - o[-1]]))

    def __call__(self, target):
        H = target.homogeneous.copy()
        H[:3, :3] = H[:3, :3] @ self.R0.T
        return list(self.bot.IK(H).Q)  # least-squares answers too: at a double root Pinocchio confirms them


def poses(robot, singular, seed, at=0.0):
    """POSES configurations: 80 % random, 10 % with ``singular`` joints set to ``at`` (a singular pose), 10 %
    with one or two joints at a limit."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(POSES):
        q = robot.random_q(rng)
        if k % 10 == 8:
            q[singular[k // 10 % len(singular)]] = at
        elif k % 10 == 9:
            for j in rng.choice(robot.n, size=1 + k % 2, replace=False):
                q[j] = robot.lower[j] if rng.random() < 0.5 else robot.upper[j]
        out.append(q)
    return out


def continuum(found):
    return any("continuum" in s.message for s in found)


@pytest.mark.parametrize("name", ["ur5", "ur10"])
def test_the_ur_branches_are_the_closed_form_and_eaik_as_sets(name):
    robot = load(name)
    eaik = Eaik(robot)
    agree_closed, agree_eaik, compared = 0, 0, 0
    for q in poses(robot, singular=[[4], [2], [2, 4]], seed=7):
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target, solver="analytic")
        assert found and all(s.success and s.solver == "analytic" for s in found)
        for s in found:  # Pinocchio confirms each, within the limits
            assert robot.within_limits(s.q) and max(robot.tool_error(s.q, target)) <= 1e-6
        assert any(np.max(np.abs(wrapped(s.q - q))) <= 1e-6 for s in found) or continuum(found)
        if continuum(found):  # a wrist at q5 = 0: a circle of answers, not a finite set to compare
            continue
        compared += 1
        ours = [s.q for s in found]
        agree_closed += same_set(ours, confirmed(robot, target, ur_inverse(BASE @ target.homogeneous,
                                                                        *UR_DH[name])))
        agree_eaik += same_set(ours, confirmed(robot, target, eaik(target)))
    print(name, compared, agree_closed, agree_eaik)
    assert compared >= 0.85 * POSES  # the q5 = 0 poses (and q5 at ±2π) are continua
    assert agree_closed >= 0.999 * compared and agree_eaik >= 0.999 * compared


def test_the_spherical_wrist_branches_of_kinova_are_eaik_s_as_sets():
    """The Jaco 2 (j2s6s200): axes 2 ∥ 3, a spherical wrist. Its wrist is singular at q5 = π (axes 4 and 6 in
    line) and its arm stretched at q3 = π; EAIK classifies it the same way (6R-SPHERICAL_SECOND_TWO_PARALLEL)."""
    robot = load("kinova")
    eaik = Eaik(robot)
    assert eaik.bot.getKinematicFamily() == "6R-SPHERICAL_SECOND_TWO_PARALLEL"
    agree, compared = 0, 0
    for q in poses(robot, singular=[[4], [2], [2, 4]], seed=8, at=np.pi):
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target, solver="analytic")
        assert found and all(s.success and "spherical wrist" in s.mode for s in found)
        for s in found:
            assert robot.within_limits(s.q) and max(robot.tool_error(s.q, target)) <= 1e-6
        # at q3 = π the elbow's two roots nearly meet: axes 2 and 3 are 2e-13 rad from parallel in this file,
        # which moves a double root by √(2e-13) ≈ 1e-6 rad; roots within SAME are one branch
        assert any(np.max(np.abs(wrapped(s.q - q))) <= SAME for s in found) or continuum(found)
        if continuum(found):  # q5 = π: q4 and q6 turn about one line, a circle of answers
            continue
        compared += 1
        agree += same_set([s.q for s in found], confirmed(robot, target, eaik(target)))
    assert compared >= 0.85 * POSES and agree >= 0.999 * compared


def test_the_youbot_heading_and_arm_branches_meet_every_pose_and_are_the_dense_multistart_s():
    """The youBot's platform heading and arm (its x and y held): axes 1 ∥ 2, axes 3 ∥ 4 ∥ 5, a class of its own
    (no EAIK class): every answer confirmed by Pinocchio, the configuration the pose came from found, and on
    one pose in fifty the same set as a dense FRDM search (0.5 s without its stopping rule)."""
    youbot = load("youbot")
    turning = load(str(youbot.source), tool=youbot.tool, base=youbot.base,
                   locked={"platform_x": 0.0, "platform_y": 0.0})
    assert classify(turning).arm.name == "6R, axes 1, 2 parallel, axes 3, 4, 5 parallel"
    searched = agree = 0
    for k, q in enumerate(poses(turning, singular=[[3], [4]], seed=12)):
        target = turning.fk(q)
        found = kinelab.solve_all(turning, target, solver="analytic")
        for s in found:
            assert turning.within_limits(s.q) and max(turning.tool_error(s.q, target)) <= 1e-6
        assert any(np.max(np.abs(wrapped(s.q - q))) <= SAME for s in found) or continuum(found)
        if k % 50 == 0:
            searched += 1
            dense = kinelab.solve_all(turning, target, solver="frdm", seed=k, time_budget=0.5, stop_below=None)
            agree += same_set([s.q for s in found], [s.q for s in dense], tol=1e-2)
    assert agree == searched == POSES // 50


def test_the_so101_branches_are_eaik_and_the_dense_multistart_as_sets():
    robot = load("so101")
    eaik = Eaik(robot)
    agree_eaik, agree_search, searched = 0, 0, 0
    for k, q in enumerate(poses(robot, singular=[[2], [3], [1, 2]], seed=8)):
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target, solver="analytic")
        assert all(robot.within_limits(s.q) and max(robot.tool_error(s.q, target)) <= 1e-6 for s in found)
        assert any(np.max(np.abs(wrapped(s.q - q))) <= 1e-6 for s in found)
        ours = [s.q for s in found]
        agree_eaik += same_set(ours, confirmed(robot, target, eaik(target)))
        if k % 50 == 0:  # a dense search (rounds of 64 seeded starts for 0.5 s), one pose in fifty
            searched += 1
            dense = kinelab.solve_all(robot, target, solver="frdm", seed=k, time_budget=0.5, stop_below=None)
            # a search's answers met to 1e-6 m scatter by up to ~1e-2 rad near a double root (test_branches.py)
            agree_search += same_set(ours, [s.q for s in dense], tol=1e-2)
    assert agree_eaik >= 0.999 * POSES
    assert agree_search == searched


def test_arms_are_classified_by_their_axes_and_others_are_refused_by_name(tmp_path):
    assert {n: classify(load(n)).arm is not None for n in ("ur3", "ur5", "ur10", "z1", "so101", "kinova", "panda",
                                                           "stanford")} == \
        {"ur3": True, "ur5": True, "ur10": True, "z1": True, "so101": True, "kinova": True, "panda": False,
         "stanford": False}
    # the kinova with its wrist point moved 3 cm off axis 6 leaves the closed forms for the 1-D search (axes 4 and
    # 5 still meet); moved 2 cm off axis 4 as well, it is in no class
    kinova = load("kinova")
    h, o, M = pinocchio_axes(kinova)
    o = o.copy()
    o[5] += 0.03 * np.cross(h[5], h[4])
    searched = load(write_urdf(tmp_path, chain_urdf(h, o, M, kinova.lower, kinova.upper)), tool="tool")
    assert classify(searched).arm.searched and "1-D search over joint 6" in classify(searched).arm.mode
    o[3] += 0.02 * np.cross(h[3], h[4])
    off = load(write_urdf(tmp_path, chain_urdf(h, o, M, kinova.lower, kinova.upper), "off.urdf"), tool="tool")
    assert classify(off).arm is None and "axes 4, 5 and 6 miss a common point by 0.04 m" in classify(off).reason
    q = off.random_q(0)
    target = off.fk(q)
    found = kinelab.solve_all(off, target, solver="analytic")  # the general 6R elimination takes it, certified
    assert found.method == "elimination" and found.complete == "certified"
    assert min(np.abs(np.arctan2(np.sin(s.q - q), np.cos(s.q - q))).max() for s in found) <= 1e-9
    # six parallel axes (a planar chain: a continuum of answers) is a structure no solver here takes, said by name
    planar = load(write_urdf(tmp_path, chain_urdf(np.tile([0.0, 0.0, 1.0], (6, 1)),
                                                  np.array([[0.3 * i, 0.05 * i, 0.1 * i] for i in range(6)]),
                                                  pin.SE3(np.eye(3), np.array([1.9, 0.3, 0.6])), np.full(6, -3.0),
                                                  np.full(6, 3.0)), "planar.urdf"), tool="tool")
    target = planar.fk(planar.random_q(0))
    with pytest.raises(OptionError, match="is not: .* nor a 1-D search class.*general 6R elimination degenerates "
                                          "on this chain's structure \\(axes 1 and 2 parallel, axes 1 and 3 "
                                          "parallel"):
        kinelab.solve_all(planar, target, solver="analytic")
    auto = kinelab.solve_all(planar, target, seed=0, time_budget=0.2)  # the numeric search instead, saying so
    assert auto and all(s.solver == "frdm" and "multistart" in s.mode for s in auto)
    assert auto.complete == "estimate"
    ur5 = load("ur5")
    with pytest.raises(OptionError, match="task"):
        kinelab.solve_all(ur5, ur5.fk(ur5.random_q(0)), solver="analytic", task="position")
    with pytest.raises(OptionError, match="options"):
        kinelab.solve_all(ur5, ur5.fk(ur5.random_q(0)), solver="analytic", relax=1.2)


def test_a_mirrored_ur5_read_from_its_tool_classifies_and_solves_the_inverse_pose(tmp_path):
    """The UR5 written tool first: its base is the UR5's tool, joint k is the UR5's joint 7 − k turning the other
    way (q'_k = −q_{7−k}), so its FK at q' is the UR5's at q inverted."""
    ur5 = load("ur5")
    h, o, M = pinocchio_axes(ur5)
    R0, N0 = M.rotation, M.translation
    mirror_file = write_urdf(tmp_path, chain_urdf((h[::-1] @ R0), (o[::-1] - N0) @ R0, M.inverse(),
                                                  -ur5.upper[::-1], -ur5.lower[::-1]))
    mirror = load(mirror_file, tool="tool")
    arm = classify(mirror).arm
    assert arm is not None and arm.mirrored
    rng = np.random.default_rng(5)
    for _ in range(200):
        q = ur5.random_q(rng)
        target = mirror.fk(-q[::-1])
        assert target.isApprox(ur5.fk(q).inverse(), 1e-9)  # the file is the mirror image
        found = kinelab.solve_all(mirror, target, solver="analytic")
        assert all(max(mirror.tool_error(s.q, target)) <= 1e-6 for s in found)
        closed = confirmed(ur5, ur5.fk(q), ur_inverse(BASE @ ur5.fk(q).homogeneous, *UR_DH["ur5"]))
        assert same_set([-s.q[::-1] for s in found], closed)


def test_a_mirrored_kinova_a_spherical_shoulder_classifies_and_solves_the_inverse_pose(tmp_path):
    """The kinova written tool first (axes 1, 2, 3 meeting, 4 ∥ 5): the spherical-wrist class, mirrored."""
    kinova = load("kinova")
    h, o, M = pinocchio_axes(kinova)
    R0, N0 = M.rotation, M.translation
    mirror = load(write_urdf(tmp_path, chain_urdf((h[::-1] @ R0), (o[::-1] - N0) @ R0, M.inverse(),
                                                  -kinova.upper[::-1], -kinova.lower[::-1])), tool="tool")
    arm = classify(mirror).arm
    assert arm is not None and arm.mirrored and "spherical wrist" in arm.name
    eaik = Eaik(kinova)
    rng = np.random.default_rng(9)
    for _ in range(200):
        q = kinova.random_q(rng)
        target = mirror.fk(-q[::-1])
        found = kinelab.solve_all(mirror, target, solver="analytic")
        assert all(max(mirror.tool_error(s.q, target)) <= 1e-6 for s in found)
        assert same_set([-s.q[::-1] for s in found], confirmed(kinova, kinova.fk(q), eaik(kinova.fk(q))))


def test_a_chain_re_rooted_at_a_tilted_mount_keeps_its_class_and_its_branches(tmp_path):
    ur5 = load("ur5")
    h, o, M = pinocchio_axes(ur5)
    mount = ((0.4, -0.1, 0.8), (0.3, -0.2, 0.5))
    path = write_urdf(tmp_path, chain_urdf(h, o, M, ur5.lower, ur5.upper, mount=mount))
    on_mount, on_world = load(path, tool="tool", base="base"), load(path, tool="tool", base="world")
    wMb = pin.SE3(pin.rpy.rpyToMatrix(*mount[1]), np.array(mount[0]))
    assert classify(on_world).arm is not None and not classify(on_world).arm.mirrored
    rng = np.random.default_rng(6)
    for _ in range(200):
        q = ur5.random_q(rng)
        assert on_mount.fk(q).isApprox(ur5.fk(q), 1e-9)
        target = on_world.fk(q)
        in_world = kinelab.solve_all(on_world, target, solver="analytic")
        in_base = kinelab.solve_all(on_mount, wMb.inverse() * target, solver="analytic")
        assert all(max(on_world.tool_error(s.q, target)) <= 1e-6 for s in in_world)
        assert same_set([s.q for s in in_world], [s.q for s in in_base])
        assert same_set([s.q for s in in_base], confirmed(ur5, ur5.fk(q), ur_inverse(BASE @ ur5.fk(q).homogeneous,
                                                                                    *UR_DH["ur5"])))


def test_a_double_root_is_one_branch_and_a_reference_picks_the_copies():
    robot = load("ur5")
    q = np.array([0.3, -1.0, 0.0, 0.4, 0.9, -0.2])  # the elbow stretched straight: θ3's two roots coincide
    found = kinelab.solve_all(robot, robot.fk(q), solver="analytic")
    straight = [s for s in found if abs(wrapped(s.q[2])) < 1e-6]
    assert len(straight) == 1 and straight[0].diagnostics.found == 2  # two roots, one answer
    assert all(s.diagnostics.branches == len(found) for s in found)
    ref = q + np.array([-2 * np.pi, 0, 0, -2 * np.pi, 0, 2 * np.pi])  # the same pose, other copies in limits
    near = kinelab.solve_all(robot, robot.fk(q), solver="analytic", q_ref=ref)
    assert np.allclose(near[0].q, ref, atol=1e-9)


def test_the_batch_gives_each_pose_the_branches_of_a_single_call_and_drops_what_pinocchio_refuses():
    from kinelab.ik.analytic.batch import all_branches_batch

    robot = load("ur10")
    rng = np.random.default_rng(9)
    Q = np.array([robot.random_q(rng) for _ in range(300)])
    H = robot.fk_batch(Q)
    H[7, 0, 3] += 5.0  # beyond reach: no branch
    batch = all_branches_batch(robot, H)
    assert batch.count[7] == 0 and np.isnan(batch.q[7]).all()
    for b in range(0, 300, 7):
        single = kinelab.solve_all(robot, pin.SE3(H[b]), solver="analytic")
        assert batch.count[b] == len(single)
        assert same_set(list(batch.q[b, :batch.count[b]]), [s.q for s in single], tol=1e-12)
        assert np.isnan(batch.q[b, batch.count[b]:]).all()
    for b, r in zip(*np.nonzero(~np.isnan(batch.q[:, :, 0])), strict=True):
        assert robot.within_limits(batch.q[b, r]) and max(robot.tool_error(batch.q[b, r], pin.SE3(H[b]))) <= 1e-6


def tilted(h, angle):
    """The axes with axis 3 turned by ``angle`` [rad] about axis 2 × axis 3's normal (out of parallel)."""
    out = h.copy()
    normal = np.cross(h[2], [0.3, 0.5, 0.8])
    out[2] = pin.exp3(normal / np.linalg.norm(normal) * angle) @ h[2]
    return out


def _closed_form_misses(robot):
    """The closed-form tests the robot's chain fails, in words (the search classes left out)."""
    v = chain_model(robot).vectors(np.zeros(6))
    return " / ".join(test(v["e"], v["o"]) for kind, _, test in CLASSES[6] if kind < SEARCH_6R)


def test_near_parallel_axes_are_classified_by_the_stated_tolerance_and_never_answered_wrongly(tmp_path):
    ur5 = load("ur5")
    h, o, M = pinocchio_axes(ur5)
    off = load(write_urdf(tmp_path, chain_urdf(tilted(h, 1e-3), o, M, ur5.lower, ur5.upper), "off.urdf"), tool="tool")
    # 1e-3 rad out of parallel is out of the closed form, named; axes 1, 2 and 4, 5 still meet: the 1-D search
    assert r"axes 2 and 3 are 0.001 rad from parallel (tolerance 1e-05)" in _closed_form_misses(off)
    assert classify(off).arm.searched
    q = off.random_q(0)
    target = off.fk(q)
    found = kinelab.solve_all(off, target)
    assert all(s.solver == "analytic" and max(off.tool_error(s.q, target)) <= 1e-6 for s in found)
    assert any(np.max(np.abs(wrapped(s.q - q))) <= 1e-9 for s in found)
    near = load(write_urdf(tmp_path, chain_urdf(tilted(h, 9e-6), o, M, ur5.lower, ur5.upper), "near.urdf"),
                tool="tool")
    assert classify(near).arm is not None  # within the tolerance: the closed form, its answers finished
    rng = np.random.default_rng(10)
    finished = 0
    for _ in range(50):
        q = near.random_q(rng)
        target = near.fk(q)
        found = kinelab.solve_all(near, target, solver="analytic")
        assert all(max(near.tool_error(s.q, target)) <= 1e-6 and near.within_limits(s.q) for s in found)
        # the pose's own branch, to 1e-3 rad: near a singular wrist a 9e-6 rad misfit moves an answer that far
        assert any(np.max(np.abs(wrapped(s.q - q))) <= 1e-3 for s in found)
        finished += sum(s.diagnostics.polished == 1 for s in found)
    assert finished > 0  # 9e-6 rad off parallel leaves some answers short of 1e-6 rad: they needed the finish


def test_solve_with_the_closed_form_returns_the_branch_nearest_the_start():
    from kinelab.collision import Collisions, Environment, Obstacle, collision_model

    ur10 = load("ur10")
    rng = np.random.default_rng(16)
    scene = Environment((Obstacle("plane", name="floor"),))
    floor = collision_model(ur10, Collisions(environment=scene))
    for _ in range(30):
        q = ur10.random_q(rng)
        start = np.clip(q + rng.normal(0.0, 0.3, 6), ur10.lower, ur10.upper)
        target = ur10.fk(q)
        res = kinelab.solve(ur10, target, solver="analytic", q0=start)
        every = kinelab.solve_all(ur10, target, solver="analytic", q_ref=start)
        assert res.success and res.solver == "analytic" and np.allclose(res.q, every[0].q)
        assert max(ur10.tool_error(res.q, target)) <= 1e-6 and res.diagnostics.branches == len(every)
        clear = kinelab.solve(ur10, target, solver="analytic", q0=start, collisions=scene)
        marked = kinelab.solve_all(ur10, target, solver="analytic", q_ref=start, collisions=scene)
        first_clear = next((b for b in marked if b.success), None)
        if first_clear is None:
            assert clear.status == kinelab.Status.COLLISION and clear.diagnostics.contact is not None
        else:
            assert clear.success and np.allclose(clear.q, first_clear.q)
            assert floor.contact(clear.q, first_test=False) is None
    far = kinelab.target_from_xyz_rpy([3.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    beyond = kinelab.solve(ur10, far, solver="analytic")
    assert not beyond.success and beyond.status == kinelab.Status.UNREACHABLE and "beyond" in beyond.message
    with pytest.raises(OptionError, match="xarm7: holding joint7, the six's compiled roots fell short"):
        kinelab.solve(load("xarm7"), far, solver="analytic")  # the Panda's six hold exactly (tests/ik/test_held.py)
    with pytest.raises(OptionError, match="the closed form has no settings"):
        kinelab.solve(ur10, far, solver="analytic", relax=1.3)


def test_the_prepared_closed_form_gives_what_the_plain_calls_give():
    ur5 = load("ur5")
    ik = kinelab.IK(ur5, solver="analytic")
    rng = np.random.default_rng(18)
    Q = np.array([ur5.random_q(rng) for _ in range(12)])
    starts = np.clip(Q + rng.normal(0.0, 0.2, Q.shape), ur5.lower, ur5.upper)
    H = ur5.fk_batch(Q)
    batch = ik.solve_batch(H, q0=starts)
    plain_batch = kinelab.solve_batch(ur5, H, solver="analytic", q0=starts)
    assert np.array_equal(plain_batch.q, batch.q) and plain_batch.solver == "analytic"
    for b in range(len(Q)):
        target = pin.SE3(H[b])  # the batch's own target (fk and fk_batch agree to 1e-16, not to the bit)
        one = ik.solve(target, q0=starts[b])
        plain = kinelab.solve(ur5, target, solver="analytic", q0=starts[b])
        assert one.success and np.array_equal(one.q, plain.q) and np.array_equal(batch.q[b], one.q)
        assert [s.q.tolist() for s in ik.solve_all(target)] == \
            [s.q.tolist() for s in kinelab.solve_all(ur5, target, solver="analytic")]
    assert batch.success.all() and batch.solver == "analytic"
    with pytest.raises(OptionError, match="xarm7: holding joint7"):
        kinelab.IK(load("xarm7"), solver="analytic")
    with pytest.raises(OptionError, match="youbot's is not"):
        kinelab.IK(load("youbot"), solver="analytic")
    with pytest.raises(OptionError, match="none with solver='analytic'"):
        kinelab.IK(ur5, solver="analytic", relax=1.2)


def _unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_arm(kind, rng):
    """Axes h (n, 3) and points o (n, 3) of a random chain of the class ``kind``, in general position otherwise
    (axes at random angles, not only at right angles; link lengths 0.1–0.5 m)."""
    h = np.array([_unit(rng) for _ in range(6)])
    o = rng.uniform(-0.5, 0.5, size=(6, 3))
    if kind in ("parallel 6R", "parallel 5R"):
        h[2], h[3] = h[1], -h[1]  # the parallel triple, one of them reversed
        if kind == "parallel 6R":
            meet = rng.uniform(-0.5, 0.5, 3)
            o[4], o[5] = meet + 0.2 * h[4], meet - 0.1 * h[5]
        return (h[:5], o[:5]) if kind == "parallel 5R" else (h, o)
    if kind in ("spherical wrist", "meeting"):
        w = rng.uniform(-0.5, 0.5, 3)
        o[3], o[4], o[5] = w + 0.3 * h[3], w - 0.2 * h[4], w + 0.1 * h[5]
        if kind == "spherical wrist":
            h[2] = -h[1]
        else:
            s = rng.uniform(-0.5, 0.5, 3)
            o[0], o[1] = s + 0.2 * h[0], s - 0.1 * h[1]
        return h, o
    h[1], h[3], h[4] = -h[0], h[2], -h[2]  # "two three": 1 ∥ 2, 3 ∥ 4 ∥ 5
    return h, o


@pytest.mark.parametrize("kind, name", [("parallel 6R", "6R, axes 2, 3, 4 parallel, axes 5 and 6 meeting"),
                                        ("parallel 5R", "5R, axes 2, 3, 4 parallel"),
                                        ("spherical wrist", "6R, axes 2, 3 parallel, axes 4, 5, 6 meeting"),
                                        ("meeting", "6R, axes 1, 2 meeting, axes 4, 5, 6 meeting"),
                                        ("two three", "6R, axes 1, 2 parallel, axes 3, 4, 5 parallel")])
def test_random_arms_of_each_class_find_the_configuration_each_pose_came_from(tmp_path, kind, name):
    """Arms generated here, ten per class, their axes at random angles (the registered arms have right angles
    only): each classifies, every answer meets its pose (Pinocchio) and the configuration the pose came from is
    among them (to SAME, or the pose is singular and its answer flagged one of a continuum), on 30 poses each."""
    rng = np.random.default_rng(zlib.crc32(kind.encode()))
    found_all = 0
    for k in range(10):
        h, o = random_arm(kind, rng)
        n = h.shape[0]
        tool = pin.SE3(pin.exp3(rng.normal(size=3)), o[-1] + rng.uniform(-0.3, 0.3, 3))
        path = write_urdf(tmp_path, chain_urdf(h, o, tool, -np.pi * np.ones(n), np.pi * np.ones(n)), f"a{k}.urdf")
        arm = load(path, tool="tool")
        assert classify(arm).arm is not None and classify(arm).arm.name.startswith(name), classify(arm).reason
        for _ in range(30):
            q = arm.random_q(rng)
            target = arm.fk(q)
            answers = kinelab.solve_all(arm, target, solver="analytic")
            assert all(max(arm.tool_error(s.q, target)) <= 1e-6 and arm.within_limits(s.q) for s in answers)
            hit = any(np.max(np.abs(wrapped(s.q - q))) <= SAME for s in answers)
            assert hit or continuum(answers) or (n == 5 and answers), (k, q)
            found_all += hit
    assert found_all >= 0.99 * 300


@pytest.mark.parametrize("name", ["ur5", "kinova", "so101", "crx10ia"])
def test_the_compiled_closed_form_gives_the_root_by_root_answers(name):
    """Every branch judged in one compiled pass equals the route that judges root by root with Pinocchio's FK: the
    same rows in the same order, the errors Pinocchio's to 1e-12, on seeded poses (crx10ia: the 1-D search)."""
    from kinelab.ik.analytic.branches import Rows, arm_of, judged_roots, limit_slack, roots
    from kinelab.ik.request import make_request

    robot = load(name)
    req = make_request("frdm")
    arm = arm_of(robot, req)
    rng = np.random.default_rng(23)
    for _ in range(30):
        target = robot.fk(robot.random_q(rng))
        found = kinelab.solve_all(robot, target)
        q, merged, free = roots(robot, arm, target.homogeneous, None, limit_slack(req.tol_rot))
        general = Rows.of(judged_roots(robot, q, merged, free, target, req), robot.n)
        np.testing.assert_array_equal(found.q, general.q)
        assert found.method == ("search" if arm.searched else "closed form") and found.status.value == "converged"
        for k, res in enumerate(found):
            dp, dr = robot.tool_error(res.q, target)  # Pinocchio's FK
            assert abs(res.position_error - dp) <= 1e-12 and abs(res.rotation_error - dr) <= 1e-12
            assert found.position_error[k] == res.position_error and res.diagnostics.found == general.merged[k]
            assert res.judge == "compiled FK (certified)" and res.diagnostics.branches == len(found)


def test_a_set_of_branches_is_arrays_and_builds_its_results_only_when_read(monkeypatch):
    import pickle

    from kinelab.ik.analytic import branches
    from kinelab.ik.result import IKResult

    robot = load("ur5")
    target = robot.fk(robot.random_q(5))
    built = []
    real_init, real_filled = IKResult.__init__, branches.filled  # the general route's results and the one call's
    monkeypatch.setattr(IKResult, "__init__", lambda self, *a, **k: built.append(1) or real_init(self, *a, **k))
    monkeypatch.setattr(branches, "filled", lambda *a, **k: built.append(1) or real_filled(*a, **k))
    found = kinelab.solve_all(robot, target)
    assert built == [] and found.q.shape == (len(found), 6) and len(found) >= 2
    assert found.rotation_error.shape == (len(found),) and np.all(found.position_error <= 1e-6)
    np.testing.assert_array_equal(found[1].q, found.q[1])
    assert len(built) == len(found)  # every result made at the first read, then kept
    assert [r.q.tolist() for r in found] == found.q.tolist() and len(built) == len(found)
    again = pickle.loads(pickle.dumps(kinelab.solve_all(robot, target)))
    np.testing.assert_array_equal(again.q, found.q)
    assert again[0].diagnostics == found[0].diagnostics
    far = kinelab.solve_all(robot, pin.SE3(np.eye(3), np.array([9.0, 0.0, 0.0])))
    assert far == [] and not far and far.status.value == "unreachable" and far.q.shape[0] == 0


@pytest.mark.parametrize("name", ["ur10", "kinova", "crx10ia"])
def test_the_every_branch_batch_gives_each_target_what_solve_all_gives(name):
    """kinelab.solve_all_batch: row b is solve_all(targets[b]) (rows, order, errors), on all cores; a target beyond
    reach has count 0; a chain without a closed form is refused by name."""
    robot = load(name)
    rng = np.random.default_rng(31)
    targets = [robot.fk(robot.random_q(rng)) for _ in range(60)]
    targets.append(pin.SE3(np.eye(3), np.array([9.0, 0.0, 0.0])))
    batch = kinelab.solve_all_batch(robot, targets)
    assert batch.q.shape == (61, 16, robot.n) and batch.count[-1] == 0 and (batch.count[:-1] >= 1).all()
    for b, target in enumerate(targets):
        one, k = kinelab.solve_all(robot, target), int(batch.count[b])
        assert k == len(one)
        np.testing.assert_array_equal(batch.q[b, :k], one.q)
        np.testing.assert_array_equal(batch.position_error[b, :k], one.position_error)
        assert np.isnan(batch.q[b, k:]).all() and np.isnan(batch.rotation_error[b, k:]).all()
        for row in batch.q[b, :k]:
            dp, dr = robot.tool_error(row, target)  # Pinocchio's FK
            assert dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(row)
    assert batch.method == ("search" if name == "crx10ia" else "closed form")
    with pytest.raises(kinelab.OptionError, match="analytic class"):
        kinelab.solve_all_batch(load("panda"), targets[:2])


@pytest.mark.parametrize("name", ["ur5", "kinova", "so101", "crx10ia"])
def test_the_nearest_branch_in_one_compiled_call_is_the_general_route_s(name):
    """``solve(solver="analytic")``'s usual call (NearestBranch: every branch found and judged in one compiled call,
    the nearest kept) answers what the general route answers root by root with Pinocchio's FK: the same q, status and
    roots merged, the errors Pinocchio's to 1e-12, with a start near the pose, a random start and none."""
    from kinelab.ik.analytic.nearest import analytic_one
    from kinelab.ik.request import make_request

    robot = load(name)
    ik = kinelab.IK(robot, solver="analytic")
    req = make_request("frdm")
    rng = np.random.default_rng(31)
    one_call = 0
    for k in range(30):
        q = robot.random_q(rng)
        target = robot.fk(q)
        q0 = [np.clip(q + rng.normal(0, 0.3, robot.n), robot.lower, robot.upper), robot.random_q(rng), None][k % 3]
        fast = ik.solve(target, q0=q0)
        general = analytic_one(robot, target, req, q0)
        np.testing.assert_array_equal(fast.q, general.q)
        assert fast.status == general.status and fast.success and fast.message == general.message
        assert fast.diagnostics.found == general.diagnostics.found
        dp, dr = robot.tool_error(fast.q, target)
        assert abs(fast.position_error - dp) <= 1e-12 and abs(fast.rotation_error - dr) <= 1e-12
        if fast.judge == "compiled FK (certified)":  # the one call (else a root to finish: the general route)
            one_call += 1
            # the pose's branches within the limits, as solve_all counts them (the root-by-root route also counts a
            # 5R arm's candidates that are no root of the pose)
            assert fast.diagnostics.branches == len(kinelab.solve_all(robot, target)) <= general.diagnostics.branches
    assert one_call >= 25


@pytest.mark.parametrize("name", ["ur5", "crx10ia", "general6r", "kinova"])
def test_the_compiled_nearest_batch_is_each_single_closed_form_solve(name):
    """solve_batch(solver="analytic") answers its rows in one compiled call: each row is what the single call gives
    its pose and start, on any thread count; a row with no branch (beyond reach) is the single call's failure."""
    from kinelab.core import threads

    robot = load(name)
    rng = np.random.default_rng(31)
    Q = robot.random_qs(60, rng)
    H = robot.fk_batch(Q)
    H[7, :3, 3] = [9.0, 0.0, 0.0]  # beyond reach
    starts = np.clip(Q + rng.normal(0.0, 0.3, Q.shape), robot.lower, robot.upper)
    for q0 in (starts, None):
        batch = kinelab.solve_batch(robot, H, solver="analytic", q0=q0)
        try:
            threads.set_count(1)
            single_thread = kinelab.solve_batch(robot, H, solver="analytic", q0=q0)
        finally:
            threads.set_count(None)
        assert np.array_equal(batch.q, single_thread.q, equal_nan=True)
        for b in range(60):
            one = kinelab.solve(robot, pin.SE3(H[b]), solver="analytic", q0=None if q0 is None else q0[b])
            assert batch.success[b] == one.success and batch.status[b] == one.status.value
            if one.success:
                assert np.array_equal(batch.q[b], one.q)
                assert batch.position_error[b] == one.position_error and batch.rotation_error[b] == one.rotation_error
        assert not batch.success[7] and batch.success.sum() == 59
