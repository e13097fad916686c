"""The prepared solver's one compiled call (its solver's engine) gives the general route's results: same q, verdict,
status, counts and diagnostics for the same seed, on the usual call and on every input it hands to the general path;
and kinelab.solve gives the prepared solver's."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import kinelab


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


SAME = ("success", "status", "position_error", "rotation_error", "iterations", "restarts", "solver", "mode",
        "message", "task")


def _general(robot, target, q0, seed, task="pose", max_restarts=1000, tol=1e-6, **solver_options):
    """The driver's general route with these settings (no budget)."""
    from dataclasses import replace

    from kinelab.ik.driver import solve_one
    from kinelab.ik.request import make_request

    req = make_request("frdm", None, tol, tol, None, max_restarts, "project", None, task, "z", solver_options)
    return solve_one(robot, target, q0, replace(req, seed=seed))


def _same(a: kinelab.IKResult, b: kinelab.IKResult) -> None:
    np.testing.assert_array_equal(a.q, b.q)
    for name in SAME:
        assert getattr(a, name) == getattr(b, name), name
    assert a.diagnostics.to_dict() == b.diagnostics.to_dict()
    assert [e.to_dict() for e in a.singular_events] == [e.to_dict() for e in b.singular_events]


@pytest.mark.parametrize("name", ["ur5", "kinova", "stanford", "youbot"])
@pytest.mark.parametrize("task", ["pose", "position", "axis"])
def test_the_one_call_equals_the_general_route_and_kinelab_solve(name, task):
    robot = kinelab.load(name)
    settings = dict(task=task, time_budget=None, max_restarts=30, solver="frdm")
    ik = kinelab.IK(robot, **settings)
    assert ik.engine is not None  # the usual call is served by the engine (pose-like targets, float starts)
    rng = np.random.default_rng(3)
    for k in range(8):
        q = robot.random_q(rng)
        target = robot.fk(q)
        warm = np.clip(q + rng.normal(0, 0.1, q.size), robot.lower, robot.upper)
        for q0 in (warm, None):
            one = ik.solve(target, q0=q0, seed=k)
            _same(one, _general(robot, target, q0, k, task, 30))
            _same(one, kinelab.solve(robot, target, q0=q0, seed=k, **settings))


def test_every_unusual_input_gets_the_general_path_s_answer_or_error(ur5):
    ik = kinelab.IK(ur5, time_budget=None, max_restarts=5)
    q = ur5.random_q(1)
    target = ur5.fk(q)
    outside = q.copy()
    outside[0] = ur5.upper[0] + 0.5
    far = pin.SE3(target.rotation, np.array([9.0, 0.0, 0.0]))  # beyond the UR5's reach: UNREACHABLE
    cases = [(target, list(q)), (target, outside), (far, q), (target, q.astype(np.float32))]
    for t, q0 in cases:
        with warnings.catch_warnings(record=True) as lean_warned:
            warnings.simplefilter("always")
            a = ik.solve(t, q0=q0, seed=2)
        with warnings.catch_warnings(record=True) as plain_warned:
            warnings.simplefilter("always")
            b = kinelab.solve(ur5, t, q0=q0, seed=2, time_budget=None, max_restarts=5)
        _same(a, b)
        assert [str(w.message) for w in lean_warned] == [str(w.message) for w in plain_warned]
    assert ik.solve(far, q0=q).status.value == "unreachable"
    bad = pin.SE3(target.rotation, np.array([np.nan, 0.0, 0.0]))
    with pytest.raises(kinelab.TargetError, match="NaN"):
        ik.solve(bad, q0=q)
    nan_start = q.copy()
    nan_start[2] = np.nan
    with pytest.raises(kinelab.ConfigurationError, match="finite"):
        ik.solve(target, q0=nan_start)
    with pytest.raises(kinelab.ConfigurationError, match="6 numbers"):
        ik.solve(target, q0=np.zeros(5))
    _same(ik.solve(target, q0=q, seed=2**64 + 5), kinelab.solve(ur5, target, q0=q, seed=2**64 + 5, time_budget=None,
                                                                max_restarts=5))  # numpy takes any size
    for seed in (-1, 1.5, True):
        with pytest.raises(kinelab.OptionError, match="seed"):
            ik.solve(target, q0=q, seed=seed)


def test_a_failure_of_the_one_call_reports_as_the_general_path_does(ur5, no_tolerance_floor):
    """Tolerances no answer meets (1e-300): the engine builds the failure through the driver's helpers."""
    ik = kinelab.IK(ur5, time_budget=None, max_restarts=3, tol_pos=1e-300, tol_rot=1e-300, finish="none")
    target = ur5.fk(ur5.random_q(4))
    a = ik.solve(target, q0=ur5.random_q(5), seed=1)
    b = kinelab.solve(ur5, target, q0=ur5.random_q(5), seed=1, time_budget=None, max_restarts=3, tol_pos=1e-300,
                      tol_rot=1e-300, finish="none")
    assert not a.success and a.restarts == 3 and "none of 4 starts" in a.message
    _same(a, b)
    _same(a, _general(ur5, target, ur5.random_q(5), 1, max_restarts=3, tol=1e-300, finish="none"))


def test_a_start_given_as_a_list_or_another_real_dtype_takes_the_one_call(ur5, monkeypatch):
    """A list, a tuple, a float32 or an integer start holds the same values as its float64 array: the engine takes
    them (no general route: 10× the cost) and answers as the general route does; anything else still gets the
    general route's named error."""
    from kinelab.ik import routes

    ik = kinelab.IK(ur5, solver="frdm", time_budget=None, max_restarts=5)
    rng = np.random.default_rng(6)
    q = ur5.random_q(rng)
    target = ur5.fk(q)
    near = np.round(q + rng.normal(0, 0.05, q.size), 3)
    starts = [near.tolist(), tuple(near.tolist()), near.astype(np.float32), np.zeros(6, dtype=np.int64),
              np.repeat(near, 2)[::2]]  # the last a strided view, not one contiguous run

    def refused(*args, **kwargs):
        raise AssertionError("the general route was taken")

    for q0 in starts:
        expected = _general(ur5, target, np.asarray(q0, dtype=float), 3, max_restarts=5)
        with monkeypatch.context() as m:
            m.setattr(routes, "solve_one", refused)
            one = ik.solve(target, q0=q0, seed=3)
        _same(one, expected)
    for bad, error in ((["a"] * 6, "numbers"), ([True] * 6, "numbers"), ([0.0] * 5, "6 numbers"),
                       ([[0.0] * 6], "6 numbers")):
        with pytest.raises(kinelab.ConfigurationError, match=error):
            ik.solve(target, q0=bad)


def test_the_engine_says_why_it_declines_and_the_general_route_then_answers():
    """#58: the one-call engine answered None for every call it leaves to the general route; it names the reason."""
    import pinocchio as pin

    from kinelab.ik.spec import Decline

    robot = kinelab.load("ur5")
    ik = kinelab.IK(robot, solver="frdm", time_budget=None)
    q = np.array([0.3, -1.2, 1.4, -0.5, 0.9, 0.2])
    target = robot.fk(q)
    far = pin.SE3(np.eye(3), np.array([5.0, 0.0, 0.0]))
    outside = q.copy()
    outside[1] = robot.upper[1] + 0.5
    cases = [(target.homogeneous, None, 0, Decline.TARGET), (far, None, 0, Decline.TARGET),
             (target, ["a"] * 6, 0, Decline.START), (target, q[:5], 0, Decline.START),
             (target, outside, 0, Decline.OUTSIDE), (target, q, -1, Decline.SEED), (target, q, 1.5, Decline.SEED)]
    for tgt, q0, seed, why in cases:
        assert ik.engine.solve(tgt, q0, seed) == why
    assert not isinstance(ik.engine.solve(target, q, 0), int)  # the usual call: a result
    far_result = ik.solve(far, q0=q, seed=0)  # the general route answers what the engine declined
    assert far_result.status == kinelab.Status.UNREACHABLE and not far_result.success
    with pytest.warns(UserWarning, match="outside"):  # the start projected into the limits, with a warning
        projected = ik.solve(target, q0=outside, seed=0)
    assert projected.success and max(robot.tool_error(projected.q, target)) <= 1e-6
