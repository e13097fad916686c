"""solve()'s own arguments: every bad one refused, naming it, before any solving."""

import numpy as np
import pytest

import kinelab
from kinelab.ik.request import verdict_reserve


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


@pytest.mark.parametrize("kwargs, name", [
    ({"tol_pos": float("inf")}, "tol_pos"), ({"tol_pos": 0.0}, "tol_pos"), ({"tol_pos": "1e-6"}, "tol_pos"),
    ({"tol_rot": float("nan")}, "tol_rot"), ({"tol_rot": -1e-6}, "tol_rot"),
    ({"time_budget": 0}, "time_budget"), ({"time_budget": float("inf")}, "time_budget"),
    ({"max_restarts": -1}, "max_restarts"), ({"max_restarts": 2.5}, "max_restarts"),
    ({"seed": -1}, "seed"), ({"seed": 1.5}, "seed"), ({"seed": np.random.default_rng(0)}, "seed"),
    ({"start_outside_limits": "clip"}, "start_outside_limits"),
])
def test_bad_arguments_are_refused_by_name(ur5, kwargs, name):
    target = ur5.fk(ur5.random_q(0))
    with pytest.raises(kinelab.OptionError, match=name) as err:
        kinelab.solve(ur5, target, **kwargs)
    assert err.value.option == name


def test_an_infinite_tolerance_cannot_make_a_far_pose_a_success(ur5):
    far = kinelab.target_from_xyz_rpy([100.0, 0.0, 0.0])
    with pytest.raises(kinelab.OptionError):
        kinelab.solve(ur5, far, tol_pos=float("inf"))
    assert not kinelab.solve(ur5, far, seed=0).success


@pytest.mark.parametrize("q0", [np.zeros(6, dtype=complex), ["0"] * 6, [True] * 6, [None] * 6])
def test_a_start_that_is_not_real_numbers_is_refused(ur5, q0):
    with pytest.raises(kinelab.ConfigurationError, match="numbers \\(real\\)"):
        kinelab.solve(ur5, ur5.fk(ur5.random_q(0)), q0=q0)


def test_numpy_integers_are_fine_as_seed_and_restarts(ur5):
    target = ur5.fk(ur5.random_q(3))
    a = kinelab.solve(ur5, target, seed=np.uint32(7), max_restarts=np.int64(10))
    b = kinelab.solve(ur5, target, seed=7, max_restarts=10)
    np.testing.assert_array_equal(a.q, b.q)


@pytest.mark.parametrize("solver", ["frdm", "biquat", "dls"])
@pytest.mark.parametrize("links", [6, 150])
def test_an_unattainable_tolerance_ends_at_the_budget(solver, links, no_tolerance_floor):
    """A tolerance no solver reaches: the answer comes back once the budget is spent, not much later (the
    compiled kernels look at the clock after a fixed amount of joint work, whatever the chain's length)."""
    from kinelab.report.bench import scaling

    robot = kinelab.load("ur5") if links == 6 else scaling.synthetic_robot(links, seed=1)
    target = robot.fk(robot.random_q(2))
    kinelab.solve(robot, target, solver=solver, time_budget=0.01)  # compile outside the measurement
    budget = 0.02
    res = kinelab.solve(robot, target, solver=solver, q0=robot.random_q(3), seed=0, tol_pos=1e-300,
                        tol_rot=1e-300, time_budget=budget, max_restarts=10**9)  # the budget must bind
    assert not res.success and res.status.value == "time_budget"
    # behaviour, not speed: it ran until the budget, less what it keeps back for the verdict, and then stopped (the
    # bench measures the overrun's p99)
    assert budget - verdict_reserve(budget) <= res.wall_time < budget + 10.0  # ten seconds: a hang, not a slow machine


def test_the_same_seed_gives_the_same_answer_in_another_process():
    """Determinism as the README states it: with a budget that does not run out, a seed fixes the answer
    bit for bit, whichever process computes it (no clock, address or thread count enters the search)."""
    import subprocess
    import sys

    code = ("import numpy as np, kinelab\n"
            "for name, solver in (('panda', 'frdm'), ('stanford', 'frdm'), ('ur5', 'biquat'), ('ur5', 'dls')):\n"
            "    r = kinelab.load(name); rng = np.random.default_rng(11)\n"
            "    for _ in range(15):\n"
            "        res = kinelab.solve(r, r.fk(r.random_q(rng)), solver=solver, seed=5, time_budget=30.0)\n"
            "        print(res.status.value, res.restarts, res.iterations, res.q.tobytes().hex())\n")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600).stdout
            for _ in range(2)]
    assert runs[0] and runs[0] == runs[1]


@pytest.mark.parametrize("solver, options", [("frdm", kinelab.FRDMOptions()), ("dls", None), ("biquat", None)])
def test_an_options_object_and_keyword_options_together_are_refused(ur5, solver, options):
    from kinelab.ik.registry import solver_module

    opts = options or solver_module(solver).Options()
    with pytest.raises(kinelab.OptionError, match="not both"):
        kinelab.solve(ur5, ur5.fk(ur5.random_q(0)), solver=solver, options=opts, max_restarts=1, **{
            "frdm": {"relax": 1.0}, "dls": {"damping": 1e-6}, "biquat": {"k": 1.0}}[solver])


@pytest.mark.parametrize("name", ["tol_pos", "tol_rot"])
def test_a_tolerance_finer_than_double_precision_can_check_is_refused(name):
    """1e-320 once came back as a success whose error, measured by pin.log3 instead of the verdict's atan2,
    was 2.3e-16 on one machine and 0 on another: below 1e-12 no verdict is trustworthy, so none is given."""
    robot = kinelab.load("ur5")
    target = robot.fk(robot.random_q(1))
    for solve_call in (lambda **kw: kinelab.solve(robot, target, **kw),
                       lambda **kw: kinelab.solve_batch(robot, [target], **kw),
                       lambda **kw: kinelab.solve_all(robot, target, **kw),
                       lambda **kw: kinelab.IK(robot, **kw)):
        with pytest.raises(kinelab.OptionError, match=rf"{name}=1e-13 .*≥ 1e-12"):
            solve_call(**{name: 1e-13})
    res = kinelab.solve(robot, target, seed=0, **{name: 1e-12})
    dp, dr = robot.tool_error(res.q, target)
    assert res.success and (dp if name == "tol_pos" else dr) <= 1e-12


def test_counts_past_the_kernels_integers_and_empty_starts_are_refused_by_name():
    """#39 item 9: max_restarts of 2³¹ − 1 or 10³⁰ once overflowed a C int in the kernel (an OverflowError), an empty
    q0 a ValueError from the kernel, threads.set_count(1000) ended the process."""
    from kinelab.core import threads

    ur5 = kinelab.load("ur5")
    target = ur5.fk(ur5.random_q(0))
    for restarts in (2**31 - 1, 10**30):
        for call in (kinelab.solve, kinelab.solve_batch):
            with pytest.raises(kinelab.OptionError, match="max_restarts.*an integer from 0 to 1,000,000,000"):
                call(ur5, [target] if call is kinelab.solve_batch else target, max_restarts=restarts)
        with pytest.raises(kinelab.OptionError, match="max_restarts"):
            kinelab.IK(ur5, max_restarts=restarts)
    for q0 in (np.zeros(0), np.zeros(7), np.zeros((2, 6))):
        with pytest.raises(kinelab.ConfigurationError, match="6"):
            kinelab.solve(ur5, target, q0=q0)
    with pytest.raises(kinelab.OptionError, match="threads=1000 is not valid: an integer from 1 to"):
        threads.set_count(1000)
    assert kinelab.solve(ur5, target, max_restarts=10**9, seed=0).success  # the largest count is a count


def test_an_anderson_memory_past_its_use_and_starts_that_do_not_match_the_targets_are_refused():
    """#39 item 9: accel_memory=10**6 was accepted and every solve then ended max_iterations; an analytic batch with 3
    starts for 2 targets ended in numpy's broadcast error."""
    ur5 = kinelab.load("ur5")
    target = ur5.fk(ur5.random_q(0))
    with pytest.raises(kinelab.OptionError, match="accel_memory.*from 1 to 50"):
        kinelab.solve(ur5, target, accel_memory=10**6)
    assert kinelab.solve(ur5, target, accel_memory=50, seed=0).success
    with pytest.raises(kinelab.ConfigurationError, match=r"\(2, 6\) for 2 targets"):
        kinelab.solve_batch(ur5, [target, target], solver="analytic", q0=np.zeros((3, 6)))
