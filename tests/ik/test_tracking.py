"""kinelab.track: the compiled follower on smooth joint-space paths, judged by Pinocchio per sample."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import TargetError, load


def smooth_path(robot, seed, samples=2000, amplitude=0.6):
    """A joint-space path (each joint a sinusoid over ±amplitude of its range about mid-range), its FK."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    phase, rate = rng.uniform(0, 2 * np.pi, robot.n), rng.uniform(0.5, 1.5, robot.n)
    t = np.linspace(0, 2 * np.pi, samples)
    Q = (lo + hi) / 2 + amplitude * (hi - lo) / 2 * np.sin(np.outer(t, rate) + phase)
    return Q, [robot.fk(q) for q in Q]


@pytest.mark.parametrize(("name", "seed", "options", "step_factor"), [
    ("panda", 1, {}, 10.0),  # FRDM alone, rest term on (7 joints)
    ("ur5", 2, {"polish": True}, 3.0),  # FRDM crawls at ur5's near-singular samples: the LM polish ends them
])
def test_the_follower_reaches_every_sample_of_a_smooth_path(name, seed, options, step_factor):
    robot = load(name)
    Q, targets = smooth_path(robot, seed)
    res = kinelab.track(robot, targets, Q[0], **options)
    assert res.q.shape == (2000, robot.n)
    assert res.reached.all(), [(k, res.status[k]) for k in np.flatnonzero(~res.reached)[:5]]
    for k in range(0, 2000, 97):  # the verdict is Pinocchio's: check a spread of samples again here
        dp, dr = robot.tool_error(res.q[k], targets[k])
        assert dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(res.q[k])
    path_step = np.abs(np.diff(Q, axis=0)).max()
    assert res.max_joint_step <= step_factor * path_step  # no branch jump
    assert res.mode == ("frdm+lm (compiled follower)" if options else "frdm (compiled follower)")


def test_the_follower_reports_an_unreachable_sample_and_carries_on():
    robot = load("ur5")
    Q, targets = smooth_path(robot, 3, samples=60)
    targets[30] = pin.SE3(targets[30].rotation, np.array([5.0, 0.0, 0.0]))  # 5 m out: beyond the UR5's reach
    res = kinelab.track(robot, targets, Q[0], polish=True)
    assert not res.reached[30] and res.status[30] != "converged"
    assert res.position_error[30] > 4.0
    assert res.reached[40:].all()  # within ten samples it is back on the path


def test_bad_targets_are_named_by_index():
    robot = load("ur5")
    Q, targets = smooth_path(robot, 3, samples=5)
    targets[3] = "not a pose"
    with pytest.raises(TargetError, match=r"targets\[3\]"):
        kinelab.track(robot, targets, Q[0])
    with pytest.raises(TargetError, match="empty"):
        kinelab.track(robot, [], Q[0])
    homogeneous = np.array([t.homogeneous for t in targets[:3]])
    homogeneous[1, 0, 3] = np.nan
    with pytest.raises(TargetError, match=r"targets\[1\]"):
        kinelab.track(robot, homogeneous, Q[0])
