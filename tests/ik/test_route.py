"""One route through the compiled core (#32): every entry point of a solve — ``kinelab.solve``, a prepared
``kinelab.IK``, a row of ``solve_batch`` — runs the same compiled multistart on the same start with the same
generator, so for the same seed they give the same answer, bit for bit, with the same diagnostics."""

import numpy as np
import pytest

import kinelab

FIELDS = ("sweeps", "attempts", "stalls", "polished", "newton_steps", "accelerated_sweeps", "path")


@pytest.mark.parametrize("name", ["ur5", "panda", "youbot", "kinova"])
def test_solve_the_prepared_solver_and_a_batch_row_take_the_same_route(name):
    robot = kinelab.load(name)
    ik = kinelab.IK(robot, time_budget=None)
    rng = np.random.default_rng(17)
    for k in range(12):
        q = robot.random_q(rng)
        target = robot.fk(q)
        q0 = np.clip(q + rng.normal(0, 0.2, q.size), robot.lower, robot.upper) if k % 2 else None
        plain = kinelab.solve(robot, target, q0=q0, seed=k, time_budget=None)
        prepared = ik.solve(target, q0=q0, seed=k)
        row = kinelab.solve_batch(robot, [target], q0=None if q0 is None else [q0], seed=k)
        np.testing.assert_array_equal(plain.q, prepared.q)
        np.testing.assert_array_equal(plain.q, row.q[0])
        assert plain.status == prepared.status and plain.status.value == row.status[0]
        assert plain.iterations == prepared.iterations == row.iterations[0]
        assert plain.restarts == prepared.restarts == row.restarts[0]
        assert plain.mode == prepared.mode
        for field in FIELDS:
            assert getattr(plain.diagnostics, field) == getattr(prepared.diagnostics, field), field
        assert plain.diagnostics.path == "compiled"


def test_a_batch_row_is_the_single_solve_with_seed_plus_its_index():
    robot = kinelab.load("panda")
    rng = np.random.default_rng(3)
    targets = [robot.fk(robot.random_q(rng)) for _ in range(20)]
    batch = kinelab.solve_batch(robot, targets, seed=100)
    for b, target in enumerate(targets):
        one = kinelab.solve(robot, target, seed=100 + b, time_budget=None)
        np.testing.assert_array_equal(one.q, batch.q[b])
        assert one.iterations == batch.iterations[b] and one.restarts == batch.restarts[b]


def test_the_biquaternion_solver_takes_one_route_too():
    robot = kinelab.load("stanford")
    ik = kinelab.IK(robot, solver="biquat", time_budget=None)
    rng = np.random.default_rng(5)
    for k in range(8):
        target = robot.fk(robot.random_q(rng))
        plain = kinelab.solve(robot, target, solver="biquat", seed=k, time_budget=None)
        prepared = ik.solve(target, seed=k)
        np.testing.assert_array_equal(plain.q, prepared.q)
        assert plain.status == prepared.status and plain.iterations == prepared.iterations
        assert plain.diagnostics.steps == prepared.diagnostics.steps
        assert plain.diagnostics.attempts == prepared.diagnostics.attempts
