"""solve_batch, Robot.fk_batch and Robot.jacobian_batch: the same answers as one at a time, on any thread count."""

import re

import numpy as np
import pytest

import kinelab
from kinelab import ConfigurationError, OptionError, TargetError, load
from kinelab.core import threads


def problems(robot, count, seed, sigma=None):
    rng = np.random.default_rng(seed)
    Q = robot.random_qs(count, rng)
    starts = None if sigma is None else np.clip(Q + rng.normal(0, sigma, Q.shape), robot.lower, robot.upper)
    return Q, [robot.fk(q) for q in Q], starts


@pytest.mark.parametrize(("name", "sigma"), [("ur5", None), ("panda", 0.2), ("stanford", None)])
def test_every_row_is_the_single_solve_with_seed_plus_row(name, sigma):
    robot = load(name)
    _, targets, starts = problems(robot, 40, 1, sigma)
    batch = kinelab.solve_batch(robot, targets, q0=starts, seed=11, solver="frdm")
    assert batch.mode.startswith("frdm+newton (compiled batch")
    for b in range(40):
        one = kinelab.solve(robot, targets[b], q0=None if starts is None else starts[b], seed=11 + b,
                            time_budget=60.0, solver="frdm")
        np.testing.assert_array_equal(batch.q[b], one.q)
        assert batch.success[b] == one.success and batch.status[b] == one.status.value
        assert batch.position_error[b] == pytest.approx(one.position_error, abs=1e-15)
        assert batch.rotation_error[b] == pytest.approx(one.rotation_error, abs=1e-12)
    assert batch.success.mean() >= 0.95


def test_the_batch_does_not_depend_on_the_thread_count():
    robot = load("panda")
    _, targets, _ = problems(robot, 600, 2)
    try:
        threads.set_count(1)
        one = kinelab.solve_batch(robot, targets, seed=5, solver="frdm")
        threads.set_count(4)  # more threads than this machine's two cores: rows interleave differently
        many = kinelab.solve_batch(robot, targets, seed=5, solver="frdm")
    finally:
        threads.set_count(None)
    assert "1 threads" in one.mode and "4 threads" in many.mode
    np.testing.assert_array_equal(one.q, many.q)
    np.testing.assert_array_equal(one.status, many.status)


def test_success_is_pinocchios_verdict_row_by_row():
    robot = load("ur5")
    _, targets, _ = problems(robot, 50, 3)
    batch = kinelab.solve_batch(robot, targets, seed=0)
    for b in range(50):
        dp, dr = robot.tool_error(batch.q[b], targets[b])
        assert batch.success[b] == (dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(batch.q[b]))
        assert batch.position_error[b] == pytest.approx(dp, abs=1e-15)


def test_other_solvers_run_row_by_row_with_the_same_seeds():
    robot = load("ur5")
    _, targets, _ = problems(robot, 5, 4)
    batch = kinelab.solve_batch(robot, targets, seed=3, solver="dls", max_restarts=20)
    assert batch.mode == "dls (per target)"
    for b in range(5):
        one = kinelab.solve(robot, targets[b], solver="dls", seed=3 + b, max_restarts=20, time_budget=60.0)
        np.testing.assert_array_equal(batch.q[b], one.q)


def test_an_unreachable_row_and_an_exhausted_budget_are_said():
    robot = load("ur5")
    _, targets, _ = problems(robot, 3, 5)
    far = targets[1].copy()
    far.translation = np.array([9.0, 0.0, 0.0])
    batch = kinelab.solve_batch(robot, [targets[0], far, targets[2]], seed=1)
    assert list(batch.success) == [True, False, True] and batch.status[1] == "unreachable"
    late = kinelab.solve_batch(robot, targets, seed=1, time_budget=1e-9)
    assert not late.success.any() and set(late.status) == {"time_budget"} and np.isnan(late.q).all()


def test_bad_batches_are_refused_naming_the_row():
    robot = load("ur5")
    Q, targets, _ = problems(robot, 4, 6)
    with pytest.raises(TargetError, match=r"targets\[2\]"):
        kinelab.solve_batch(robot, [*targets[:2], None, targets[3]])
    H = np.array([t.homogeneous for t in targets])
    H[3, 1, 1] = np.inf
    with pytest.raises(TargetError, match=r"targets\[3\]"):
        kinelab.solve_batch(robot, H)
    starts = Q.copy()
    starts[1, 2] = np.nan
    with pytest.raises(ConfigurationError, match=r"q0\[1\]"):
        kinelab.solve_batch(robot, targets, q0=starts)
    starts[1, 2] = 99.0
    with pytest.raises(kinelab.JointLimitError):
        kinelab.solve_batch(robot, targets, q0=starts)
    with pytest.raises(ConfigurationError, match=r"\(4, 6\)"):
        kinelab.solve_batch(robot, targets, q0=np.zeros((3, 6)))
    with pytest.raises(OptionError, match="seed"):
        kinelab.solve_batch(robot, targets, seed=-1)


def test_fk_and_jacobian_batches_equal_the_single_calls():
    robot = load("kinova")
    Q = robot.random_qs(20, 7)
    H = robot.fk_batch(Q)
    J = robot.jacobian_batch(Q, frame="world")
    for b in range(20):
        # fk_batch is the certified compiled FK: Pinocchio's single call to rounding, not to the bit
        np.testing.assert_allclose(H[b], robot.fk(Q[b]).homogeneous, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(J[b], robot.jacobian_world(Q[b]))
    np.testing.assert_array_equal(robot.jacobian_batch(Q[:3])[1], robot.jacobian_local(Q[1]))
    with pytest.raises(ConfigurationError, match=rf"\(B, {robot.n}\)"):
        robot.fk_batch(Q[:, :5])
    bad = Q.copy()
    bad[4, 0] = np.nan
    with pytest.raises(ConfigurationError, match=r"Q\[4\]"):
        robot.fk_batch(bad)
    with pytest.raises(OptionError, match="frame"):
        robot.jacobian_batch(Q, frame="tool")


@pytest.mark.parametrize("defect, needle", [
    (lambda H: H.__setitem__((3, 0), np.nan), "has NaN or infinite entries"),
    (lambda H: H.__setitem__((3, 3, 0), 0.5), "its last row is not (0, 0, 0, 1)"),
    (lambda H: H.__setitem__((3, slice(0, 3), 0), -H[3, :3, 0]), "its rotation is not a rotation matrix"),
    (lambda H: H.__setitem__((3, slice(0, 3), slice(0, 3)), 1.001 * H[3, :3, :3]),
     "its rotation is not a rotation matrix"),
])
def test_the_compiled_target_check_names_the_first_bad_target(defect, needle):
    """The batch's targets are checked in one compiled pass (numpy's stacked checks cost 2 ms for 2,000): each
    defect named at its index, a tolerance of 1e-6 on RᵀR kept (1.000 0001 × R passes)."""
    ur5 = load("ur5")
    H = np.array([ur5.fk(ur5.random_q(k)).homogeneous for k in range(5)])
    ok = H.copy()
    ok[2, :3, :3] *= 1 + 4e-8
    assert kinelab.solve_batch(ur5, ok, seed=0).success.all()
    defect(H)
    with pytest.raises(kinelab.TargetError, match=re.escape(f"targets[3] {needle}")):
        kinelab.solve_batch(ur5, H, seed=0)
