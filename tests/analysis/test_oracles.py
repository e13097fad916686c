"""The model cross-checks: yourdfpy FK vs Pinocchio FK, Pinocchio Jacobians vs finite differences."""

import numpy as np
import pytest
from helpers import BUNDLED, ERD_ARMS

from kinelab.analysis import oracles as checks

FK_TOL = 1e-9  # m and rad
JAC_TOL = 1e-6  # max abs entry; central differences with eps = 1e-6


@pytest.mark.parametrize("name", BUNDLED + ERD_ARMS)
def test_yourdfpy_and_pinocchio_agree_on_1000_configurations(robots, name):
    agreement = checks.fk_vs_yourdfpy(robots[name], count=1000, seed=2024)
    assert agreement.max_position < FK_TOL
    assert agreement.max_rotation < FK_TOL


@pytest.mark.parametrize("name", BUNDLED + ERD_ARMS)
def test_pinocchio_jacobians_match_finite_differences(robots, name):
    agreement = checks.jacobians_vs_fd(robots[name], count=100, seed=2025)
    assert agreement.max_rotation < JAC_TOL


def test_the_cross_check_detects_a_wrong_model(robots, monkeypatch):
    """A one-millimetre change in the tool offset must show up: the check can fail."""
    robot = robots["ur5"]
    from kinelab.analysis.oracles import YourdfpyFK

    original = YourdfpyFK.fk

    def shifted(self, q):
        oMtool = original(self, q)
        oMtool.translation = oMtool.translation + np.array([1e-3, 0, 0])
        return oMtool

    monkeypatch.setattr(YourdfpyFK, "fk", shifted)
    agreement = checks.fk_vs_yourdfpy(robot, count=5)
    assert agreement.max_position == pytest.approx(1e-3, rel=1e-6)


def test_finite_difference_jacobian_tracks_a_continuous_joint_through_integrate(robots):
    robot = robots["kinova"]
    q = robot.random_q(1)
    q[0] = np.pi - 1e-7  # a step across the ±π seam of a continuous joint must stay small
    J_fd = checks.jacobian_local_fd(robot, q)
    np.testing.assert_allclose(J_fd, robot.jacobian_local(q), atol=JAC_TOL)
