"""The biquaternion control laws of paper 001 (docs/methods.md §2.4–2.5), callable from Python.

Each equation is written once, in :mod:`kinelab.core._biquat` (law (11)/(12), which only the Python integrators
use, here); the compiled preset and the Python integrators (:mod:`kinelab.ik.biquat.integrators`) both use them.
M is the error biquaternion M* = N̄∘Λ as 8 numbers (real w, x, y, z, dual w, x, y, z) with m^0 ≥ 0; a control U = ω + s v
(end-link axes) is written into ``twist`` in Pinocchio's order [v; ω].
"""

from __future__ import annotations

import numpy as np

from kinelab.core._biquat import converged_of, error_biquaternion_of, joint_rates_of, simple_law_of


def error_biquaternion(p: np.ndarray, R: np.ndarray, pstar: np.ndarray, Rstar: np.ndarray) -> np.ndarray:
    """M* = N̄∘Λ (8 numbers, m^0 ≥ 0): the tool's pose (p [m], R) in the target frame (p*, R*)."""
    return error_biquaternion_of(np.ascontiguousarray(p, dtype=float), R, np.ascontiguousarray(pstar, dtype=float),
                                 Rstar)


def simple_law(M: np.ndarray, k: float, k0: float, k_v: float, twist: np.ndarray) -> bool:
    """Law (9)/(16): U = −2K vect(M)/scal(M) with K = k + s k0 [1/s]; ``k_v`` a separate moment gain.

    ω = −2k m⃗/m^0 and v = −2[k_v (m^0 m0⃗ − m0^0 m⃗) + k0 m^0 m⃗]/(m^0)². With k_v = k this is the dual gain
    K = k + s k0 of (9); with k0 = 0 and k_v ≠ k it is the paper's separate gains (16). U goes into ``twist``.

    Returns:
        False when the law is singular (m^0 = 0: the error rotation is π), else True.
    """
    return simple_law_of(M, float(k), float(k0), float(k_v), twist)


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


def joint_rates(J: np.ndarray, twist: np.ndarray, damping: float) -> np.ndarray:
    """q̇ = A(q)⁻¹U (eq. 8 inverted) from the LOCAL tool Jacobian J (rows [v; ω], 6 × n).

    Square and undamped: an exact solve (a NaN result marks a singular A). Otherwise the damped
    pseudo-inverse V diag(σ/(σ² + λ²)) Uᵀ with λ = ``damping``.
    """
    return joint_rates_of(J, np.ascontiguousarray(twist, dtype=float), float(damping))


def converged(M: np.ndarray, eps_rot: float, eps_dual: float) -> bool:
    """|m⃗| < eps_rot and |m0⃗| < eps_dual (near ±1, m⃗ ≈ δθ/2 and m0⃗ ≈ ½R*ᵀΔp)."""
    return converged_of(M, float(eps_rot), float(eps_dual))
