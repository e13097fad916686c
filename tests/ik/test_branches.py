"""solve_all against the UR arms' closed-form inverse (up to 8 solutions, tests/closed_forms.py: wrist centre →
θ1, θ5, θ6, then the planar 2R for θ2, θ3 and θ4), itself checked by Pinocchio's FK."""

import numpy as np
import pytest
from closed_forms import BASE, UR_DH, ur_inverse

import kinelab
from kinelab import OptionError, load
from kinelab.ik.branches import distance


@pytest.mark.parametrize("name", ["ur5", "ur10"])
def test_the_multistart_finds_every_closed_form_solution_and_no_other(name):
    robot = load(name)
    rng = np.random.default_rng(1)
    complete = 0
    for k in range(40):
        target = robot.fk(robot.random_q(rng))
        analytic = [q for q in ur_inverse(BASE @ target.homogeneous, *UR_DH[name]) if robot.within_limits(q)]
        for q in analytic:  # the oracle is itself exact
            dp, dr = robot.tool_error(q, target)
            assert dp < 1e-9 and dr < 1e-9
        found = kinelab.solve_all(robot, target, solver="frdm", seed=k, time_budget=None)  # the stop rule ends it
        for sol in found:  # every answer is a closed-form solution, and checked by Pinocchio
            assert min(distance(robot, sol.q, q) for q in analytic) < 1e-2  # ill-conditioned near a singularity
            assert robot.tool_error(sol.q, target)[0] <= 1e-6
        complete += all(min(distance(robot, s.q, q) for s in found) < 1e-2 for q in analytic)
    assert complete >= 39  # measured: 198 of 200 targets complete (within 50 ms when the machine is quiet)


def test_solutions_sort_by_distance_to_a_reference_and_bad_arguments_are_named():
    robot = load("ur5")
    q_ref = robot.random_q(4)
    found = kinelab.solve_all(robot, robot.fk(q_ref), solver="frdm", seed=0, time_budget=None, q_ref=q_ref)
    distances = [distance(robot, s.q, q_ref) for s in found]
    assert distances == sorted(distances) and distances[0] < 1e-3  # the reference's own branch comes first
    with pytest.raises(OptionError, match="max_solutions"):
        kinelab.solve_all(robot, robot.fk(q_ref), max_solutions=0)
    with pytest.raises(kinelab.ConfigurationError, match="q_ref"):
        kinelab.solve_all(robot, robot.fk(q_ref), q_ref=[0.0, 1.0])
    assert len(kinelab.solve_all(robot, robot.fk(q_ref), seed=0, max_solutions=2)) == 2


def stanford_inverse(T):
    """Every solution of kinelab's Stanford arm (urdf/stanford.urdf) for the tool pose T, from its geometry:
    the tool point is the wrist centre p = Rz(θ1)·(s + Rx(θ2)·(0, d3, 0)) with s = (0.121, 0, 0.324), so θ1
    puts p's x in the turned frame at the shoulder offset (two roots), d3 = |(y, z − 0.324)| (the other sign
    is outside d3's limits) and θ2 its elevation; the wrist is Ry(θ4)·Rz(θ5)·Ry(θ6) (two roots, ±θ5)."""
    from scipy.spatial.transform import Rotation

    s_x, s_z = 0.121, 0.324
    tool = Rotation.from_euler("xyz", [np.pi / 2, 0, np.pi]).as_matrix()  # link6 → tool, from the URDF
    p, R = T.translation, T.rotation
    r, phi = np.hypot(p[0], p[1]), np.arctan2(p[1], p[0])
    out = []
    if r < s_x:
        return out
    for s1 in (1, -1):
        t1 = phi + s1 * np.arccos(s_x / r)
        c1, n1 = np.cos(t1), np.sin(t1)
        y, z = -p[0] * n1 + p[1] * c1, p[2] - s_z
        d3, t2 = np.hypot(y, z), np.arctan2(z, y)
        arm = Rotation.from_euler("ZX", [t1, t2]).as_matrix()
        W = arm.T @ R @ tool.T  # = Ry(θ4)·Rz(θ5)·Ry(θ6)
        for s5 in (1, -1):
            t5 = s5 * np.arccos(np.clip(W[1, 1], -1, 1))
            sb = np.sin(t5)
            t4 = np.arctan2(W[2, 1] / sb, -W[0, 1] / sb)
            t6 = np.arctan2(W[1, 2] / sb, W[1, 0] / sb)
            q = np.array([t1, t2, d3, t4, t5, t6])
            q[[0, 1, 3, 4, 5]] = np.arctan2(np.sin(q[[0, 1, 3, 4, 5]]), np.cos(q[[0, 1, 3, 4, 5]]))
            out.append(q)
    return out


def test_solve_all_finds_every_closed_form_solution_of_the_stanford_arm():
    robot = load("stanford")
    rng = np.random.default_rng(2)
    complete, counts = 0, []
    for k in range(40):
        target = robot.fk(robot.random_q(rng))
        analytic = [q for q in stanford_inverse(target) if robot.within_limits(q)]
        assert analytic  # the target's own q is one of them
        for q in analytic:  # the oracle is itself exact
            dp, dr = robot.tool_error(q, target)
            assert dp < 1e-9 and dr < 1e-9
        found = kinelab.solve_all(robot, target, solver="frdm", seed=k, time_budget=None)  # the stop rule ends it
        for sol in found:
            assert min(distance(robot, sol.q, q) for q in analytic) < 1e-2
        complete += all(min(distance(robot, s.q, q) for s in found) < 1e-2 for q in analytic)
        counts.append(len(analytic))
    assert complete >= 39 and max(counts) == 4  # measured: 200 of 200 complete (quiet: within 50 ms, median 3.8 ms)


def test_solve_with_prefer_returns_the_branch_nearest_the_reference():
    robot = load("ur5")
    rng = np.random.default_rng(5)
    for k in range(5):
        q_ref = robot.random_q(rng)
        target = robot.fk(q_ref)
        analytic = [q for q in ur_inverse(BASE @ target.homogeneous, *UR_DH["ur5"]) if robot.within_limits(q)]
        nearest = min(analytic, key=lambda q: distance(robot, q, q_ref + 0.05))
        res = kinelab.solve(robot, target, seed=k, time_budget=None, prefer=q_ref + 0.05)
        assert res.success and robot.tool_error(res.q, target)[0] <= 1e-6
        assert distance(robot, res.q, nearest) < 1e-2 and res.diagnostics.branches >= 2
    beyond = kinelab.target_from_xyz_rpy([5.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    res = kinelab.solve(robot, beyond, seed=0, time_budget=0.02, prefer=q_ref)
    assert not res.success and res.status is kinelab.Status.UNREACHABLE


def test_the_good_turing_estimate_counts_the_branches_reached_once():
    from kinelab.ik.branches import unseen

    assert unseen([]) == 1.0  # nothing found yet: a start may find anything
    assert unseen([5, 5, 5]) == pytest.approx(1 / 15)  # none reached once: (0 + 1) / 15
    assert unseen([1, 3]) == pytest.approx(2 / 4)  # one branch reached once


def test_the_search_stops_by_its_rule_with_every_closed_form_branch():
    """kinelab 0.2 spent the whole budget on every target; with a generous budget the rule stops the search
    once another start is unlikely to add a branch, and the branches are still all the closed form's."""
    ur5 = load("ur5")
    rng = np.random.default_rng(4)
    complete = stopped = 0
    for k in range(20):
        target = ur5.fk(ur5.random_q(rng))
        analytic = [q for q in ur_inverse(BASE @ target.homogeneous, *UR_DH["ur5"]) if ur5.within_limits(q)]
        found = kinelab.solve_all(ur5, target, solver="frdm", seed=k, time_budget=60.0)  # the rule ends it first
        d = found[0].diagnostics
        stopped += d.unseen < 0.01
        complete += all(min(distance(ur5, s.q, q) for s in found) < 1e-2 for q in analytic)
    assert stopped == 20 and complete >= 19
    with pytest.raises(OptionError, match="stop_below"):
        kinelab.solve_all(ur5, target, stop_below=1.5)


def test_no_budget_pays_for_the_first_calls_preparation(monkeypatch):
    """#39 item 5: the first solve_all of a robot once spent its 50 ms certifying the judge and returned [] — read as
    "unreachable". Here the certificate is made to take 0.3 s: the search must still get its whole budget."""
    import time

    from kinelab.robot import chain as model  # the chain view certifies its FK (#58: robot.model split)

    real = model.certify

    def slow_certify(robot):
        time.sleep(0.3)
        return real(robot)

    monkeypatch.setattr(model, "certify", slow_certify)
    robot = load("tiago_pro")  # a fresh Robot: nothing prepared yet; the multistart serves it
    target = robot.fk(robot.random_q(np.random.default_rng(7)))
    found = kinelab.solve_all(robot, target, seed=0, time_budget=0.05)
    assert found and found.status == kinelab.Status.CONVERGED and found.message == ""
    assert all(r.success and robot.tool_error(r.q, target)[0] <= 1e-6 for r in found)


def test_an_empty_set_of_branches_says_why():
    """#39 item 5: an empty answer carries its status; "unreachable" only where something proved it."""
    ur5, tiago = load("ur5"), load("tiago_pro")
    far = kinelab.target_from_xyz_rpy([3.0, 0.0, 0.5], [0.0, 0.0, 0.0])
    by_search = kinelab.solve_all(ur5, far, solver="frdm", seed=0)  # proved by the reach bound
    assert by_search == [] and by_search.status == kinelab.Status.UNREACHABLE and "beyond" in by_search.message
    closed = kinelab.solve_all(ur5, far, seed=0)  # the closed form computes every branch: none is a proof
    assert closed == [] and closed.status == kinelab.Status.UNREACHABLE and "beyond" in closed.message
    limited = kinelab.solve_all(ur5, ur5.fk(np.array([0.3, -1.2, 1.0, -0.5, 0.8, 0.2])), seed=0, tol_pos=1e-12)
    assert len(limited) == 8 and limited.status == kinelab.Status.CONVERGED
    reachable = tiago.fk(tiago.random_q(np.random.default_rng(3)))
    starved = kinelab.solve_all(tiago, reachable, seed=0, time_budget=1e-4)  # no round fits: nothing was proved
    assert starved == [] and starved.status == kinelab.Status.TIME_BUDGET and "nothing proves" in starved.message
    found = kinelab.solve_all(tiago, reachable, seed=0)
    assert found and found.status == kinelab.Status.CONVERGED


def test_merging_counts_an_answer_towards_the_first_equal_branch_and_agrees_with_the_distance():
    """The merge compares an answer with every branch found in one pass (#71: one by one it took ten times the
    search on a 7R arm): the same first match as the branch-by-branch loop, revolute joints modulo 2π."""
    from kinelab.ik import branches
    from kinelab.ik.limits import distance, distances

    panda = kinelab.load("panda", prepare=False)
    rng = np.random.default_rng(9)
    refs = panda.random_qs(40, rng)
    q = refs[17] + 2 * np.pi * np.array([1, 0, -1, 0, 0, 0, 1]) + 4e-4  # branch 17 turned by whole turns, nudged
    np.testing.assert_array_equal(distances(panda, q, refs), [distance(panda, q, r) for r in refs])
    found = [(r, 0.0, 0.0, 1) for r in refs]
    found.insert(30, (refs[17] + 2e-4, 0.0, 0.0, 1))  # a later branch as near: the first one counts the answer
    branches._merge(panda, found, q, 1e-7, 1e-7)
    assert len(found) == 41 and found[17][3] == 2 and found[30][3] == 1
    branches._merge(panda, found, refs[3] + 0.01, 1e-7, 1e-7)  # 0.01 rad from every branch: a new one
    assert len(found) == 42 and found[-1][3] == 1
