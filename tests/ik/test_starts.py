"""The start table (kinelab.ik.starts): configurations within the limits, the look-up checked against a brute-force
search, and solve_batch(q0="table") row by row the single solve from the table's start."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import ConfigurationError, load
from kinelab.ik.starts import SIZE, start_table


def test_the_table_is_configurations_within_the_limits_drawn_the_same_each_time():
    panda = load("panda")
    table = start_table(panda)
    assert table.q.shape == (SIZE, panda.n) and panda.within_limits_batch(table.q).all()
    again = start_table(kinelab.load("panda"))  # another Robot: built afresh from the same seed
    assert np.array_equal(table.q, again.q)
    assert 0 < table.nbytes < 8 * 2**20


def test_the_look_up_is_the_brute_force_nearest_and_a_stored_pose_finds_itself():
    ur5 = load("ur5")
    table = start_table(ur5)
    stored = table.q[[3, 500, 4000]]
    assert np.array_equal(table.nearest(ur5.fk_batch(stored)), stored)
    targets = ur5.fk_batch(ur5.random_qs(30, 4))
    features = table.features(ur5.fk_batch(table.q))
    for H, found in zip(targets, table.nearest(targets), strict=True):
        wanted = table.features(H[None])[0]
        brute = table.q[np.argmin(np.linalg.norm(features - wanted, axis=1))]
        assert np.array_equal(found, brute)


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_a_batch_from_the_table_is_each_single_solve_from_its_start(name):
    robot = load(name)
    targets = robot.fk_batch(robot.random_qs(40, 9))
    batch = kinelab.solve_batch(robot, targets, q0="table", seed=5, solver="frdm")
    assert "first starts from the start table" in batch.mode and batch.success.all()
    starts = start_table(robot).nearest(targets)
    for b in range(0, 40, 7):
        one = kinelab.solve(robot, pin.SE3(targets[b]), q0=starts[b], seed=5 + b, time_budget=60.0, solver="frdm")
        np.testing.assert_array_equal(batch.q[b], one.q)
    random = kinelab.solve_batch(robot, targets, q0="random", seed=5, solver="frdm")
    assert "start table" not in random.mode and random.success.all()
    np.testing.assert_array_equal(random.q, kinelab.solve_batch(robot, targets, seed=5, solver="frdm").q)


def test_a_start_mode_that_is_not_one_is_refused_by_name():
    panda = load("panda")
    targets = panda.fk_batch(panda.random_qs(3, 1))
    with pytest.raises(ConfigurationError, match="'random', 'table'"):
        kinelab.solve_batch(panda, targets, q0="tables")
    with pytest.raises(ConfigurationError, match="task 'position'"):
        kinelab.solve_batch(panda, targets, q0="table", task="position")
