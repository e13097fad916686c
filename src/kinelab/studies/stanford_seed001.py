"""Seed paper 001 (Lomovtseva & Chelnokov, Stanford arm, biquaternion IK): its printed numbers.

The paper's biquaternion N = n + s n0 is printed to six digits, scalar first (``_wxyz``). Its rotation
part is reproduced by ``urdf/stanford.urdf`` at the paper's target q; its dual part equals
n0 = ½ r∘n of that model divided by 10 (see the header of stanford.urdf and robot-models.md §4).
"""

from __future__ import annotations

import numpy as np

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
