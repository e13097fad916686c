"""#68: a whole-body problem prepared once (kinelab.WholeBody): its step is kinelab.step's, set_target moves one
target without packing again and answers as a problem made anew with that target, and the function's kept
problems answer for the tasks they are given."""

import sys

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import ComTask, DampingTask, FrameTask, Limits, PostureTask, WholeBody

STEP = sys.modules.get("kinelab.wholebody.step") or __import__("kinelab.wholebody.step", fromlist=["_step"])
HANDS = ("arm_left_7_link", "arm_right_7_link")
FEET = ("left_sole_link", "right_sole_link")


@pytest.fixture(scope="module")
def talos():
    return kinelab.load("talos")


def tasks_of(robot, q, shift=0.0):
    hands = [FrameTask(h, pin.SE3(robot.frame_placement(q, h).rotation,
                                  robot.frame_placement(q, h).translation + np.array([shift, 0.05, 0.0])))
             for h in HANDS]
    feet = [FrameTask(f, robot.frame_placement(q, f)) for f in FEET]
    return [*hands, *feet, ComTask(robot.com(q), axes="xy"), PostureTask(q, priority=2), DampingTask(1e-4)]


def test_a_problems_step_is_the_functions_and_the_readable_steps(talos):
    q = talos.neutral()
    tasks = tasks_of(talos, q)
    problem = WholeBody(talos, tasks)
    assert problem.compiled
    a, b = problem.step(q, 0.01), kinelab.step(talos, q, tasks, 0.01)
    slow = STEP._step(talos, q, tuple(tasks), 0.01, Limits(), STEP.DEFAULT_OPTIONS, None)
    assert np.abs(a.v - b.v).max() <= 1e-12 and np.abs(a.v - slow.v).max() <= 1e-6
    assert [e.label for e in a.errors] == [t.label for t in tasks]


def test_set_target_moves_one_target_as_a_problem_made_anew_would(talos):
    rng = np.random.default_rng(3)
    q = talos.neutral()
    problem = WholeBody(talos, tasks_of(talos, q))
    for k in range(20):
        hand = problem.tasks[k % 2]
        target = pin.SE3(hand.target.rotation, hand.target.translation + rng.normal(scale=0.02, size=3))
        moved = problem.set_target(hand, target)
        assert moved is problem.tasks[k % 2] and moved.target == target
        fresh = WholeBody(talos, list(problem.tasks))
        a, b = problem.step(q, 0.01), fresh.step(q, 0.01)
        assert np.abs(a.v - b.v).max() <= 1e-6 * max(1.0, np.abs(b.v).max())  # the QP's warm start aside
        q = a.q
    com = problem.set_target(4, talos.com(q) + np.array([0.01, 0.0, 0.0]))
    assert np.allclose(com.target, talos.com(q) + np.array([0.01, 0.0, 0.0]))
    with pytest.raises(kinelab.KinelabError, match="has none to move"):
        problem.set_target(6, np.zeros(3))  # the damping
    with pytest.raises(kinelab.KinelabError, match="one of this problem's tasks"):
        problem.set_target(FrameTask(HANDS[0], pin.SE3.Identity()), pin.SE3.Identity())


def test_the_functions_kept_problem_answers_for_each_list_it_is_given(talos):
    """Lists of one structure taken turn about, limits made anew each call: each call answers for its own list
    (the readable step is the judge)."""
    q = talos.neutral()
    lists = [tasks_of(talos, q, shift) for shift in (0.0, 0.03, -0.03)]
    for _ in range(3):
        for tasks in lists:
            limits = Limits(acceleration=4.0)
            v_prev = np.zeros(talos.nv)
            fast = kinelab.step(talos, q, tasks, 0.01, limits=limits, v_prev=v_prev)
            slow = STEP._step(talos, q, tuple(tasks), 0.01, limits, STEP.DEFAULT_OPTIONS, v_prev)
            assert np.abs(fast.v - slow.v).max() <= 1e-6


def test_a_problems_solve_judges_its_tasks(talos):
    rng = np.random.default_rng(8)
    q_true = talos.random_q(rng)
    q_true[:7] = talos.neutral()[:7]
    tasks = [FrameTask(f, talos.frame_placement(q_true, f)) for f in (*HANDS, *FEET)]
    res = WholeBody(talos, tasks).solve(q0=talos.neutral(), seed=0, time_budget=None, max_restarts=100)
    assert res.success
    for task, verdict in zip(tasks, res.tasks, strict=True):
        M = talos.frame_placement(res.q, task.frame)
        assert np.linalg.norm(M.translation - task.target.translation) <= 1e-6 and verdict.met


def test_bad_problems_are_refused_by_name(talos):
    with pytest.raises(kinelab.ChainError, match="whole robot .* or a chain"):
        WholeBody(kinelab.load("panda").model, [ComTask([0, 0, 0])])
    with pytest.raises(kinelab.FrameNotFoundError):
        WholeBody(talos, [FrameTask("no_such_frame", pin.SE3.Identity())])
    with pytest.raises(kinelab.KinelabError, match="limits"):
        WholeBody(talos, [ComTask([0, 0, 0])], limits="tight")
    problem = WholeBody(talos, [ComTask([0, 0, 0.8])])
    with pytest.raises(kinelab.KinelabError, match="same kinds"):
        problem.retarget([ComTask([0, 0, 0.8], axes="xy")])


def test_a_problem_says_which_step_answers_and_why(talos):
    from kinelab import StepOptions

    assert WholeBody(talos, [ComTask([0, 0, 0.8])]).route.startswith("compiled")
    assert "proxsuite" in WholeBody(talos, [ComTask([0, 0, 0.8])], options=StepOptions(solver="proxsuite")).route
    two = WholeBody(talos, [PostureTask(), PostureTask(weight=1e-2)])
    assert not two.compiled and "two postures" in two.route


def test_a_robot_stands_on_its_feet_and_its_named_poses_too(talos):
    """#72 item 4: kinelab.standing(talos) is the SRDF's half_sitting with the soles on the floor (z = 0, 1e-12),
    as is named_q("half_sitting"); a robot with loops stands with them closed; a chain is refused by name."""
    q = kinelab.standing(talos)
    assert np.allclose(q, talos.named_q("half_sitting"))
    soles = [M.translation[2] for M in talos.frame_placements(q, talos.feet)]
    assert min(soles) == pytest.approx(0.0, abs=1e-12) and q[2] > 0.9
    delta = kinelab.load("delta")
    assert np.abs(delta.closure_error(kinelab.standing(delta))).max() <= 1e-10
    with pytest.raises(kinelab.ChainError, match="whole robot"):
        kinelab.standing(kinelab.load("panda"))
