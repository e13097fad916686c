"""``WholeBody.step_batch``: N worlds a call. Each world's answer is the single step's from its q with its targets
(the same problem), whatever the threads; bad arrays are named; a problem the compiled step does not take steps
each world by the readable step."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.wholebody import ComTask, FrameTask, Limits, PostureTask, WholeBody
from kinelab.wholebody.subject import as_robot
from kinelab.wholebody.worlds import Worlds


@pytest.fixture(scope="module")
def panda():
    return as_robot(kinelab.load("panda"))


def _problem(robot, limits=None):
    q = robot.neutral()
    tasks = [FrameTask(robot.hands[0], robot.frame_placement(q, robot.hands[0])), PostureTask(q.copy(), weight=1e-3)]
    return WholeBody(robot, tasks, limits=limits or Limits())


def _draws(robot, n, seed):
    rng = np.random.default_rng(seed)
    Q = np.array([robot.random_q(rng) for _ in range(n)])
    H = np.array([robot.frame_placement(robot.random_q(rng), robot.hands[0]).homogeneous for _ in range(n)])
    return Q, H


def _one_by_one(problem, Q, H, dt):
    """Each world by the single step, its target set first (the reference the batch must equal)."""
    out = []
    for q, h in zip(Q, H, strict=True):
        problem.set_target(0, pin.SE3(h))
        out.append(problem.step(q, dt))
    return out


def test_each_world_is_the_single_step_from_its_q_toward_its_target(panda):
    """32 worlds, each a random q and a random reachable target: q and v per world equal the single compiled step's
    to 1e-9 (same code; a warm start may change DAQP's path, not its answer), every world solved."""
    problem = _problem(panda)
    assert problem.compiled
    Q, H = _draws(panda, 32, 0)
    batch = problem.step_batch(Q, 0.01, targets={0: H})
    singles = _one_by_one(_problem(panda), Q, H, 0.01)
    assert batch.solved.all() and batch.status == ["solved"] * 32
    for w, res in enumerate(singles):
        assert np.abs(batch.v[w] - res.v).max() <= 1e-9 * max(1.0, np.abs(res.v).max())
        assert np.abs(batch.q[w] - res.q).max() <= 1e-9


def test_the_answers_do_not_depend_on_the_threads(panda):
    problem = _problem(panda)
    Q, H = _draws(panda, 20, 1)
    one, two = Worlds(problem, threads=1), Worlds(problem, threads=2)
    a, b = one.step(Q, 0.01, {0: H}, None), two.step(Q, 0.01, {0: H}, None)
    assert np.abs(a.q - b.q).max() <= 1e-12 and (a.flags == b.flags).all()


def test_worlds_converge_on_their_own_targets_by_pinocchio(panda):
    """16 worlds, each from a random q toward the hand pose of a q within 0.3 rad of it (reachable on a short
    path; both 0.2 rad inside the limits), the posture in the null space: stepped 300 times at dt = 0.02 s,
    every hand within 1e-6 m of its own target by Pinocchio's FK, every step within the joint limits."""
    rng = np.random.default_rng(2)
    lo, hi = panda.lower + 0.2, panda.upper - 0.2  # starts and targets 0.2 rad inside the limits
    Q = lo + (hi - lo) * rng.random((16, panda.nq))
    near = np.clip(Q + rng.uniform(-0.3, 0.3, Q.shape), lo, hi)
    H = np.array([panda.frame_placement(q, panda.hands[0]).homogeneous for q in near])
    hand = FrameTask(panda.hands[0], pin.SE3(H[0]))
    problem = WholeBody(panda, [hand, PostureTask(panda.neutral(), priority=2)])
    for _ in range(300):
        Q = problem.step_batch(Q, 0.02, targets=[(hand, H)]).q
        assert all(panda.within_limits(q) for q in Q)
    model, data = panda.model, panda.model.createData()
    fid = model.getFrameId(panda.hands[0])
    for q, h in zip(Q, H, strict=True):
        pin.framesForwardKinematics(model, data, q)
        assert np.linalg.norm(data.oMf[fid].translation - h[:3, 3]) <= 1e-6


def test_a_centre_of_mass_target_per_world_on_a_humanoid():
    """TALOS, feet held, the centre of mass moved per world by (N, 3) points: each world's answer is the single
    step's with its ComTask moved there (1e-9)."""
    talos = kinelab.load("talos")
    q0 = talos.standing()
    feet = [FrameTask(f, talos.frame_placement(q0, f)) for f in talos.feet]
    com = ComTask(talos.com(q0))
    problem = WholeBody(talos, [*feet, com, PostureTask(q0, weight=1e-3)])
    assert problem.compiled
    points = talos.com(q0) + np.random.default_rng(3).uniform(-0.03, 0.03, (6, 3))
    Q = np.repeat(q0[None], 6, axis=0)
    batch = problem.step_batch(Q, 0.01, targets=[(com, points)])  # a ComTask holds an array: no dict key
    for w in range(6):
        single = WholeBody(talos, [*feet, ComTask(points[w]), PostureTask(q0, weight=1e-3)]).step(q0, 0.01)
        assert np.abs(batch.q[w] - single.q).max() <= 1e-9


def test_a_problem_the_compiled_step_does_not_take_steps_each_world_readably(panda):
    """With a user's inequality (no compiled block) every world is the readable single step with its target."""
    from test_inequalities import AtLeast

    limits = Limits(inequalities=(AtLeast(panda.joint_names[3], -1.0),))
    problem = _problem(panda, limits)
    assert not problem.compiled
    Q, H = _draws(panda, 4, 4)
    Q[:, 3] = np.clip(Q[:, 3], -0.9, None)
    batch = problem.step_batch(Q, 0.01, targets={0: H})
    singles = _one_by_one(_problem(panda, limits), Q, H, 0.01)
    for w, res in enumerate(singles):
        assert np.abs(batch.q[w] - res.q).max() <= 1e-9 and batch.solved[w] == res.solved


@pytest.mark.parametrize("bad", [np.zeros((3, 5)), np.full((2, 7), np.nan), "q", np.zeros((0, 7))])
def test_bad_configurations_are_named(panda, bad):
    with pytest.raises(kinelab.OptionError, match="one row per world"):
        _problem(panda).step_batch(bad, 0.01)


def test_bad_targets_are_named(panda):
    problem = _problem(panda)
    Q, H = _draws(panda, 3, 5)
    with pytest.raises(kinelab.KinelabError, match="N = 3"):
        problem.step_batch(Q, 0.01, targets={0: H[:2]})
    H[1, :3, :3] *= 2.0
    with pytest.raises(kinelab.KinelabError, match="world 1"):
        problem.step_batch(Q, 0.01, targets={0: H})
    with pytest.raises(kinelab.OptionError, match="a task with a target"):
        problem.step_batch(Q, 0.01, targets={1: H})
    with pytest.raises(kinelab.OptionError, match="task"):
        problem.step_batch(Q, 0.01, targets={7: H})


def test_the_worlds_bench_steps_every_world_compiled_and_names_an_unknown_robot(capsys):
    """``kinelab bench --worlds``: the Panda's 1,024 worlds, every world solved by the compiled step in every call;
    a robot without a scenario is refused in one line naming the valid ones."""
    import json

    from kinelab import cli

    assert cli.main(["bench", "--worlds", "--robots", "panda", "--repeats", "1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["worlds"]["rows"]
    assert [(r["robot"], r["worlds"], r["compiled"], r["unsolved"]) for r in rows] == [("panda", 1024, True, 0)]
    assert cli.main(["bench", "--worlds", "--robots", "ur5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'ur5'" in err[0] and "g1" in err[0]


def test_a_robot_with_folded_mimic_joints_steps_each_world_as_the_single_step_does():
    """Romeo (22 mimic joints Pinocchio cannot build, held as couplings the compiled step packs): 3 worlds whose
    rows are off the couplings (the followers moved by 0.1 rad) and whose left hands move by their own targets —
    each world's q equals the single step's (which starts on the couplings) to 1e-9; the caller's Q is unchanged."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        romeo = kinelab.load("romeo")
    q0 = romeo.standing()
    tasks = [FrameTask(f, romeo.frame_placement(q0, f)) for f in romeo.hands + romeo.feet]
    problem = WholeBody(romeo, [*tasks, PostureTask(q0, weight=1e-3)])
    assert problem.compiled and len(problem.loops) == 22
    followers = [romeo.model.joints[romeo.model.getJointId(m.name)].idx_q for m in romeo.mimics]
    Q = np.repeat(q0[None], 3, axis=0)
    Q[:, followers] += 0.1
    given = Q.copy()
    H = np.repeat(romeo.frame_placement(q0, romeo.hands[0]).homogeneous[None], 3, axis=0)
    H[:, :3, 3] += np.random.default_rng(6).uniform(-0.02, 0.02, (3, 3))
    batch = problem.step_batch(Q, 0.01, targets={0: H})
    assert np.array_equal(Q, given)
    for w in range(3):
        single = WholeBody(romeo, [FrameTask(romeo.hands[0], pin.SE3(H[w])), *tasks[1:],
                                   PostureTask(q0, weight=1e-3)]).step(Q[w], 0.01)
        assert batch.solved[w] and np.abs(batch.q[w] - single.q).max() <= 1e-9
