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
    res = kinelab.track(robot, targets, q0=Q[0], **options)
    assert res.q.shape == (2000, robot.n)
    assert res.reached.all(), [(k, res.status[k]) for k in np.flatnonzero(~res.reached)[:5]]
    for k in range(0, 2000, 97):  # the verdict is Pinocchio's: check a spread of samples again here
        dp, dr = robot.tool_error(res.q[k], targets[k])
        assert dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(res.q[k])
    path_step = np.abs(np.diff(Q, axis=0)).max()
    assert res.max_joint_step <= step_factor * path_step  # no branch jump
    assert res.mode == ("frdm+newton+lm (compiled follower)" if options else "frdm+newton (compiled follower)")


def test_the_follower_reports_an_unreachable_sample_and_carries_on():
    robot = load("ur5")
    Q, targets = smooth_path(robot, 3, samples=60)
    targets[30] = pin.SE3(targets[30].rotation, np.array([5.0, 0.0, 0.0]))  # 5 m out: beyond the UR5's reach
    # a coarse path (here and below): its own steps pass the default jump_limit (#57), not what this checks
    res = kinelab.track(robot, targets, q0=Q[0], polish=True, jump_limit=None)
    assert not res.reached[30] and res.status[30] != "converged"
    assert res.position_error[30] > 4.0
    assert res.reached[40:].all()  # within ten samples it is back on the path


def test_the_follower_keeps_its_time_budget_and_leaves_the_samples_after_it_unsolved():
    """#32: the compiled follower looks at the clock before every sample. A budget that has passed before the first
    sample leaves every sample unstarted (NaN, status time_budget); none is passed off as reached."""
    robot = load("ur5")
    Q, targets = smooth_path(robot, 4, samples=50)
    res = kinelab.track(robot, targets, q0=Q[0], time_budget=1e-9)
    assert np.isnan(res.q).all() and set(res.status) == {"time_budget"} and not res.reached.any()
    full = kinelab.track(robot, targets, q0=Q[0], time_budget=None, jump_limit=None)
    assert full.reached.all() and not np.isnan(full.q).any()


def test_bad_targets_are_named_by_index():
    robot = load("ur5")
    Q, targets = smooth_path(robot, 3, samples=5)
    targets[3] = "not a pose"
    with pytest.raises(TargetError, match=r"targets\[3\]"):
        kinelab.track(robot, targets, q0=Q[0])
    with pytest.raises(TargetError, match="empty"):
        kinelab.track(robot, [], q0=Q[0])
    homogeneous = np.array([t.homogeneous for t in targets[:3]])
    homogeneous[1, 0, 3] = np.nan
    with pytest.raises(TargetError, match=r"targets\[1\]"):
        kinelab.track(robot, homogeneous, q0=Q[0])


def _own_verdict(robot, q, target, task="pose", tol=1e-6):
    """The test's own check: Pinocchio's FK of q against the target on the task's components, within the limits."""
    err = target.actInv(robot.fk(q))
    dp = np.linalg.norm(robot.fk(q).translation - target.translation)
    dr = np.linalg.norm(pin.log3(err.rotation))
    return (dp <= tol or task == "orientation") and (dr <= tol or task == "position") and robot.within_limits(q)


def test_the_monitored_path_reports_only_what_pinocchio_confirms():
    """kinelab 0.1: a monitored sample's status was the solver's own (16 of 20 'reached' with rotation errors up
    to 3.1 rad when FRDM's mode was position while the task was the pose)."""
    robot = load("ur5")
    Q, targets = smooth_path(robot, 5, samples=20, amplitude=0.9)
    res = kinelab.track(robot, targets, q0=Q[0], policy=(), mode="position")
    assert res.reached.sum() < 20  # the rotation is not met by a position-only FRDM
    for k in range(20):
        assert res.reached[k] == _own_verdict(robot, res.q[k], targets[k]), k


def test_a_sample_outside_the_limits_is_not_reached_even_when_the_solver_may_leave_them():
    robot = load("ur5")
    Q, targets = smooth_path(robot, 6, samples=30, amplitude=0.95)
    res = kinelab.track(robot, targets, q0=Q[0], policy=(), use_limits=False, jump_limit=None)
    outside = [k for k in range(30) if not robot.within_limits(res.q[k])]
    assert all(not res.reached[k] for k in outside)
    assert all(res.reached[k] == _own_verdict(robot, res.q[k], targets[k]) for k in range(30))


@pytest.mark.parametrize("bad", [{"tol_pos": float("inf")}, {"tol_rot": 0.0}, {"tol_pos": -1.0},
                                 {"max_sweeps": -3}, {"hold": 1.5}, {"rest_weight": float("nan")},
                                 {"jump_limit": 0.0}, {"restrict": "freeze"}, {"solver": "dls"}])
def test_track_refuses_bad_arguments_by_name(bad):
    robot = load("ur5")
    Q, targets = smooth_path(robot, 3, samples=3)
    with pytest.raises(kinelab.OptionError, match=next(iter(bad))):
        kinelab.track(robot, targets, q0=Q[0], **bad)


@pytest.mark.parametrize("seed", range(6))
def test_every_reached_sample_is_met_whatever_the_options(seed):
    """A property test over random options, monitored loop and follower alike: 'reached' is Pinocchio's verdict."""
    rng = np.random.default_rng(seed)
    robot = load(["ur5", "panda", "so101"][seed % 3])
    task = ["pose", "position", "axis"][rng.integers(3)] if robot.n >= 6 else "position"
    options = {"policy": (), "use_limits": bool(rng.integers(2)), "order": ["tip2base", "base2tip"][rng.integers(2)],
               "polish": bool(rng.integers(2))}
    if rng.integers(2):
        options = {"polish": options["polish"]}  # the compiled follower
    Q, targets = smooth_path(robot, seed, samples=25, amplitude=0.8)
    tol = float(rng.choice([1e-6, 1e-4]))
    res = kinelab.track(robot, targets, q0=Q[0], task=task, tol_pos=tol, tol_rot=tol, **options)
    axis_task = task == "axis"
    for k in range(25):
        q, target = res.q[k], targets[k]
        dp = np.linalg.norm(robot.fk(q).translation - target.translation)
        if axis_task:
            u, v = robot.fk(q).rotation[:, 2], target.rotation[:, 2]
            dr = np.arctan2(np.linalg.norm(np.cross(u, v)), u @ v)
        else:
            dr = np.linalg.norm(pin.log3(target.rotation.T @ robot.fk(q).rotation))
        met = dp <= tol and (task == "position" or dr <= tol) and robot.within_limits(q)
        # since #57 a sample met by a step beyond jump_limit is not reached either (status jump)
        assert res.reached[k] == (met and res.status[k] != "jump"), (k, task, options, dp, dr)
        assert res.status[k] != "jump" or met


def test_the_compiled_follower_reports_a_jump_as_the_monitored_loop_does():
    """#39 item 4: a step above jump_limit is an event in the result on the compiled path too (it had none)."""
    ur5 = kinelab.load("ur5")
    a, b = ur5.random_q(1), ur5.random_q(2)
    path = [ur5.fk(a), ur5.fk(a), ur5.fk(b)]  # two samples apart by whole radians: a jump the path asks for
    for policy in (None, ("auto_kick",)):
        res = kinelab.track(ur5, path, q0=a, policy=policy)
        assert res.mode.endswith("(compiled follower)") == (policy is None)
        jumps = [e for e in res.events if e.trigger == "jump"]
        step = np.abs(res.q[2] - res.q[1]).max()
        assert step > 0.2 and [e.sample for e in jumps] == [2] and jumps[0].max_joint_step == pytest.approx(step)
    quiet = kinelab.track(ur5, path, q0=a, jump_limit=None)
    assert not [e for e in quiet.events if e.trigger == "jump"]
