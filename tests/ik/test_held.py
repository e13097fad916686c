"""Solver "analytic" on 7R arms (kinelab.ik.analytic.held): the six other joints in closed form with the swept end
joint held at the start's value (else at samples of its range, else FRDM), each answer judged by Pinocchio."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from helpers import assert_meets_pose, turn_gap

import kinelab
from kinelab.ik.analytic import held
from kinelab.ik.analytic.redundancy import swept_arm


def _set(name, count, seed):
    robot = kinelab.load(name)
    rng = np.random.default_rng(seed)
    Q, starts = robot.random_qs(count, rng), robot.random_qs(count, rng)
    return robot, Q, starts


@pytest.mark.parametrize("name", ["panda", "era"])
def test_every_row_meets_its_pose_by_pinocchio_within_the_limits(name):
    robot, Q, starts = _set(name, 300, 1)
    res = kinelab.solve_batch(robot, robot.fk_batch(Q), solver="analytic", q0=starts)
    assert res.success.all() and res.solver == "analytic" and "held at the start's value" in res.mode
    for q, target in zip(res.q, robot.fk_batch(Q), strict=True):
        assert robot.within_limits(q)
        assert_meets_pose(robot, [q], pin.SE3(target), 1e-6)


@pytest.mark.parametrize("name", ["panda", "era"])
def test_a_row_solved_at_the_start_s_value_is_the_branch_there_nearest_the_start(name):
    """Where the start's own value of the swept joint has a branch, the answer holds the joint exactly there and is
    the branch nearest the start among every branch solve_all(redundancy=) finds at that value."""
    robot, Q, starts = _set(name, 40, 2)
    j = swept_arm(robot).joint
    res = kinelab.solve_batch(robot, robot.fk_batch(Q), solver="analytic", q0=starts)
    first = np.flatnonzero(res.iterations == 0)  # solved at the first value tried: the start's own
    assert first.size >= 5
    for b in first:
        assert res.q[b, j] == starts[b, j]
        target = robot.fk(Q[b])
        every = kinelab.solve_all(robot, target, redundancy={robot.joints[j].name: float(starts[b, j])})
        gaps = [turn_gap(branch.q, starts[b]) for branch in every]
        assert turn_gap(res.q[b], starts[b]) <= min(gaps) + 1e-9
        assert min(turn_gap(res.q[b], branch.q) for branch in every) <= 1e-9


def test_the_single_call_is_the_batch_s_row():
    robot, Q, starts = _set("panda", 30, 3)
    H = robot.fk_batch(Q)
    batch = kinelab.solve_batch(robot, H, solver="analytic", q0=starts)
    ik = kinelab.IK(robot, solver="analytic")
    answered = np.flatnonzero(~np.isnan(held.held_rows(robot, H, starts, ik.request)[0][:, 0]))
    assert answered.size >= 25
    for b in answered:  # the rows the closed form answers (the others go to FRDM)
        one = kinelab.solve(robot, pin.SE3(H[b]), solver="analytic", q0=starts[b])
        assert one.success and one.solver == "analytic" and one.q.tobytes() == batch.q[b].tobytes()
        assert ik.solve(pin.SE3(H[b]), q0=starts[b]).q.tobytes() == batch.q[b].tobytes()


def test_rows_no_held_value_solves_go_to_frdm_and_say_so(monkeypatch):
    monkeypatch.setattr(held, "SAMPLES", 1)  # the start's value and the middle only: some rows left over
    robot, Q, starts = _set("panda", 200, 4)
    res = kinelab.solve_batch(robot, robot.fk_batch(Q), solver="analytic", q0=starts)
    frdm = int(res.mode.split("; ")[-1].split(" of ")[0])
    assert res.success.all() and 0 < frdm < 200 and res.mode.endswith("rows by FRDM (no branch at any value tried)")


def test_an_arm_whose_six_hold_only_within_tolerance_is_refused_by_name_and_collisions_too():
    xarm7 = kinelab.load("xarm7")
    assert not held.applies(xarm7) and "fell short of 1e-6" in held.refusal(xarm7)
    with pytest.raises(kinelab.OptionError, match="solver"):
        kinelab.solve(xarm7, xarm7.fk(xarm7.random_q(0)), solver="analytic")
    panda = kinelab.load("panda")
    with pytest.raises(kinelab.OptionError, match="collisions"):
        kinelab.solve_batch(panda, panda.fk_batch(panda.random_qs(3, 0)), solver="analytic", collisions="self")
    with pytest.raises(kinelab.OptionError, match="task"):
        kinelab.solve(panda, panda.fk(panda.random_q(0)), solver="analytic", task="position")


def test_sub_targets_turn_the_pose_as_the_swept_form_does():
    """The vectorised turn of every row against SweptArm.sub_target one at a time, and the six's FK at the pose's
    own six angles reaching it (Pinocchio's FK of the arm with the joint locked)."""
    for name in ("panda", "era"):
        robot, Q, _ = _set(name, 10, 5)
        sw, six = swept_arm(robot), held.held_robot(robot)
        keep = np.arange(7) != sw.joint
        H = robot.fk_batch(Q)
        mine = held.sub_targets(sw, H, Q[:, sw.joint])
        for b in range(10):
            np.testing.assert_allclose(mine[b], sw.sub_target(H[b], Q[b, sw.joint]), atol=1e-12)
            np.testing.assert_allclose(six.fk(Q[b, keep]).homogeneous, mine[b], atol=1e-12)
