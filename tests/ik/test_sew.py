"""The SEW angle as a 7R arm's redundancy parameter (kinelab.ik.analytic.sew): the angle is checked against one
built here from Pinocchio's joint axes, and every branch at an angle against Pinocchio's FK, the limits and that
angle; a pose's own configuration must be among its branches."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from helpers import pinocchio_axes, turn_gap

import kinelab
from kinelab.errors import OptionError
from kinelab.ik.analytic.sew import SEW, arm7, sew_angle

TOL = 1e-6  # [m, rad] the judge's tolerances, and the SEW angle's
FOUND = 1e-6  # [rad] the pose's own configuration is an answer to this, joint by joint, modulo 2π


gap = turn_gap


def nearest(h_a, o_a, h_b, o_b):
    """The point of line a nearest line b, by least squares on the two line parameters."""
    A = np.column_stack([h_a, -h_b])
    s, _ = np.linalg.lstsq(A, o_b - o_a, rcond=None)[0]
    return o_a + s * h_a


def psi_by_pinocchio(robot, q, singular=(0.0, 0.0, -1.0), reference=(1.0, 0.0, 0.0)):
    """The stereographic SEW angle written out from its definition with Pinocchio's axes: S on axis 1 nearest
    axis 2, E on axis 4 nearest axis 3, W on axis 7 nearest axis 6; the reference plane's normal (ŵ − e_t) × e_r,
    the angle about ŵ from it to the plane SEW's normal (W − S) × (E − S)."""
    h, o, _ = pinocchio_axes(robot, q)
    S, E, W = nearest(h[0], o[0], h[1], o[1]), nearest(h[3], o[3], h[2], o[2]), nearest(h[6], o[6], h[5], o[5])
    w = (W - S) / np.linalg.norm(W - S)
    e_t, e_r = np.array(singular), np.array(reference)
    ref = np.cross(w - e_t, e_r)
    ref -= (ref @ w) * w
    n = np.cross(W - S, E - S)
    return math.atan2(np.cross(ref, n) @ w, ref @ n)


@pytest.mark.parametrize("name", ["panda", "tiago_pro", "xarm7"])
def test_the_angle_is_the_one_built_from_pinocchios_axes(name):
    robot = kinelab.load(name)
    for q in robot.random_qs(20, 5):
        assert abs(gap(sew_angle(robot, q), psi_by_pinocchio(robot, q))) < 1e-9


def test_turning_the_elbow_about_the_shoulder_wrist_line_turns_the_angle_by_as_much():
    sew = SEW(0.0, singular=(0.3, -0.2, -0.9), reference=(1.0, 0.5, 0.0))
    rng = np.random.default_rng(2)
    for _ in range(50):
        S, E, W = rng.normal(size=(3, 3))
        turn = rng.uniform(-3.0, 3.0)
        axis = (W - S) / np.linalg.norm(W - S)
        E_turned = S + pin.exp3(turn * axis) @ (E - S)
        assert abs(gap(sew.of(S, E_turned, W) - sew.of(S, E, W), turn)) < 1e-9


def test_the_angles_derivative_is_its_difference_quotient():
    robot = kinelab.load("xarm7")
    arm, sew = arm7(robot), SEW(0.0)
    for q in robot.random_qs(10, 3):
        S, E, W, dE, dW = arm.moved(q)
        g_E, g_W = sew.gradient(S, E, W)
        row = g_E @ dE + g_W @ dW
        quotient = [(sew_angle(robot, q + 1e-6 * np.eye(7)[k]) - sew_angle(robot, q - 1e-6 * np.eye(7)[k])) / 2e-6
                    for k in range(7)]
        assert np.allclose(row, quotient, atol=1e-6)


def check_branches(robot, found, target, psi):
    """Every answer meets the pose by Pinocchio's FK within the limits, has the SEW angle psi, and is distinct."""
    for r in found:
        p_err, r_err = robot.tool_error(r.q, target)
        assert p_err <= TOL and r_err <= TOL and robot.within_limits(r.q, slack=0.0)
        assert abs(gap(psi_by_pinocchio(robot, r.q), psi)) <= TOL
    qs = [r.q for r in found]
    assert all(gap(a, b) > FOUND for i, a in enumerate(qs) for b in qs[:i])


@pytest.mark.parametrize(("name", "poses"), [("panda", 25), ("xarm7", 10), ("tiago_pro", 5)])
def test_a_poses_own_configuration_is_among_its_branches_at_its_angle(name, poses):
    robot = kinelab.load(name)
    for q in robot.random_qs(poses, 11):
        target, psi = robot.fk(q), sew_angle(robot, q)
        found = kinelab.solve_all(robot, target, redundancy=SEW(psi))
        check_branches(robot, found, target, psi)
        assert min(gap(r.q, q) for r in found) < FOUND
        assert found.complete == "search" and found.method == "search"


def test_a_reference_of_ones_own_and_q_ref_ordering():
    robot = kinelab.load("panda")
    q = robot.random_qs(1, 4)[0]
    sew = SEW(0.0, singular=(-1.0, 0.0, 0.0), reference=(0.0, 0.0, 1.0))
    psi = sew.of(*arm7(robot).points(q))
    found = kinelab.solve_all(robot, robot.fk(q), redundancy=SEW(psi, (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)), q_ref=q)
    assert gap(found[0].q, q) < FOUND
    for r in found:
        assert abs(gap(psi_by_pinocchio(robot, r.q, (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)), psi)) <= TOL


def test_an_angle_no_configuration_has_gives_an_honest_empty_set():
    robot = kinelab.load("panda")
    q = robot.random_qs(1, 8)[0]
    target = robot.fk(q)
    reached = [sew_angle(robot, r.q) for r in kinelab.solve_all(robot, target, redundancy=64)]
    psi = np.linspace(-np.pi, np.pi, 721)
    spread = np.array([min(abs(gap(p, a)) for a in reached) for p in psi])
    far = float(psi[spread.argmax()])
    found = kinelab.solve_all(robot, target, redundancy=SEW(far))
    check_branches(robot, found, target, far)
    if not found:
        assert found.status is not None and found.complete == "search" and found.message


@pytest.mark.parametrize("bad", [
    {"angle": float("nan")}, {"angle": "1"}, {"angle": 0.0, "singular": (0.0, 0.0, 0.0)},
    {"angle": 0.0, "singular": (0.0, 0.0, 1.0), "reference": (0.0, 0.0, -2.0)},
    {"angle": 0.0, "reference": (1.0, 0.0)}, {"angle": 0.0, "samples": 3}, {"angle": 0.0, "samples": True},
])
def test_bad_sew_options_are_refused_by_name(bad):
    with pytest.raises(OptionError, match="SEW"):
        SEW(**bad)


def test_an_arm_that_is_not_7r_or_a_task_that_is_not_a_pose_is_refused():
    ur5 = kinelab.load("ur5")
    with pytest.raises(OptionError, match="7R"):
        kinelab.solve_all(ur5, ur5.fk(np.zeros(6)), redundancy=SEW(0.5))
    with pytest.raises(OptionError, match="7R"):
        sew_angle(ur5, np.zeros(6))
    panda = kinelab.load("panda")
    with pytest.raises(OptionError, match="pose"):
        kinelab.solve_all(panda, panda.fk(panda.neutral()), redundancy=SEW(0.5), task="position")


def test_the_bench_table_counts_own_configurations_and_names_misses():
    from kinelab.report.bench import sew as bench

    row = bench.measure(kinelab.load("panda"), 6, 0)
    assert row["poses"] == 6 and row["found"] == 1.0 and row["missed"] == [] and row["branches_median"] >= 1
    row["missed"] = [{"q": [0.0] * 7, "nearest": 0.5, "elbow_off_line": 0.012}]
    lines = bench.markdown([row])
    assert any(line.startswith("| panda | 6 | 100.00 % |") for line in lines)
    assert "- panda: q = (0.000000, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000), elbow 0.012 m " \
           "from the shoulder–wrist line" in lines
