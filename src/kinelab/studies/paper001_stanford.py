"""Seed paper 001 (Lomovtseva & Chelnokov, Stanford arm, biquaternion IK): its printed numbers.

The paper's biquaternion N = n + s n0 is printed to six digits, scalar first (``_wxyz``). Its rotation
part is reproduced by ``urdf/stanford.urdf`` at the paper's target q; its dual part equals
n0 = ½ r∘n of that model divided by 10 (see the header of stanford.urdf and docs/robot-models.md §4).
"""

from __future__ import annotations

import numpy as np

from kinelab.dq import kinematics as biquat_kinematics
from kinelab.ik.biquat import solver as biquat
from kinelab.ik.result import BiquatTrajectory
from kinelab.robot import load

# Target and start configurations (q1, q2, q3 [m], q4, q5, q6); angles in degrees as printed.
TARGET_Q_DEG = (20.0, 40.0, 0.3, -35.0, 60.0, -45.0)
START_Q_DEG = (-30.0, 15.0, 0.1, 36.0, -90.0, 45.0)
N_REAL_WXYZ = np.array([0.181938, -0.718084, 0.117974, 0.661314])
N_DUAL_WXYZ = np.array([-0.017347, 0.005780, -0.017376, 0.014148])
DUAL_PART_SCALE = 10.0  # kinelab's n0 = DUAL_PART_SCALE × the printed n0 (lengths read as H2)
PRINTED_DIGITS_TOL = 1e-5  # the paper prints six decimals


def q_from_paper(q_deg) -> np.ndarray:
    """Paper coordinates (deg, deg, m, deg, deg, deg) → kinelab q (rad, rad, m, rad, rad, rad)."""
    q = np.array(q_deg, dtype=float)
    angular = np.array([True, True, False, True, True, True])
    return np.where(angular, np.deg2rad(q), q)


TARGET_Q = q_from_paper(TARGET_Q_DEG)
START_Q = q_from_paper(START_Q_DEG)


def quat_distance_wxyz(a, b) -> float:
    """Largest component difference between unit quaternions, treating a and −a as equal."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(min(np.max(np.abs(a - b)), np.max(np.abs(a + b))))


def reproduce(robot=None, law: str = "simple", integrator: str = "euler", step: float = 0.01, k: float = 1.0,
              k0: float = 0.0, k_v: float | None = None, start_q=None, record: bool = True):
    """The paper's run: from START_Q to the target N = Λ(TARGET_Q), K = k + s k0, step h [s].

    Returns the solver's Attempt; its ``diagnostics`` hold model_time [s], M0 (the scalar of N̄∘Λ at the end, the
    chain product keeping Λ continuous) and, with ``record``, the trajectory (t, q, M*, U).
    """
    robot = robot or load("stanford")
    N = biquat_kinematics.pose(robot, TARGET_Q)
    q0 = START_Q if start_q is None else np.asarray(start_q, dtype=float)
    return biquat.attempt(robot, robot.fk(TARGET_Q), q0, 1e-6, 1e-6, np.inf, law=law, integrator=integrator,
                          step=step, k=k, k0=k0, k_v=k_v, target_biquaternion=N, record=record)


def part_times(trajectory: BiquatTrajectory, eps: float = 5e-7) -> tuple[float, float]:
    """Model times [s] at which the rotation part |m⃗| and the moment part |m0⃗| of M* first fall below eps."""
    t, M = trajectory.t, trajectory.M
    rot, mom = np.linalg.norm(M[:, 1:4], axis=1), np.linalg.norm(M[:, 5:8], axis=1)
    first = [t[np.argmax(x < eps)] if (x < eps).any() else float("nan") for x in (rot, mom)]
    return float(first[0]), float(first[1])


def near_pi_start(delta: float = 1e-2) -> np.ndarray:
    """A start whose error rotation is π − delta: the target with q6 turned by π − delta."""
    q = TARGET_Q.copy()
    q[5] += np.pi - delta
    return q
