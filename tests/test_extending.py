"""docs/extending.md holds: its example task and inequality, defined on the page (not in kinelab), are stepped (and
the task solved) on TALOS and judged here by Pinocchio; the page names every method of both protocols."""

import re
from pathlib import Path

import numpy as np
import pinocchio as pin

import kinelab
from kinelab.wholebody import Inequality, Task

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", PAGE.read_text(), re.S)


def test_the_pages_toy_task_is_stepped_and_solved_by_its_own_methods(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    block = _blocks()[0]
    namespace: dict = {}
    exec(compile(block, "extending.md", "exec"), namespace)  # noqa: S102 - the page's own example
    talos, q, solved = namespace["talos"], namespace["q"], namespace["solved"]
    assert not namespace["problem"].compiled  # a task with no compiled block: the readable step answered
    model, data = talos.model, talos.model.createData()
    j = model.joints[model.getJointId("arm_left_4_joint")]
    assert abs(q[j.idx_q] + 1.2) <= 1e-3
    assert solved.success and abs(solved.q[j.idx_q] + 1.2) <= 1e-6
    start = talos.neutral()
    for q_end in (q, solved.q):
        pin.framesForwardKinematics(model, data, q_end)
        for foot in ("left_sole_link", "right_sole_link"):
            before = talos.frame_placement(start, foot)
            after = data.oMf[model.getFrameId(foot)]
            assert np.linalg.norm(after.translation - before.translation) <= 1e-5
        assert talos.within_limits(q_end)


def test_the_page_names_every_method_of_the_protocols():
    page = PAGE.read_text()
    methods = [name for name in vars(Task) if not name.startswith("_") and name not in ("uses_com", "preference",
                                                                                       "second")]
    methods += [name for name in vars(Inequality) if not name.startswith("_")]
    missing = [m for m in methods if f"`{m}" not in page]
    assert not missing, missing


def test_the_pages_inequality_keeps_the_hand_above_its_plane_at_every_step(monkeypatch, tmp_path):
    """The hand pulled 0.3 m down through a plane 0.1 m below it: by Pinocchio's FK it never goes more than 1e-6 m
    below the plane, ends on it (within 1 mm), the feet stay (1e-5 m); the same tasks without the inequality take the
    hand below the plane (so the rows are what holds it)."""
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(_blocks()[1], "extending.md", "exec"), namespace)  # noqa: S102 - the page's own example
    talos, q, table, start = namespace["talos"], namespace["q"], namespace["table"], namespace["start"]
    assert not namespace["held"].compiled and "inequalities" in namespace["held"].route
    model, data = talos.model, talos.model.createData()
    hand = model.getFrameId("gripper_left_base_link")
    assert min(namespace["heights"]) >= table - 1e-6
    pin.framesForwardKinematics(model, data, q)
    assert abs(data.oMf[hand].translation[2] - table) <= 1e-3
    for foot in ("left_sole_link", "right_sole_link"):
        after = data.oMf[model.getFrameId(foot)].translation
        assert np.linalg.norm(after - talos.frame_placement(start, foot).translation) <= 1e-5
    free = kinelab.WholeBody(talos, namespace["tasks"])
    q_free = start
    for _ in range(60):
        q_free = free.step(q_free, 0.05).q
    pin.framesForwardKinematics(model, data, q_free)
    assert data.oMf[hand].translation[2] < table - 0.1


def test_the_converged_solve_holds_an_inequality_and_says_when_its_answer_breaks_it():
    """A solve asked to put the hand below the plane with the plane held: no success, and the answer is not below
    the plane by more than 1e-6 m (Pinocchio); a target above it: success."""
    namespace: dict = {}
    exec(compile(_blocks()[1].split("q, heights")[0], "extending.md", "exec"), namespace)  # noqa: S102
    talos, table, above = namespace["talos"], namespace["table"], namespace["above"]
    limits = kinelab.Limits(velocity=None, inequalities=(above,))
    low = kinelab.solve(talos, namespace["tasks"], q0=namespace["start"], limits=limits, seed=0, max_restarts=0)
    assert not low.success
    assert talos.frame_placement(low.q, "gripper_left_base_link").translation[2] >= table - 1e-6
    hand = namespace["hand"]
    up = pin.SE3(hand.rotation, hand.translation + np.array([0.05, 0.0, 0.05]))
    tasks = [*namespace["feet"], kinelab.FrameTask("gripper_left_base_link", up, task="position")]
    high = kinelab.solve(talos, tasks, q0=namespace["start"], limits=limits, seed=0)
    assert high.success and talos.frame_placement(high.q, "gripper_left_base_link").translation[2] >= table


def test_a_limits_inequality_must_be_one():
    import pytest

    with pytest.raises(kinelab.OptionError, match="inequalities"):
        kinelab.Limits(inequalities=("above",))


def test_a_start_that_breaks_the_inequality_is_brought_back_not_frozen():
    """The page's plane 5 cm above the hand at the start (the start breaks it), the hand's task holding it where it
    is, a posture: the step brings the hand up — every step higher than the one before until it reaches the plane,
    never below it (1e-9) after, on it within 1e-6 m after 60 steps — instead of halving every step to nothing."""
    namespace: dict = {}
    exec(compile(_blocks()[1].split("talos = kinelab.load")[0], "extending.md", "exec"), namespace)  # noqa: S102
    talos = kinelab.load("talos")
    start = talos.neutral()
    hand = talos.frame_placement(start, "gripper_left_base_link")
    above = namespace["AbovePlane"]("gripper_left_base_link", hand.translation[2] + 0.05)
    feet = [kinelab.FrameTask(f, talos.frame_placement(start, f)) for f in ("left_sole_link", "right_sole_link")]
    tasks = [*feet, kinelab.FrameTask("gripper_left_base_link", hand, task="position"),
             kinelab.PostureTask(start, weight=1e-3)]  # the null space held: the hand moves as its rows say
    problem = kinelab.WholeBody(talos, tasks, limits=kinelab.Limits(inequalities=(above,)))
    q, heights = start, [hand.translation[2]]
    for _ in range(60):
        q = problem.step(q, 0.05).q
        heights.append(talos.frame_placement(q, "gripper_left_base_link").translation[2])
    reached = next(k for k, h in enumerate(heights) if h >= above.height - 1e-9)  # StopIteration: never came up
    assert all(b >= a - 1e-9 for a, b in zip(heights[:reached], heights[1:reached + 1], strict=True))  # rising
    assert min(heights[reached:]) >= above.height - 1e-9 and abs(heights[-1] - above.height) <= 1e-6
