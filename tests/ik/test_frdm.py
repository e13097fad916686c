"""FRDM: the vector model, the exact steps (against Pinocchio FK on dense grids), monotonicity, limits,
the monitor and the kick branches, and solutions re-checked by Pinocchio."""

import functools
import warnings

import numpy as np
import pinocchio as pin
import pytest
from helpers import revolute, write_urdf

import kinelab
from kinelab.ik import solve
from kinelab.ik.chain import PRISMATIC
from kinelab.ik.chain import chain_model as vector_model
from kinelab.ik.frdm import kernel, reference
from kinelab.ik.multistart import seed_state

ROBOTS = ("stanford", "era", "youbot", "panda", "ur5", "kinova")


def tool_objective(robot, q, oMtarget, w_p):
    """E through Pinocchio's FK (the oracle)."""
    oMtool = robot.fk(q)
    return reference.objective(oMtool.translation, oMtool.rotation, oMtarget.translation, oMtarget.rotation,
                               w_p, np.ones(3))


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_vector_model_matches_pinocchio(robots, name):
    robot = robots.get(name) or kinelab.load(name)
    vm = vector_model(robot)
    for q in robot.random_qs(20, 3):
        mine, ref = vm.vectors(q), reference.vector_model(robot, q)
        oMtool = robot.fk(q)
        np.testing.assert_allclose(mine["e"], ref["e"], atol=1e-12)
        np.testing.assert_allclose(mine["N"], oMtool.translation, atol=1e-12)
        np.testing.assert_allclose(mine["R"], oMtool.rotation, atol=1e-12)
        revolute_rows = vm.kind != PRISMATIC
        # the two points lie on the same axis line: their difference is parallel to e
        diff = mine["o"] - ref["o"]
        np.testing.assert_allclose(np.cross(diff, mine["e"])[revolute_rows], 0, atol=1e-11)


def test_compiled_fk_matches_pinocchio_about_negative_and_oblique_axes(tmp_path):
    """The compiled FK turns about ±x, ±y, ±z by the two columns they move and about any other axis by Rodrigues'
    product: a chain with every kind of axis (negative, oblique, not unit in the file) against Pinocchio."""
    axes = ("0 0 -1", "0 -1 0", "-1 0 0", "1 0 0", "0 1 0", "0.6 0 0.8", "1 2 -2")
    links = "".join(f'<link name="l{i}"/>' for i in range(len(axes) + 1))
    joints = "".join(revolute(f"j{i}", f"l{i}", f"l{i + 1}", axis=a, xyz="0.1 0.05 0.3")
                     for i, a in enumerate(axes))
    robot = kinelab.load(write_urdf(tmp_path, links + joints))
    vm = vector_model(robot)
    for q in robot.random_qs(20, 5):
        mine, oMtool = vm.vectors(q), robot.fk(q)
        np.testing.assert_allclose(mine["N"], oMtool.translation, atol=1e-12)
        np.testing.assert_allclose(mine["R"], oMtool.rotation, atol=1e-12)
        data = robot.model.createData()
        pin.computeJointJacobians(robot.model, data, q)
        for i in range(robot.n):  # each world axis: the angular rows of Pinocchio's Jacobian column
            axis = pin.getJointJacobian(robot.model, data, i + 1, pin.ReferenceFrame.WORLD)[3:, i]
            np.testing.assert_allclose(mine["e"][i], axis, atol=1e-12)


@pytest.mark.parametrize("name", ROBOTS)
def test_exact_step_is_the_minimum_of_the_true_objective_on_a_dense_grid(name):
    robot = kinelab.load(name)
    vm = vector_model(robot)
    rng = np.random.default_rng(11)
    w_p = 10 / vm.length**2
    for _ in range(6):
        q = robot.random_q(rng)
        target = robot.fk(robot.random_q(rng))
        i = int(rng.integers(robot.n))
        joint = robot.joints[i]
        model = reference.vector_model(robot, q)
        if joint.kind == "continuous":
            window = (-np.pi, np.pi)
        else:
            window = (joint.lower - q[i], joint.upper - q[i])
        if joint.kind == "prismatic":
            step = reference.prismatic_step(model["e"][i], model["p"], target.translation, w_p, window)
        else:
            step = reference.revolute_step(model["e"][i], model["o"][i], model["p"], model["R"],
                                           target.translation, target.rotation, w_p, np.ones(3),
                                           window if joint.kind == "revolute" else (-np.inf, np.inf))
        grid = np.linspace(window[0], window[1], 20001)
        values = []
        for t in grid:
            dq = np.zeros(robot.nv)
            dq[i] = t
            values.append(tool_objective(robot, robot.integrate(q, dq), target, w_p))
        dq = np.zeros(robot.nv)
        dq[i] = step
        at_step = tool_objective(robot, robot.integrate(q, dq), target, w_p)
        assert at_step <= min(values) + 1e-9, (name, i)
        assert at_step <= tool_objective(robot, q, target, w_p) + 1e-12
        spacing = grid[1] - grid[0]
        gap = grid[int(np.argmin(values))] - step
        if joint.kind != "prismatic":  # windows wider than 2π hold the same minimum twice
            gap = (gap + np.pi) % (2 * np.pi) - np.pi
        assert abs(gap) <= spacing + 1e-9


def test_closed_form_objective_is_a_sinusoid_matching_fk(robots):
    """E(θ) = a − 2B cos θ − 2C sin θ with B, C from the vector model, checked against Pinocchio FK."""
    robot = robots["panda"]
    rng = np.random.default_rng(5)
    w_p = 1.7
    for _ in range(10):
        q, target = robot.random_q(rng), robot.fk(robot.random_q(rng))
        i = int(rng.integers(robot.n))
        m = reference.vector_model(robot, q)
        B, C = kernel.revolute_BC(m["e"][i], m["o"][i], m["p"], m["R"], target.translation, target.rotation,
                                  w_p, np.ones(3))
        E0 = tool_objective(robot, q, target, w_p)
        for theta in np.linspace(-np.pi, np.pi, 41):
            dq = np.zeros(robot.nv)
            dq[i] = theta
            predicted = E0 + 2 * B - 2 * B * np.cos(theta) - 2 * C * np.sin(theta)
            assert predicted == pytest.approx(tool_objective(robot, robot.integrate(q, dq), target, w_p), abs=1e-10)


@pytest.mark.parametrize("base_to_tip", [True, False])
@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_sweep_equals_the_readable_reference(name, base_to_tip):
    robot = kinelab.load(name)
    vm = vector_model(robot)
    rng = np.random.default_rng(2)
    for _ in range(5):
        q, target = robot.random_q(rng), robot.fk(robot.random_q(rng))
        w_p = 10 / vm.length**2
        expected = reference.sweep(robot, q, target, w_p, base_to_tip=base_to_tip)
        got = q.copy()
        v = vm.vectors(q)
        kernel.sweep(got, v["e"], v["o"], vm.kind, vm.lower, vm.upper, np.ones(robot.n, dtype=np.bool_),
                     v["N"].copy(), v["R"].copy(), target.translation.copy(), target.rotation.copy(), w_p,
                     np.ones(3), 1.0, base_to_tip, np.zeros(robot.n), 0.0)
        np.testing.assert_allclose(got, expected, atol=1e-10)


def _objective_with_rest(robot, q, i, target, rest, w_p, w_rest, x):
    """E + rest term with joint i at x, E from Pinocchio's FK."""
    qq = q.copy()
    qq[i] = x
    M = robot.fk(qq)
    d = x - rest[i]
    rest_term = d * d if robot.joints[i].kind == "prismatic" else 2 * (1 - np.cos(d))
    return (w_p * np.sum((M.translation - target.translation) ** 2)
            + np.sum((M.rotation - target.rotation) ** 2) + w_rest * rest_term)


@pytest.mark.parametrize("name", ["panda", "stanford"])
def test_a_step_with_the_rest_term_is_the_exact_minimiser_by_pinocchio(name):
    """One joint free: the kernel's step must minimise E + w_rest·2(1 − cos(q_i − r_i)) (revolute) or
    w_rest (q_i − r_i)² (prismatic), E evaluated with Pinocchio's FK on a fine grid over the window."""
    robot = kinelab.load(name)
    vm = vector_model(robot)
    rng = np.random.default_rng(5)
    w_p, w_rest = 10 / vm.length**2, 0.3
    for _ in range(4):
        q, target, rest = robot.random_q(rng), robot.fk(robot.random_q(rng)), robot.random_q(rng)
        i = int(rng.integers(robot.n))
        free = np.zeros(robot.n, dtype=np.bool_)
        free[i] = True
        got = q.copy()
        v = vm.vectors(q)
        kernel.sweep(got, v["e"], v["o"], vm.kind, vm.lower, vm.upper, free, v["N"].copy(), v["R"].copy(),
                     target.translation.copy(), target.rotation.copy(), w_p, np.ones(3), 1.0, True, rest, w_rest)

        total = functools.partial(_objective_with_rest, robot, q, i, target, rest, w_p, w_rest)
        grid = np.linspace(robot.lower[i], robot.upper[i], 4001)
        best = grid[np.argmin([total(x) for x in grid])]
        step = (robot.upper[i] - robot.lower[i]) / 4000
        assert total(got[i]) <= total(best) + 1e-12
        assert abs(got[i] - best) <= step or total(got[i]) <= min(total(best - step), total(best + step))


@pytest.mark.parametrize("name", ROBOTS)
def test_sweeps_never_increase_the_objective_and_keep_limits(name):
    robot = kinelab.load(name)
    vm = vector_model(robot)
    rng = np.random.default_rng(9)
    w_p = 10 / vm.length**2
    for _ in range(10):
        q, target = robot.random_q(rng), robot.fk(robot.random_q(rng))
        E = tool_objective(robot, q, target, w_p)
        for k in range(15):
            v = vm.vectors(q)
            kernel.sweep(q, v["e"], v["o"], vm.kind, vm.lower, vm.upper, np.ones(robot.n, dtype=np.bool_),
                         v["N"].copy(), v["R"].copy(), target.translation.copy(), target.rotation.copy(), w_p,
                         np.ones(3), 1.0, k % 2 == 0, np.zeros(robot.n), 0.0)
            E_next = tool_objective(robot, q, target, w_p)
            assert E_next <= E + 1e-12
            assert robot.within_limits(q, slack=1e-12)  # continuous joints have no limits
            E = E_next


def test_accelerated_runs_are_monotone_too(robots):
    robot = robots["era"]
    target = robot.fk(robot.random_q(4))
    res = solve(robot, target, q0=robot.random_q(5), max_restarts=0, trace=True, time_budget=5.0)
    trace = np.array(res.diagnostics.trace)
    assert len(trace) >= 2 and np.all(np.diff(trace) <= 1e-15 * trace[:-1] + 1e-300)


# -- the monitor and the kicks on a straight planar arm ---------------------------------------------

PLANAR_3R = ('<link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="tool"/>'
             + revolute("j1", "base", "l1", xyz="0 0 0") + revolute("j2", "l1", "l2", xyz="1 0 0")
             + revolute("j3", "l2", "l3", xyz="1 0 0")
             + '<joint name="jt" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>')


@pytest.fixture
def planar(tmp_path):
    return kinelab.load(write_urdf(tmp_path, PLANAR_3R.replace('lower="-2" upper="2"', 'lower="-3" upper="3"')))


def test_monitor_fires_on_a_straight_arm_with_the_target_on_its_line(planar):
    target = pin.SE3(np.eye(3), np.array([2.3, 0.0, 0.0]))
    res = solve(planar, target, q0=np.zeros(3), mode="position", max_restarts=0, policy=())
    assert not res.success and res.status.value == "singular"
    first = res.singular_events[0]
    assert first.trigger == "step" and first.sweep == 1 and first.diagnosis == "singular"
    np.testing.assert_allclose(res.q, 0.0)


def test_the_two_kick_signs_give_the_two_mirror_branches(planar):
    target = pin.SE3(np.eye(3), np.array([2.3, 0.0, 0.0]))
    branches = {}
    for sign in (-1.0, 1.0):
        res = solve(planar, target, q0=np.zeros(3), mode="position", max_restarts=0, kicks={"j2": sign * 1e-3},
                    tol_rot=10.0, order="tip2base", time_budget=5.0)
        assert res.success, res
        assert [b.bypass for b in res.bypasses] == ["kicks"]
        branches[sign] = res.q
    # mirror images about the line: the elbow (j3) folds one way or the other
    assert np.sign(branches[-1.0][2]) != np.sign(branches[1.0][2]) and abs(branches[1.0][2]) > 0.5
    np.testing.assert_allclose(branches[-1.0], -branches[1.0], atol=1e-5)


# -- solutions, checked by Pinocchio ----------------------------------------------------------------------

@pytest.mark.parametrize("name", ("stanford", "era", "youbot", "panda", "ur5"))
def test_frdm_solutions_are_confirmed_by_pinocchio(name):
    robot = kinelab.load(name)
    rng = np.random.default_rng(21)
    solved = 0
    for k in range(25):
        target = robot.fk(robot.random_q(rng))
        res = solve(robot, target, solver="frdm", seed=k, time_budget=0.2)
        if res.success:
            solved += 1
            oMtool = robot.fk(res.q)  # independent re-check
            assert np.linalg.norm(oMtool.translation - target.translation) <= 1e-6
            assert np.linalg.norm(pin.log3(target.rotation.T @ oMtool.rotation)) <= 1e-6
            assert robot.within_limits(res.q)
        else:
            assert res.status.value != "converged"
    assert solved >= 24


def test_position_and_orientation_modes(robots):
    robot = robots["panda"]
    target = robot.fk(robot.random_q(8))
    pos = solve(robot, target, mode="position", seed=1, tol_rot=np.pi)
    assert pos.success and np.linalg.norm(robot.fk(pos.q).translation - target.translation) <= 1e-6
    ori = solve(robot, target, mode="orientation", seed=1, tol_pos=10.0)
    assert ori.success and np.linalg.norm(pin.log3(target.rotation.T @ robot.fk(ori.q).rotation)) <= 1e-6


# -- bad input -----------------------------------------------------------------------------------

def test_unreachable_target_is_reported_never_success(robots):
    robot = robots["ur5"]
    target = pin.SE3(np.eye(3), np.array([3.0, 0.0, 0.5]))
    res = solve(robot, target, seed=0, time_budget=0.05)
    assert not res.success and res.status.value == "unreachable"
    assert res.position_error > 1.5 and "beyond" in res.message
    # the reported error is the distance this test measures with Pinocchio's FK of the returned q
    assert res.position_error == pytest.approx(np.linalg.norm(robot.fk(res.q).translation - target.translation),
                                               abs=1e-12)
    assert robot.within_limits(res.q)


def test_start_outside_limits_is_projected_with_a_warning_or_refused(robots):
    robot = robots["stanford"]
    target = robot.fk(robot.random_q(1))
    q0 = np.array([0, 0, 1.5, 0, 0, 0])
    with pytest.warns(UserWarning, match="projected"):
        solve(robot, target, q0=q0, seed=0)
    with pytest.raises(kinelab.JointLimitError, match="joint3"):
        solve(robot, target, q0=q0, start_outside_limits="refuse")


@pytest.mark.parametrize("options, match", [
    ({"kicks": {"nojoint": 0.1}}, "unknown joint 'nojoint'"),
    ({"intervals": {"joint5": (0.5, 0.2)}}, "empty"),
    ({"freeze": {"joint9": 0.0}}, "unknown joint"),
    ({"policy": ("teleport",)}, "unknown bypass"),
    ({"order": "sideways"}, "sweep order"),
    ({"speed": 3}, "unknown option 'speed'"),
])
def test_bad_bypass_and_options_are_refused_clearly(options, match):
    robot = kinelab.load("era")
    with pytest.raises(kinelab.KinelabError, match=match):
        solve(robot, robot.fk(np.zeros(7)), **options)


def test_targets_must_be_poses():
    robot = kinelab.load("ur5")
    with pytest.raises(kinelab.KinelabError, match="pin.SE3"):
        solve(robot, np.eye(4))
    bad = pin.SE3.Identity()
    bad.translation = np.array([np.nan, 0, 0])
    with pytest.raises(kinelab.KinelabError, match="NaN"):
        solve(robot, bad)
    skew = pin.SE3.Identity()
    skew.rotation = np.diag([1.0, 1.0, 1.001])
    with pytest.raises(kinelab.KinelabError, match="not a rotation"):
        solve(robot, skew)
    mirror = pin.SE3.Identity()
    mirror.rotation = np.diag([1.0, 1.0, -1.0])
    with pytest.raises(kinelab.KinelabError, match="det R < 0"):
        solve(robot, mirror)


def test_huge_finite_inputs_are_judged_exactly_not_as_overflow():
    """The fast finiteness tests sum the entries; a sum that overflows must fall back to the exact test."""
    robot = kinelab.load("ur5")
    far = pin.SE3.Identity()
    far.translation = np.array([1e308, 1e308, 0.0])  # finite, its sum is not
    res = solve(robot, far)
    assert not res.success and res.status.value == "unreachable"
    q = np.zeros(robot.n)
    q[:2] = 1e308
    with pytest.raises(kinelab.KinelabError, match="outside its limits"):
        robot.check_q(q, limits=True)
    assert robot.check_q(q).shape == (robot.n,)  # finite: accepted when limits are not asked for


def test_helical_or_spherical_joints_are_refused_by_name(tmp_path):
    body = ('<link name="base"/><link name="a"/>'
            '<joint name="ball" type="planar"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(kinelab.ChainError, match="ball"):
            kinelab.load(write_urdf(tmp_path, body))


def test_compiled_multistart_is_seeded_and_checked_by_pinocchio(robots):
    robot = robots["panda"]
    rng = np.random.default_rng(44)
    for k in range(10):
        target = robot.fk(robot.random_q(rng))
        a = solve(robot, target, seed=k, time_budget=1.0)
        b = solve(robot, target, seed=k, time_budget=1.0)
        assert a.diagnostics.path == "compiled" and a.success
        np.testing.assert_array_equal(a.q, b.q)
        assert robot.tool_error(a.q, target)[0] <= 1e-6 and robot.within_limits(a.q)
    loop = solve(robot, target, seed=0, policy=("auto_kick",))
    assert loop.diagnostics.path == "" and loop.success


def test_mixed_order_restarts_turn_the_sweep_direction(robots):
    """order="mixed": attempt 1 sweeps base → tip, the restart tip → base, from the same seeded start."""
    from kinelab.ik.frdm.options import ORDERS

    robot = robots["stanford"]
    vm = vector_model(robot)
    rng = np.random.default_rng(3)
    for _ in range(20):  # find a start whose first attempt, either way, does not converge
        target, q0 = robot.fk(robot.random_q(rng)), robot.random_q(rng)
        last = {}
        for name in ("mixed", "base2tip", "tip2base"):
            q, best, stats = q0.copy(), q0.copy(), np.zeros(kernel.STATS_SIZE)
            problem = kernel.Objective(vm.lower, vm.upper, np.ones(vm.n, dtype=np.bool_), target.translation,
                                     target.rotation, 3.0 / vm.length**2, np.ones(3), 1e-6, 1e-6, True, True,
                                     np.zeros(vm.n), 0.0, -1)
            settings = kernel.Settings(1.0, 1e-10, 10, 0.1, 5, 0, 0.0, 8)  # no polish: both attempts run
            code = kernel.multistart(q, vm.chain, problem, settings, ORDERS[name], 100, seed_state(7), 2, 1e9, best,
                                     stats, kernel.new_memory(vm.n, 5))
            last[name] = (q, stats[0], code)
        if last["mixed"][1] == 2 and last["base2tip"][1] == 2 and last["tip2base"][1] == 2:
            np.testing.assert_array_equal(last["mixed"][0], last["tip2base"][0])  # the restart ran tip → base
            assert not np.array_equal(last["mixed"][0], last["base2tip"][0])
            return
    pytest.fail("no start found whose first attempt fails both ways")


@pytest.mark.parametrize("chunk", [3, 7, 40])
def test_the_answer_does_not_depend_on_where_the_clock_chunks_end(chunk):
    """The multistart called in chunks of a few sweeps (as a timed solve calls it) resumes each cut attempt
    with its history: the same answer, sweep for sweep, as one uncut call."""
    robot = kinelab.load("panda")
    vm = vector_model(robot)
    rng = np.random.default_rng(11)
    settings = kernel.Settings(1.0, 1e-10, 10, 0.1, 5, 10, 0.0, 8)
    for _ in range(5):
        target, q0 = robot.fk(robot.random_q(rng)), robot.random_q(rng)
        problem = kernel.Objective(vm.lower, vm.upper, np.ones(vm.n, dtype=np.bool_), target.translation,
                                 target.rotation, 3.0 / vm.length**2, np.ones(3), 1e-9, 1e-9, True, True,
                                 np.zeros(vm.n), 0.0, -1)
        results = []
        for size in (1e9, chunk):
            q, best, stats, mem = q0.copy(), q0.copy(), np.zeros(kernel.STATS_SIZE), kernel.new_memory(vm.n, 5)
            rng_state, left, code = seed_state(3), 20, -1
            while left > 0:
                before = stats[kernel.T_ATTEMPTS]
                code = kernel.multistart(q, vm.chain, problem, settings, kernel.MIXED, 100, rng_state, left,
                                           stats[kernel.T_SWEEPS] + size, best, stats, mem)
                left -= int(stats[kernel.T_ATTEMPTS] - before)
                if code == kernel.CONVERGED:
                    break
            results.append((code, best.copy(), stats[kernel.T_SWEEPS], stats[kernel.T_ATTEMPTS]))
        assert results[0][0] == results[1][0] and results[0][2:] == results[1][2:]
        np.testing.assert_array_equal(results[0][1], results[1][1])


def test_numpy_scalars_as_arguments_give_the_same_answer_as_python_ones(robots):
    """Every scalar reaching a compiled kernel is made a Python int, float or bool first (one signature)."""
    robot = robots["ur5"]
    rng = np.random.default_rng(5)
    for _ in range(5):
        target, q0 = robot.fk(robot.random_q(rng)), robot.random_q(rng)
        plain = solve(robot, target, q0=q0, seed=3, max_restarts=20, max_sweeps=100, w_p=30.0, relax=1.0)
        numpy = solve(robot, target, q0=q0, seed=np.int64(3), max_restarts=np.int32(20), max_sweeps=np.int16(100),
                      w_p=np.float64(30.0), relax=np.float32(1.0), tol_pos=np.float64(1e-6))
        np.testing.assert_array_equal(plain.q, numpy.q)
        assert plain.status == numpy.status and plain.iterations == numpy.iterations
