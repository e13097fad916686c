"""Biquaternion algebra, with a double-cover aware comparator, against Pinocchio."""

import numpy as np
import pinocchio as pin
import pytest

from kinelab.dq.algebra import BiquaternionError, DualQuat, dual_div, same_pose


def random_dq(rng, unit=True) -> DualQuat:
    if unit:
        return DualQuat.from_se3(pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)))
    return DualQuat(rng.normal(size=4), rng.normal(size=4))


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def test_product_is_associative(rng):
    for _ in range(50):
        a, b, c = (random_dq(rng, unit=False) for _ in range(3))
        np.testing.assert_allclose(((a * b) * c).as_array(), (a * (b * c)).as_array(), atol=1e-12)


def test_unit_biquaternions_are_closed_under_the_product(rng):
    for _ in range(50):
        assert (random_dq(rng) * random_dq(rng)).is_unit(1e-12)


def test_conjugate_of_a_product_reverses_the_order(rng):
    for _ in range(50):
        a, b = random_dq(rng, unit=False), random_dq(rng, unit=False)
        np.testing.assert_allclose((a * b).conj().as_array(), (b.conj() * a.conj()).as_array(), atol=1e-12)


def test_the_three_conjugations():
    lam = DualQuat(np.array([1.0, 2, 3, 4]), np.array([5.0, 6, 7, 8]))
    np.testing.assert_array_equal(lam.conj().as_array(), [1, -2, -3, -4, 5, -6, -7, -8])
    np.testing.assert_array_equal(lam.dual_conj().as_array(), [1, 2, 3, 4, -5, -6, -7, -8])
    np.testing.assert_array_equal(lam.full_conj().as_array(), [1, -2, -3, -4, -5, 6, 7, 8])


def test_norm_and_normalisation(rng):
    for _ in range(20):
        a = random_dq(rng, unit=False)
        r, r0 = a.norm()
        # Λ∘Λ̄ = |λ|² + s 2 λ·λ0, a dual scalar: its square root is r + s r0
        prod = (a * a.conj()).as_array()
        assert prod[0] == pytest.approx(r**2) and prod[4] == pytest.approx(2 * r * r0)
        np.testing.assert_allclose(prod[[1, 2, 3, 5, 6, 7]], 0, atol=1e-12)
        assert a.normalized().is_unit(1e-12)


def test_se3_round_trip_and_composition_match_pinocchio(rng):
    for _ in range(100):
        A, B = pin.SE3.Random(), pin.SE3.Random()
        assert np.allclose(DualQuat.from_se3(A).to_se3().homogeneous, A.homogeneous, atol=1e-12)
        assert same_pose(DualQuat.from_se3(A) * DualQuat.from_se3(B), DualQuat.from_se3(A * B), 1e-12)
        assert same_pose(DualQuat.from_se3(A).conj(), DualQuat.from_se3(A.inverse()), 1e-12)


def test_exp_of_log_is_identity_and_log_matches_log6(rng):
    for _ in range(100):
        M = pin.SE3.Random()
        lam = DualQuat.from_se3(M)
        w, v = lam.log()
        xi = pin.log6(M)
        np.testing.assert_allclose(w, 0.5 * xi.angular, atol=1e-12)
        np.testing.assert_allclose(v, 0.5 * xi.linear, atol=1e-12)
        assert same_pose(DualQuat.from_screw((w, v)), lam, 1e-12)
    pure = pin.SE3(np.eye(3), np.array([0.3, -0.2, 0.1]))
    assert same_pose(DualQuat.from_screw(DualQuat.from_se3(pure).log()), DualQuat.from_se3(pure), 1e-12)


def test_double_cover_comparator(rng):
    lam = random_dq(rng)
    assert same_pose(lam, -lam) and not same_pose(lam, random_dq(rng))


def test_bad_biquaternions_are_refused():
    with pytest.raises(BiquaternionError, match="NaN"):
        DualQuat(np.array([1.0, np.nan, 0, 0]), np.zeros(4))
    with pytest.raises(BiquaternionError, match="shape"):
        DualQuat(np.ones(3), np.zeros(4))
    with pytest.raises(BiquaternionError, match="not a unit"):
        DualQuat(np.array([2.0, 0, 0, 0]), np.zeros(4)).to_se3()
    with pytest.raises(BiquaternionError, match="zero"):
        dual_div((1.0, 0.0), (0.0, 1.0))
