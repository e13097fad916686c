"""Λ(q) and A(q) from biquaternions against Pinocchio (tool pose, LOCAL Jacobian) and finite differences."""

import numpy as np
import pytest
from helpers import BUNDLED

import kinelab
from kinelab.dq import kinematics as bk
from kinelab.dq.algebra import DualQuat, same_pose
from kinelab.robot import catalog

ARMS = tuple(e.name for e in catalog.ERD_ARMS)


@pytest.mark.parametrize("name", BUNDLED + ARMS)
def test_chain_product_is_pinocchios_tool_pose(name):
    robot = kinelab.load(name)
    for q in robot.random_qs(20, 4):
        assert same_pose(bk.pose(robot, q), DualQuat.from_se3(robot.fk(q)), 1e-12)


@pytest.mark.parametrize("name", BUNDLED + ARMS)
def test_A_is_the_local_jacobian_with_row_blocks_swapped(name):
    robot = kinelab.load(name)
    for q in robot.random_qs(10, 5):
        J = robot.jacobian_local(q)
        np.testing.assert_allclose(bk.a_matrix(robot, q), np.vstack([J[3:], J[:3]]), atol=1e-10)


@pytest.mark.parametrize("name", ("stanford", "youbot", "kinova"))
def test_A_matches_finite_differences_of_the_biquaternion(name):
    """U = 2 Λ̄∘Λ̇: columns by central differences of Λ(q) stepped with pin.integrate."""
    robot = kinelab.load(name)
    eps = 1e-6
    for q in robot.random_qs(5, 6):
        lam = bk.pose(robot, q)
        A = bk.a_matrix(robot, q)
        for i in range(robot.n):
            dq = np.zeros(robot.nv)
            dq[i] = eps
            plus, minus = bk.pose(robot, robot.integrate(q, dq)), bk.pose(robot, robot.integrate(q, -dq))
            if plus.real_wxyz @ lam.real_wxyz < 0:
                plus = -plus
            if minus.real_wxyz @ lam.real_wxyz < 0:
                minus = -minus
            deriv = DualQuat((plus.real_wxyz - minus.real_wxyz) / (2 * eps),
                             (plus.dual_wxyz - minus.dual_wxyz) / (2 * eps))
            U = (lam.conj() * deriv).as_array() * 2
            np.testing.assert_allclose(np.r_[U[1:4], U[5:8]], A[:, i], atol=1e-6)
