"""Pieper's decoupling (kinelab.ik.analytic.pieper): a 6R chain whose first (or last) three axes meet, the rest
general or with axes 4 and 5 meeting — where the general elimination's pencil is singular. Every answer is checked
by Pinocchio's FK; the sets are compared with the multistart's; the Panda with its elbow held is such a chain."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from helpers import assert_meets_pose, chain_urdf, multistart_gaps, turn_gap, write_urdf

import kinelab
from kinelab.ik.analytic.branches import arm_of
from kinelab.ik.analytic.kernel import PIEPER_6R
from kinelab.ik.request import make_request

TOL = 1e-6  # [m, rad] the judge's tolerances
FOUND = 1e-9  # [rad] the pose's own configuration is an answer to this, joint by joint, modulo 2π


gap = turn_gap


def pieper_robot(tmp_path, seed, wrist_meets=False, mirrored=False):
    """A random arm whose axes 1, 2, 3 pass through one point (4 and 5 meeting too with ``wrist_meets``); with
    ``mirrored`` the chain is built backwards, so that axes 4, 5, 6 meet instead."""
    rng = np.random.default_rng(seed)
    h = rng.normal(size=(6, 3))
    h /= np.linalg.norm(h, axis=1)[:, None]
    o = rng.uniform(-0.4, 0.4, (6, 3))
    o[1] = o[2] = o[0]
    if wrist_meets:
        o[4] = o[3] + 0.3 * h[3]  # a point of axis 4 also on axis 5
    if mirrored:
        h, o = h[::-1].copy(), o[::-1].copy()
    tool = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.4, 0.4, 3))
    path = write_urdf(tmp_path, chain_urdf(h, o, tool, np.full(6, -np.pi), np.full(6, np.pi)), f"p{seed}.urdf")
    return kinelab.load(path, tool="tool")


@pytest.mark.parametrize(("seed", "wrist_meets", "mirrored"), [(1, False, False), (2, False, True), (3, True, False),
                                                               (4, True, True)])
def test_random_pieper_arms_give_the_pose_s_own_configuration_among_judged_branches(tmp_path, seed, wrist_meets,
                                                                                      mirrored):
    robot = pieper_robot(tmp_path, seed, wrist_meets, mirrored)
    arm = arm_of(robot, make_request("frdm"))
    assert arm is not None and arm.kind == PIEPER_6R and arm.mirrored == mirrored
    rng = np.random.default_rng(seed)
    for _ in range(20):
        q = robot.random_q(rng)
        target = robot.fk(q)
        found = kinelab.solve_all(robot, target)
        assert found.method == "closed form" and "spherical shoulder" in found[0].mode
        assert 1 <= len(found) <= 8 and min(gap(s.q, q) for s in found) <= FOUND
        assert_meets_pose(robot, found.q, target, TOL)


def test_every_branch_the_multistart_finds_is_among_the_decoupling_s(tmp_path):
    for ours, found, farthest in multistart_gaps(pieper_robot(tmp_path, 5), 5):
        assert found >= 1 and farthest <= 1e-5
        assert ours.complete == "certified" or ours.complete_reason


def test_the_panda_with_its_elbow_held_is_decoupled_and_keeps_each_pose_s_configuration():
    robot = kinelab.load("panda")
    rng = np.random.default_rng(6)
    for _ in range(20):
        q = robot.random_q(rng)
        found = kinelab.solve_all(robot, robot.fk(q), redundancy={"panda_joint4": float(q[3])})
        assert "spherical shoulder" in found[0].mode
        assert min(gap(s.q, q) for s in found) <= FOUND
        assert all(s.q[3] == q[3] for s in found)


def test_a_decoupled_set_is_certified_only_with_eight_proved_branches(tmp_path):
    """The decoupling's subproblems can lose a root near its own singular configurations, so a set is proved
    complete only when it holds the most a Pieper arm has: eight branches, each proved by Kantorovich's test."""
    robot = pieper_robot(tmp_path, 4)  # an arm where many poses have all eight branches within ±π
    rng = np.random.default_rng(8)
    seen = set()
    for _ in range(60):
        found = kinelab.solve_all(robot, robot.fk(robot.random_q(rng)))
        if len(found) == 8:
            assert found.complete in ("certified", "search")
            seen.add(found.complete)
        else:
            assert found.complete == "search" and "Pieper's decoupling is measured complete" in found.complete_reason
            seen.add("fewer")
    assert seen >= {"certified", "fewer"}
