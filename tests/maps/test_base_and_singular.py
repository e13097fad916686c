"""The youBot's base map (every reachable platform pose really reaches the grasp with the whole robot) and
the singularity map (the sweep's engine: rank-deficient samples are singular by an independent SVD)."""

import numpy as np
import pytest

import kinelab
from kinelab import KinelabError, maps


def test_every_reachable_platform_pose_reaches_the_grasp_with_the_whole_youbot():
    youbot = kinelab.load("youbot")
    q_true = youbot.display_q()
    grasp = youbot.fk(q_true)
    result = maps.base_map(youbot, grasp, step=0.05)
    assert result.reachable.sum() >= 10  # measured: 62 of 741 positions
    for i in np.flatnonzero(result.reachable):
        q = np.concatenate([result.poses[i], result.q[i]])
        dp, dr = youbot.tool_error(q, grasp)
        assert dp <= 1e-6 and dr <= 1e-6 and youbot.within_limits(q)
    best = result.ranked(5)
    assert list(result.manipulability[best]) == sorted(result.manipulability[best], reverse=True)
    far = kinelab.target_from_xyz_rpy([0.0, 0.0, 3.0], [0.0, 0.0, 0.0])  # 3 m up: out of any reach
    assert not maps.base_map(youbot, far, step=0.1).reachable.any()
    with pytest.raises(KinelabError, match="no platform joint 'platform_x'"):
        maps.base_map(kinelab.load("ur5"), grasp)


def test_the_closed_form_base_map_reaches_every_position_the_numeric_one_reaches(monkeypatch):
    """The youBot's heading and arm have a closed form: every branch of every platform position in one batch.
    Held against the numeric batch (restarts, the path for chains without one) on five grasps: no position the
    numeric map reaches is missing, and each extra one reaches the grasp with the whole robot."""
    import kinelab.maps.base as base
    from kinelab.ik.analytic.classify import Classification

    youbot = kinelab.load("youbot")
    rng = np.random.default_rng(3)
    real = base.classify
    for _ in range(5):
        grasp = youbot.fk(youbot.random_q(rng))
        closed = maps.base_map(youbot, grasp, step=0.1)
        monkeypatch.setattr(base, "classify", lambda robot: Classification(None, "the numeric path, for the test"))
        numeric = maps.base_map(youbot, grasp, step=0.1)
        monkeypatch.setattr(base, "classify", real)
        assert np.array_equal(closed.poses[:, :2], numeric.poses[:, :2])
        assert np.all(closed.reachable[numeric.reachable])
        for i in np.flatnonzero(closed.reachable & ~numeric.reachable):
            q = np.concatenate([closed.poses[i], closed.q[i]])
            assert max(youbot.tool_error(q, grasp)) <= 1e-6 and youbot.within_limits(q)


def test_the_singularity_map_flags_what_an_independent_svd_finds_singular():
    ur5 = kinelab.load("ur5")
    result = maps.singularity(ur5, samples=500, seed=0)
    q = result.q[0].copy()
    q[4] = 0.0  # the wrist lock, added by hand
    from kinelab.analysis.families import sigma_ratio_batch

    assert sigma_ratio_batch(ur5, q[None])[0] < 1e-10
    length = ur5.characteristic_length()
    expected = []
    for x in result.q[:50]:  # the same ratio through Robot's Jacobian and numpy's SVD, sample by sample
        J = ur5.jacobian_local_world_aligned(x)
        J[:3] /= length
        s = np.linalg.svd(J, compute_uv=False)
        expected.append(s[5] / s[0])
    np.testing.assert_allclose(result.sigma_ratio[:50], expected, rtol=1e-9, atol=1e-15)
    with pytest.raises(KinelabError, match="at least one sample"):
        maps.singularity(ur5, samples=0)
