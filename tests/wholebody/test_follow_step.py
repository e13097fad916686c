"""#59 goal 4: ``kinelab.track(..., follower="step")`` follows a redundant arm's path without drifting into a limit
or jumping: the task at priority 1, a posture (keep moving as before, away from a limit as it nears) at priority 2,
every sample within a box about the one before. The trust issue's panda path (#57 item 6: FRDM's follower slid joint
1 to its limit and turned joint 5 by 2.2 rad in one sample) is the reproducer."""

import numpy as np
import pytest
from helpers import cosine_path, joint_line

import kinelab
from kinelab.errors import OptionError


def margin(robot, Q):
    """Each row's distance to its nearest joint limit [rad]."""
    return np.minimum(Q - robot.lower, robot.upper - Q).min(axis=1)


def test_the_issues_panda_path_is_met_without_a_jump_or_a_drift():
    panda = kinelab.load("panda")
    path = cosine_path(panda, np.random.default_rng(4))
    res = kinelab.track(panda, panda.fk_batch(path), q0=path[0], seed=3, follower="step")
    assert res.success.sum() == 2000 and res.path_success
    assert res.mode.startswith("whole-body step")
    own = np.abs(np.diff(path, axis=0)).max()
    steps = np.abs(np.diff(np.vstack([path[:1], res.q]), axis=0)).max()
    assert steps <= 3 * own  # FRDM's follower: 2.18 rad against the path's 0.0021
    assert (margin(panda, path) - margin(panda, res.q)).max() <= 0.1  # FRDM's: 1.04 rad closer to joint 1's limit
    assert np.all(res.position_error <= 1e-6) and np.all(res.rotation_error <= 1e-6)


@pytest.mark.parametrize("name", ["era", "baxter_left", "xarm7"])
def test_no_joint_ever_moves_more_than_the_jump_limit(name):
    """FRDM's follower turned a joint of era 6.27 rad in one sample on these lines (baxter_left 6.12, xarm7 3.59):
    the step's box holds every sample within jump_limit; a sample it cannot meet so is a miss, never a jump."""
    robot = kinelab.load(name)
    for seed in range(2):
        path = joint_line(robot, np.random.default_rng(seed))
        res = kinelab.track(robot, robot.fk_batch(path), q0=path[0], follower="step", jump_limit=0.05)
        steps = np.abs(np.diff(np.vstack([path[:1], res.q]), axis=0)).max(axis=1)
        assert steps.max() <= 0.05 + 1e-9
        assert robot.within_limits_batch(res.q).all()
        met = res.success
        assert met.mean() >= 0.95
        assert np.all(res.position_error[met] <= 1e-6) and np.all(res.rotation_error[met] <= 1e-6)


def test_a_position_task_leaves_the_rotation_free():
    panda = kinelab.load("panda")
    path = joint_line(panda, np.random.default_rng(7), samples=100)
    res = kinelab.track(panda, panda.fk_batch(path), q0=path[0], follower="step", task="position")
    assert res.success.all() and np.all(res.position_error <= 1e-6)


def test_the_followers_and_their_settings_are_named():
    panda = kinelab.load("panda")
    targets = panda.fk_batch(np.tile(panda.random_q(0), (3, 1)))
    with pytest.raises(OptionError, match="'frdm' or 'step'"):
        kinelab.track(panda, targets, follower="newton")
    with pytest.raises(OptionError, match="jump_limit"):
        kinelab.track(panda, targets, follower="step", kicks={"panda_joint1": 0.1})
    with pytest.raises(OptionError):
        kinelab.track(panda, targets, follower="step", jump_limit=-1.0)
