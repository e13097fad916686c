"""solve()'s own arguments: every bad one refused, naming it, before any solving."""

import numpy as np
import pytest

import kinelab


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
