"""#57 item 6: a tracked sample reached by a joint step larger than ``jump_limit`` is not a success (status
``jump``, the path's success False), and slow self-motion (drift along the task's null space beyond five times the
path's own largest step) is an event in the result."""

import numpy as np
import pytest
from helpers import cosine_path, joint_line

import kinelab
from kinelab.ik.result import Status


def assert_jumps_are_not_successes(res, q0, jump_limit=0.2):
    steps = np.abs(np.diff(np.vstack([q0, res.q]), axis=0)).max(axis=1)
    jumped = np.nan_to_num(steps) > jump_limit
    assert not res.success[jumped].any()
    assert (res.status[jumped & (res.position_error <= 1e-6)] != Status.CONVERGED).all()
    if jumped.any():
        assert not res.path_success


def test_a_path_the_follower_still_jumps_on_is_not_a_success():
    """The xArm7's joint-space line of seed 38 (400 samples), a path the rejoin does not undo: its jumps are marked,
    each sample reached by one is not a success, and neither is the path."""
    xarm7 = kinelab.load("xarm7")
    path = joint_line(xarm7, np.random.default_rng(38), samples=400)
    res = kinelab.track(xarm7, xarm7.fk_batch(path), q0=path[0], seed=38)
    assert_jumps_are_not_successes(res, path[0])
    assert (res.status == Status.JUMP).any() and not res.path_success


@pytest.mark.parametrize("name", ["era", "baxter_left", "xarm7", "panda"])
def test_on_joint_space_lines_every_jump_is_marked(name):
    """On aadeea0: era turned a joint 6.27 rad in one sample, baxter_left 6.12, xarm7 3.59, panda 1.50, each a
    success."""
    robot = kinelab.load(name)
    for seed in range(4):
        path = joint_line(robot, np.random.default_rng(seed))
        res = kinelab.track(robot, robot.fk_batch(path), q0=path[0], seed=seed)
        assert_jumps_are_not_successes(res, path[0])


def test_a_six_joint_arm_has_no_self_motion_events():
    ur5 = kinelab.load("ur5")
    path = joint_line(ur5, np.random.default_rng(1))
    res = kinelab.track(ur5, ur5.fk_batch(path), q0=path[0], seed=0)
    assert res.path_success and not [e for e in res.events if e.trigger == "self_motion"]


def test_the_monitored_loop_marks_jumps_too():
    panda = kinelab.load("panda")
    path = cosine_path(panda, np.random.default_rng(4), samples=300)
    res = kinelab.track(panda, panda.fk_batch(path), q0=path[0], seed=3, jump_limit=1e-4, restrict=(),
                        policy=("auto_kick",))
    assert "monitored" in res.mode
    assert_jumps_are_not_successes(res, path[0], jump_limit=1e-4)
    assert (res.status == Status.JUMP).any()


def test_self_motion_events_by_cumulative_sums_are_the_running_totals():
    """The drift summed since the last event, as a running total reset at each event (the definition), against the
    cumulative-sum search: the same samples, the same amounts to rounding."""
    import numpy as np

    from kinelab.ik.frdm import tracking

    rng = np.random.default_rng(5)
    for _ in range(20):
        drift = rng.normal(scale=0.05, size=(300, 7)) + rng.normal(scale=0.01, size=7)  # a steady drift, and noise
        largest = 0.05
        expected, total = [], np.zeros(7)
        for k in range(drift.shape[0]):
            total += drift[k]
            if np.abs(total).max() > tracking.SELF_MOTION * largest:
                expected.append((k, float(np.abs(total).max())))
                total[:] = 0.0
        found = tracking._drift_events(drift, largest)
        assert len(expected) >= 2
        assert [e.sample for e in found] == [k for k, _ in expected]
        assert np.allclose([e.max_joint_step for e in found], [m for _, m in expected], rtol=1e-9, atol=0)


def test_the_self_motion_events_made_when_read_are_the_paths_own():
    """The self-motion check runs when a path's events are first read: the events are those of the q the path
    returned (a change to ``res.q`` before the read does not move them), a pickle and a copy carry them, and events
    can still be set and appended to."""
    import copy
    import pickle

    from kinelab.ik.frdm import tracking
    from kinelab.ik.tasks import POSE

    panda = kinelab.load("panda")
    path = cosine_path(panda, np.random.default_rng(4))
    targets = panda.fk_batch(path)
    res = kinelab.track(panda, targets, q0=path[0], seed=3)
    returned_q = res.q.copy()
    res.q[:] = path[0]  # a user's change before reading the log
    drift = [e for e in res.events if e.trigger == "self_motion"]
    expected = tracking.self_motion_events(panda, returned_q, path[0], targets[:, :3, 3], targets[:, :3, :3], POSE)
    assert drift and [(e.sample, e.max_joint_step) for e in drift] == \
        [(e.sample, e.max_joint_step) for e in expected]
    again = kinelab.track(panda, targets, q0=path[0], seed=3)
    for made in (pickle.loads(pickle.dumps(again)), copy.deepcopy(again)):
        assert [e.sample for e in made.events if e.trigger == "self_motion"] == [e.sample for e in drift]
        assert "_make_events" not in vars(made)
    again.events.append(drift[0])
    assert again.events[-1] is drift[0]
    again.events = []
    assert again.events == []
