"""The biquaternion control laws of paper 001 (docs/methods.md §2.4–2.5), compiled and callable from Python.

Each equation is written once here; the compiled preset (:mod:`kinelab.ik.biquat.kernel`) and the
Python integrators (:mod:`kinelab.ik.biquat.integrators`) both call these functions. M is the error
biquaternion M* = N̄∘Λ as 8 numbers (real w, x, y, z, dual w, x, y, z) with m^0 ≥ 0; a control U = ω + s v
(end-link axes) is written into ``twist`` in Pinocchio's order [v; ω].
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kinelab.ik.chain import quat_wxyz


@njit(cache=True)
def error_biquaternion(p, R, pstar, Rstar):
    """M* = N̄∘Λ (8 numbers, m^0 ≥ 0): the tool's pose (p [m], R) in the target frame (p*, R*)."""
    Rrel = Rstar.T @ R
    t = Rstar.T @ (p - pstar)
    m = quat_wxyz(Rrel)
    tx, ty, tz = 0.5 * t[0], 0.5 * t[1], 0.5 * t[2]
    out = np.empty(8)
    out[:4] = m
    out[4] = -tx * m[1] - ty * m[2] - tz * m[3]
    out[5] = tx * m[0] + ty * m[3] - tz * m[2]
    out[6] = ty * m[0] + tz * m[1] - tx * m[3]
    out[7] = tz * m[0] + tx * m[2] - ty * m[1]
    return out


@njit(cache=True)
def simple_law(M: np.ndarray, k: float, k0: float, k_v: float, twist: np.ndarray) -> bool:
    """Law (9)/(16): U = −2K vect(M)/scal(M) with K = k + s k0 [1/s]; ``k_v`` a separate moment gain.

    ω = −2k m⃗/m^0 and v = −2[k_v (m^0 m0⃗ − m0^0 m⃗) + k0 m^0 m⃗]/(m^0)². With k_v = k this is the dual gain
    K = k + s k0 of (9); with k0 = 0 and k_v ≠ k it is the paper's separate gains (16).

    Returns:
        False when the law is singular (m^0 = 0: the error rotation is π), else True.
    """
    m0, d0 = M[0], M[4]
    if m0 == 0.0:
        return False
    for j in range(3):
        twist[3 + j] = -2.0 * k * M[1 + j] / m0
        twist[j] = -2.0 * (k_v * (m0 * M[5 + j] - d0 * M[1 + j]) + k0 * m0 * M[1 + j]) / (m0 * m0)
    return True


@njit(cache=True)
def regular_law(M: np.ndarray, tau: float, tau0: float, k: float, k0: float,
                twist: np.ndarray) -> tuple[float, float]:
    """Law (11)/(12): U = −K T⁻¹ vect(M), 2Ṫ = K(scal(M) − T), T = τ + s τ0 (T(t0) = 1).

    Returns:
        (τ̇, τ̇0), with U written into ``twist``.
    """
    c, c0 = k / tau, (k0 * tau - k * tau0) / tau**2  # K T⁻¹ as a dual number
    for j in range(3):
        twist[3 + j] = -c * M[1 + j]
        twist[j] = -(c * M[5 + j] + c0 * M[1 + j])
    return 0.5 * k * (M[0] - tau), 0.5 * (k * (M[4] - tau0) + k0 * (M[0] - tau))


@njit(cache=True)
def joint_rates(J, twist, damping):
    """q̇ = A(q)⁻¹U (eq. 8 inverted) from the LOCAL tool Jacobian J (rows [v; ω], 6 × n).

    Square and undamped: an exact solve (a NaN result marks a singular A). Otherwise the damped
    pseudo-inverse V diag(σ/(σ² + λ²)) Uᵀ with λ = ``damping``.
    """
    n = J.shape[1]
    if n == 6 and damping == 0.0:
        if abs(np.linalg.det(J)) < 1e-300:
            return np.full(6, np.nan)
        return np.linalg.solve(J, twist)
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    return Vt.T @ ((s / (s * s + damping * damping)) * (U.T @ twist))


@njit(cache=True)
def converged(M, eps_rot, eps_dual):
    """|m⃗| < eps_rot and |m0⃗| < eps_dual (near ±1, m⃗ ≈ δθ/2 and m0⃗ ≈ ½R*ᵀΔp)."""
    return M[1] ** 2 + M[2] ** 2 + M[3] ** 2 < eps_rot**2 and M[5] ** 2 + M[6] ** 2 + M[7] ** 2 < eps_dual**2
