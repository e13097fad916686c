"""#71 goal 3: the default follower never jumps on the trust issues' Panda path — it follows the path back from
where it jumped to and forward again drawn towards it (kinelab.ik.frdm.rejoin) — and the draw itself keeps a
redundant arm on the configurations it is given."""

import numpy as np
import pinocchio as pin
from helpers import cosine_path

import kinelab
from kinelab.ik.chain import chain_model
from kinelab.ik.frdm import rejoin
from kinelab.ik.frdm.follower import follow
from kinelab.ik.frdm.options import FRDMOptions
from kinelab.ik.result import Status, TrackResult
from kinelab.ik.targets import TargetArrays


def _trust_path(panda):
    return cosine_path(panda, np.random.default_rng(4))


def test_the_issues_panda_path_with_seed_3_is_met_without_a_jump():
    """Before the rejoin: 1,999 of 2,000 samples met, joint 1 in its limit at sample 1,449 and a 2.2 rad jump (a
    step 1,044 times the path's own largest). Every sample is now met by Pinocchio's judge within the limits, and no
    joint step is above 3 times the path's own largest."""
    panda = kinelab.load("panda")
    path = _trust_path(panda)
    targets = panda.fk_batch(path)
    res = kinelab.track(panda, targets, q0=path[0], seed=3)
    assert res.success.all() and res.path_success
    assert not (res.status == Status.JUMP).any()
    assert all(panda.within_limits(q) for q in res.q)
    for q, target in zip(res.q[::97], targets[::97], strict=True):
        assert max(panda.tool_error(q, pin.SE3(target))) <= 1e-6
    steps = np.abs(np.diff(np.vstack([path[:1], res.q]), axis=0)).max()
    assert steps <= 3 * np.abs(np.diff(path, axis=0)).max()


def _follow(robot, path, toward=None):
    targets = robot.fk_batch(path)
    arrays = TargetArrays(np.ascontiguousarray(targets[:, :3, 3]), np.ascontiguousarray(targets[:, :3, :3]))
    chain_model(robot)
    return follow(robot, arrays, path[0], 1e-6, 1e-6, 200, None, FRDMOptions(), seed=0, toward=toward)


def test_a_redundant_arm_drawn_towards_the_paths_own_configurations_stays_on_them():
    """Pushed from its limits, the follower's self-motion leaves the trust path's (0.3 rad and more apart by the
    path's middle); drawn towards the path's own configurations it stays within 0.05 rad of them, every sample
    met."""
    panda = kinelab.load("panda")
    path = _trust_path(panda)[:1000]
    pushed, drawn = _follow(panda, path), _follow(panda, path, toward=path)
    assert np.abs(pushed.q - path).max() > 0.3
    assert (drawn.status_code == Status.CONVERGED.code).all()
    assert np.abs(drawn.q - path).max() < 0.05


def test_nan_rows_of_toward_leave_those_samples_to_the_push():
    panda = kinelab.load("panda")
    path = _trust_path(panda)[:600]
    toward = np.full_like(path, np.nan)
    toward[:200] = path[:200]
    pushed, mixed = _follow(panda, path), _follow(panda, path, toward=toward)
    assert np.abs(mixed.q[:200] - path[:200]).max() < 0.05
    assert np.abs(mixed.q[300:] - pushed.q[300:]).max() > 0  # the push from there on, from where the draw left it


def _result(Q, met=None):
    count = Q.shape[0]
    codes = np.full(count, Status.CONVERGED.code, dtype=np.int8)
    if met is not None:
        codes[~met] = Status.MAX_ITERATIONS.code
    zeros = np.zeros(count)
    return TrackResult(Q, zeros, zeros, codes, np.zeros(count, dtype=np.int64), zeros)


def test_a_rejoin_whose_backward_path_jumps_keeps_the_first_path():
    line = np.linspace(0, 1, 11)[:, None] * np.ones((1, 2))
    jumped = line.copy()
    jumped[6:] += 1.0  # a 1 rad jump at sample 6
    calls = []

    def run(targets, start, toward):
        calls.append(toward)
        return _result(np.vstack([start[None, :], start[None, :] + 2.0] + [start[None, :]] * 5))  # jumps back too

    targets = TargetArrays(np.zeros((11, 3)), np.tile(np.eye(3), (11, 1, 1)))
    first = _result(jumped)
    assert rejoin.first_jump(first, np.zeros(2), 0.2) == 6
    assert rejoin.rejoined(targets, np.zeros(2), first, 0.2, run) is first
    assert len(calls) == 1 and calls[0] is None  # the backward pass only: no forward pass drawn towards a jump


def test_a_rejoin_that_meets_fewer_samples_is_not_kept():
    line = np.linspace(0, 1, 11)[:, None] * np.ones((1, 2))
    jumped = line.copy()
    jumped[6:] += 1.0

    def run(targets, start, toward):
        count = targets.points.shape[0]
        if toward is None:  # the backward pass: smooth, every sample met
            return _result(start[None, :] - np.linspace(0, 0.5, count)[:, None])
        met = np.ones(count, dtype=bool)
        met[3:] = False
        return _result(line, met)

    targets = TargetArrays(np.zeros((11, 3)), np.tile(np.eye(3), (11, 1, 1)))
    first = _result(jumped)
    assert rejoin.rejoined(targets, np.zeros(2), first, 0.2, run) is first
    assert rejoin.rejoined(targets, np.zeros(2), first, None, run) is first  # no jump limit: no jumps to undo


def _run_at(robot):
    chain_model(robot)

    def run(targets, start, toward):
        return follow(robot, targets, start, 1e-6, 1e-6, 200, None, FRDMOptions(), seed=0, toward=toward)
    return run


def test_a_paths_pace_is_its_typical_joint_step():
    """A straight joint-space line moves its joints by the same step every sample: the pilot pass (one sample in ten)
    measures that step within a factor of two (the follower's own self-motion is not the line's)."""
    from helpers import joint_line

    from kinelab.ik.frdm.follower import path_pace

    for name, seed in (("panda", 0), ("xarm7", 1), ("baxter_left", 2)):
        robot = kinelab.load(name)
        path = joint_line(robot, np.random.default_rng(seed))
        own = np.abs(np.diff(path, axis=0)).max()
        targets = robot.fk_batch(path)
        arrays = TargetArrays(np.ascontiguousarray(targets[:, :3, 3]), np.ascontiguousarray(targets[:, :3, :3]))
        pace = path_pace(arrays, path[0], _run_at(robot))
        assert 0.5 * own <= pace <= 2.0 * own, (name, pace, own)
        short = TargetArrays(arrays.points[:19], arrays.rotations[:19])
        assert path_pace(short, path[0], _run_at(robot)) == 0.0  # too short to measure: no pace
