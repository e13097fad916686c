"""The small geometry every layer shares, written once: quaternions (w ≥ 0), pose error, 2π wrapping.

Conventions: rotations are 3 × 3 matrices, poses ``pin.SE3``, quaternions (w, x, y, z) with the sign
chosen so that w ≥ 0 (q and −q are the same rotation).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

TWO_PI = 2.0 * np.pi


def quat_wxyz_from_matrix(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (w, x, y, z) of a rotation matrix, with w ≥ 0."""
    q = pin.Quaternion(np.asarray(R, dtype=float))
    wxyz = np.array([q.w, q.x, q.y, q.z])
    return -wxyz if wxyz[0] < 0 else wxyz


def matrix_from_quat_wxyz(wxyz: np.ndarray) -> np.ndarray:
    """The rotation matrix of a quaternion (w, x, y, z), normalised first."""
    w, x, y, z = np.asarray(wxyz, dtype=float) / np.linalg.norm(wxyz)
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


def pose_error(oMa: pin.SE3, oMb: pin.SE3) -> tuple[float, float]:
    """(position error [m], rotation angle error [rad]) between two poses of the same frame.

    The position error is |t_a − t_b|; the rotation error is the angle of R_aᵀR_b (in [0, π]).
    """
    err = oMa.actInv(oMb)  # b in a's frame: |t| is the distance, log3 the relative rotation
    return math.hypot(*err.translation.tolist()), math.hypot(*pin.log3(err.rotation).tolist())


def stack_homogeneous(points: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """(B, 4, 4) homogeneous matrices from (B, 3) points [m] and (B, 3, 3) rotations."""
    H = np.zeros((points.shape[0], 4, 4))
    H[:, :3, :3], H[:, :3, 3], H[:, 3, 3] = rotations, points, 1.0
    return H


def pose_errors(H_a: np.ndarray, H_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pose_error` for (B, 4, 4) stacks of homogeneous matrices: (position errors [m], rotation
    angles [rad]), the angle as atan2(|vee(M − Mᵀ)|/2, (tr M − 1)/2) with M = R_aᵀR_b (accurate near 0 and π).
    """
    dp = np.linalg.norm(H_a[:, :3, 3] - H_b[:, :3, 3], axis=1)
    M = np.einsum("bki,bkj->bij", H_a[:, :3, :3], H_b[:, :3, :3])
    vee = np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], axis=1)
    cos = (M[:, 0, 0] + M[:, 1, 1] + M[:, 2, 2] - 1.0) / 2.0
    return dp, np.arctan2(np.linalg.norm(vee, axis=1) / 2.0, cos)


def wrap_to_pi(angles: np.ndarray) -> np.ndarray:
    """Angles [rad] wrapped into (−π, π] (the same rotations) by whole turns: exact for an angle already inside,
    and no trigonometry — the compiled kernels wrap with the same arithmetic, so both agree to the last bit on any
    processor (NumPy's and the C library's sine and arctangent differ by an ulp on some)."""
    angles = np.asarray(angles, dtype=float)
    t = angles - TWO_PI * np.rint(angles / TWO_PI)
    return np.where(t <= -np.pi, t + TWO_PI, np.where(t > np.pi, t - TWO_PI, t))[()]


def wrap_angle(theta: float) -> float:
    """One angle [rad] wrapped into (−π, π] as :func:`wrap_to_pi` wraps it, in plain floats (a tenth of its cost on
    one number, for scalar loops); NaN and ±inf stay as they are."""
    if not math.isfinite(theta):
        return theta
    t = theta - TWO_PI * round(theta / TWO_PI)
    return t + TWO_PI if t <= -math.pi else t - TWO_PI if t > math.pi else t


def turns_into(x: np.ndarray, lower: np.ndarray, upper: np.ndarray, where: np.ndarray | None = None) -> np.ndarray:
    """x moved by whole turns (2πk, the same rotation) towards [lower, upper]: values above the upper
    bound come down, values below the lower one go up; a value no turn brings inside stays outside by less
    than a turn (clip it if it must be inside). ``where``: only these entries (the angles) move."""
    x = np.array(x, dtype=float)
    over = x > upper if where is None else where & (x > upper)
    x[over] -= TWO_PI * np.ceil((x[over] - upper[over]) / TWO_PI)
    under = x < lower if where is None else where & (x < lower)
    x[under] += TWO_PI * np.ceil((lower[under] - x[under]) / TWO_PI)
    return x
