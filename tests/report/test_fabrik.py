"""The FABRIK bench reference: it reaches reachable points on a planar chain and on real arms (judged by
Pinocchio's FK of its q, within the limits), and it says so when a point is out of reach."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import revolute, write_urdf

import kinelab
from kinelab.report.bench import fabrik
from kinelab.report.bench.protocol import TOL_POS, cases, check_solution

PLANAR_4R = ('<link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>'
             '<link name="tool"/>' + revolute("j1", "base", "l1", xyz="0 0 0")
             + revolute("j2", "l1", "l2", xyz="0.4 0 0") + revolute("j3", "l2", "l3", xyz="0.3 0 0")
             + revolute("j4", "l3", "l4", xyz="0.2 0 0")
             + '<joint name="jt" type="fixed"><parent link="l4"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>')


def test_fabrik_reaches_every_reachable_point_of_a_planar_chain_within_its_limits(tmp_path):
    robot = kinelab.load(write_urdf(tmp_path, PLANAR_4R))
    solve = fabrik.prepare(robot, budget=0.5)
    rng = np.random.default_rng(0)
    for k in range(50):
        q_target = robot.random_q(rng)
        oMtarget = pin.SE3(np.eye(3), robot.fk(q_target).translation)  # a point: the rotation is not asked
        q, iterations = solve(cases(robot, 1, k)[0].__class__(k, q_target, robot.random_q(rng), oMtarget,
                                                              "position"), k)
        assert robot.within_limits(q) and iterations > 0
        assert np.linalg.norm(robot.fk(q).translation - oMtarget.translation) <= TOL_POS


def test_fabrik_stops_at_the_nearest_point_of_an_unreachable_target(tmp_path):
    robot = kinelab.load(write_urdf(tmp_path, PLANAR_4R))
    model = fabrik.chain_model(robot)
    q = np.zeros(4) + 0.3
    target = np.array([2.0, 0.0, 0.0])  # the chain is 1.0 m long
    iterations, error = fabrik.attempt(model.chain, model.lower, model.upper, target, q, 1e-9, 100)
    assert iterations < 100  # a stall, not the iteration cap
    assert error == pytest.approx(1.0, abs=1e-4)  # stretched out towards the point
    assert np.linalg.norm(robot.fk(q).translation - target) == pytest.approx(error, abs=1e-12)


@pytest.mark.parametrize("name", ["ur5", "panda", "so101", "stanford"])
def test_fabrik_solves_position_targets_of_real_arms_judged_by_pinocchio(name):
    robot = kinelab.load(name)
    solve = fabrik.prepare(robot, budget=3600.0, max_attempts=20)  # #31.7: attempts, not a 50 ms wall clock
    problems = cases(robot, 30, seed=3, task="position")
    solved = sum(check_solution(robot, solve(case, case.index)[0], case.oMtarget, 0.0, task="position")[0]
                 for case in problems)
    assert solved >= 28  # measured: 30 of 30 on each
