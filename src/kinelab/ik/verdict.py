"""Compiled arithmetic on Pinocchio's numbers: the checks a solve makes on its target and on its answer.

Pinocchio computes the tool pose; these functions only compare matrices (in nopython code: a solve in a
loop spends more on a dozen Python float operations than on the FK itself).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.chain import rotation_angle

NOT_FINITE, NOT_A_ROTATION = 1, 2


@njit(cache=True)
def pose_defect(H: np.ndarray) -> int:
    """0 when the 4 × 4 homogeneous matrix H has finite entries and a rotation block (RᵀR = I to 1e-6,
    det R > 0); else NOT_FINITE or NOT_A_ROTATION."""
    total = 0.0
    for i in range(3):
        for j in range(4):
            total += H[i, j]
    if not np.isfinite(total):  # NaN and ±inf poison the sum; so does an overflow of huge finite entries
        for i in range(3):
            for j in range(4):
                if not np.isfinite(H[i, j]):
                    return NOT_FINITE
    gram = 0.0
    for a in range(3):
        for b in range(a, 3):
            d = H[0, a] * H[0, b] + H[1, a] * H[1, b] + H[2, a] * H[2, b] - (1.0 if a == b else 0.0)
            gram = max(gram, abs(d))
    det = (H[0, 0] * (H[1, 1] * H[2, 2] - H[1, 2] * H[2, 1]) - H[0, 1] * (H[1, 0] * H[2, 2] - H[1, 2] * H[2, 0])
           + H[0, 2] * (H[1, 0] * H[2, 1] - H[1, 1] * H[2, 0]))
    return NOT_A_ROTATION if gram > 1e-6 or det < 0.0 else 0


@njit(cache=True)
def pose_verdict(H_target: np.ndarray, H_tool: np.ndarray, q: np.ndarray, lower: np.ndarray,
                 upper: np.ndarray, axis: int) -> tuple[float, float, bool]:
    """(position error [m], rotation error [rad], q within [lower, upper]) for homogeneous matrices of the
    target and of the tool (from Pinocchio's FK). The rotation error is the angle of R*ᵀR (the chain
    kernels' own :func:`~kinelab.ik.chain.rotation_angle`), or with ``axis`` = 0, 1, 2 the angle between
    the tool's and the target's x, y or z axes (task "axis"; −1 for the whole rotation)."""
    d0, d1, d2 = H_target[0, 3] - H_tool[0, 3], H_target[1, 3] - H_tool[1, 3], H_target[2, 3] - H_tool[2, 3]
    if axis < 0:
        angle = rotation_angle(H_tool[:3, :3], H_target[:3, :3])
    else:
        u0, u1, u2 = H_tool[0, axis], H_tool[1, axis], H_tool[2, axis]
        v0, v1, v2 = H_target[0, axis], H_target[1, axis], H_target[2, axis]
        c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        angle = np.arctan2(np.sqrt(c0 * c0 + c1 * c1 + c2 * c2), u0 * v0 + u1 * v1 + u2 * v2)
    within = True
    for i in range(q.shape[0]):
        within = within and lower[i] <= q[i] <= upper[i]
    return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2), angle, within
