"""Biquaternions (dual quaternions) Λ = λ + s λ0, s² = 0, in Chelnokov's notation.

Both parts are quaternions stored scalar first (``_wxyz``), Hamilton product. A pose (R, t) is the
unit biquaternion with λ the quaternion of R (R x = λ∘x∘λ̄) and λ0 = ½ t∘λ; composition of poses is
the product, Λ_02 = Λ_01∘Λ_12 ⇔ T_02 = T_01 T_12. Λ and −Λ are the same pose.

Dual numbers a + s a0 are pairs (a, a0). The screw (vector) part of a biquaternion is a dual vector,
a pair of 3-vectors; a twist in Pinocchio's order (v, ω) is the dual vector ω + s v.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import BiquaternionError
from kinelab.geometry import matrix_from_quat_wxyz, quat_wxyz_from_matrix


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions (w, x, y, z)."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return np.array([
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ])


def qconj(a: np.ndarray) -> np.ndarray:
    """The conjugate of quaternion(s) ``a`` in (w, x, y, z) order."""
    return np.array([a[0], -a[1], -a[2], -a[3]])


@dataclass(frozen=True)
class DualQuat:
    """Λ = real + s·dual; ``real_wxyz`` and ``dual_wxyz`` are quaternions, scalar first."""

    real_wxyz: np.ndarray
    dual_wxyz: np.ndarray

    def __post_init__(self):
        for name in ("real_wxyz", "dual_wxyz"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.shape != (4,) or not math.isfinite(arr.sum()):
                bad = "NaN or infinite components" if arr.shape == (4,) else f"shape {arr.shape}, need 4 (w, x, y, z)"
                raise BiquaternionError(f"{name} has {bad}: {arr}")
            object.__setattr__(self, name, arr)

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def identity(cls) -> DualQuat:
        """The unit biquaternion of the identity pose."""
        return cls(np.array([1.0, 0, 0, 0]), np.zeros(4))

    @classmethod
    def from_array(cls, arr) -> DualQuat:
        """From 8 numbers: real (w, x, y, z) then dual (w, x, y, z)."""
        arr = np.asarray(arr, dtype=float)
        if arr.shape != (8,):
            raise BiquaternionError(f"a biquaternion has 8 components, got shape {arr.shape}")
        return cls(arr[:4], arr[4:])

    @classmethod
    def from_se3(cls, M: pin.SE3) -> DualQuat:
        """The unit biquaternion of a pose: λ = quat(R), λ0 = ½ t∘λ."""
        real = quat_wxyz_from_matrix(M.rotation)
        dual = 0.5 * qmul(np.r_[0.0, M.translation], real)
        return cls(real, dual)

    @classmethod
    def from_screw(cls, dual_vector: tuple[np.ndarray, np.ndarray]) -> DualQuat:
        """exp of the pure dual vector a + s a0 (the inverse of :meth:`log`)."""
        a, a0 = (np.asarray(x, dtype=float) for x in dual_vector)
        alpha = float(np.linalg.norm(a))
        if alpha < 1e-9:  # series: exp(a + s a0) ≈ (1 − α²/2) + a + s(a0 − (a·a0)) for small a
            real = np.r_[1.0 - 0.5 * alpha**2, a]
            dual = np.r_[-(a @ a0), a0]
            return cls(real, dual).normalized()
        alpha0 = float(a @ a0) / alpha  # dual part of the dual norm |a + s a0|
        c, s = np.cos(alpha), np.sin(alpha)
        # exp(A) = cos|A| + (A/|A|) sin|A| with dual-number functions
        unit_r = a / alpha
        unit_d = (a0 - unit_r * alpha0) / alpha
        real = np.r_[c, unit_r * s]
        dual = np.r_[-alpha0 * s, unit_d * s + unit_r * alpha0 * c]
        return cls(real, dual)

    # -- algebra ------------------------------------------------------------------------------
    def __mul__(self, other: DualQuat) -> DualQuat:
        """Λ∘Μ = λ∘μ + s(λ∘μ0 + λ0∘μ)."""
        return DualQuat(qmul(self.real_wxyz, other.real_wxyz),
                        qmul(self.real_wxyz, other.dual_wxyz) + qmul(self.dual_wxyz, other.real_wxyz))

    def __neg__(self) -> DualQuat:
        return DualQuat(-self.real_wxyz, -self.dual_wxyz)

    def conj(self) -> DualQuat:
        """Quaternion conjugate of both parts, Λ̄ = λ̄ + s λ̄0 (the inverse of a unit biquaternion)."""
        return DualQuat(qconj(self.real_wxyz), qconj(self.dual_wxyz))

    def dual_conj(self) -> DualQuat:
        """Dual-number conjugate, λ − s λ0."""
        return DualQuat(self.real_wxyz, -self.dual_wxyz)

    def full_conj(self) -> DualQuat:
        """Both conjugations, λ̄ − s λ̄0."""
        return DualQuat(qconj(self.real_wxyz), -qconj(self.dual_wxyz))

    def norm(self) -> tuple[float, float]:
        """The dual-number norm √(Λ∘Λ̄) = |λ| + s (λ·λ0)/|λ|."""
        r = float(np.linalg.norm(self.real_wxyz))
        if r == 0:
            raise BiquaternionError("the real part is zero: the norm is not invertible")
        return r, float(self.real_wxyz @ self.dual_wxyz) / r

    def normalized(self) -> DualQuat:
        """Λ / |Λ| (dual-number division): a unit biquaternion, |λ| = 1 and λ·λ0 = 0."""
        r, r0 = self.norm()
        return DualQuat(self.real_wxyz / r, self.dual_wxyz / r - self.real_wxyz * r0 / r**2)

    def is_unit(self, tol: float = 1e-9) -> bool:
        """True when |λ| = 1 and λ·λ0 = 0 to ``tol``."""
        r = self.real_wxyz
        return abs(r @ r - 1.0) <= tol and abs(r @ self.dual_wxyz) <= tol

    def scal(self) -> tuple[float, float]:
        """The scalar part, a dual number (λ^0, λ0^0)."""
        return float(self.real_wxyz[0]), float(self.dual_wxyz[0])

    def vect(self) -> tuple[np.ndarray, np.ndarray]:
        """The screw (vector) part, a dual vector (λ⃗, λ⃗0)."""
        return self.real_wxyz[1:].copy(), self.dual_wxyz[1:].copy()

    def as_array(self) -> np.ndarray:
        """The eight numbers (real w, x, y, z, then dual w, x, y, z)."""
        return np.r_[self.real_wxyz, self.dual_wxyz]

    # -- poses --------------------------------------------------------------------------------
    def require_unit(self, what: str = "biquaternion", tol: float = 1e-6) -> DualQuat:
        """This biquaternion, or a BiquaternionError naming ``what`` when it is not unit to ``tol``."""
        if not self.is_unit(tol):
            r = self.real_wxyz
            raise BiquaternionError(
                f"{what} is not a unit biquaternion: |λ|² = {r @ r:.6g}, λ·λ0 = {r @ self.dual_wxyz:.3g} "
                "(need 1 and 0; use .normalized())"
            )
        return self

    def to_se3(self) -> pin.SE3:
        """The pose of a unit biquaternion: R from λ, t = vect(2 λ0∘λ̄)."""
        self.require_unit()
        t = 2.0 * qmul(self.dual_wxyz, qconj(self.real_wxyz))[1:]
        return pin.SE3(matrix_from_quat_wxyz(self.real_wxyz), t)

    def log(self) -> tuple[np.ndarray, np.ndarray]:
        """The dual vector ½Φ e (Φ = φ + s d the dual angle, e the unit screw) with exp(log Λ) = Λ.

        For a pose it equals ½(ω + s v) where (v, ω) = pin.log6 of that pose.
        """
        self.require_unit()
        lam = self.real_wxyz if self.real_wxyz[0] >= 0 else -self.real_wxyz
        lam0 = self.dual_wxyz if self.real_wxyz[0] >= 0 else -self.dual_wxyz
        sin_half = float(np.linalg.norm(lam[1:]))
        if sin_half < 1e-9:  # pure translation (and rounding): Λ ≈ 1 + s(0, t/2)
            return lam[1:].copy(), lam0[1:].copy()
        half = np.arctan2(sin_half, lam[0])  # φ/2
        axis = lam[1:] / sin_half
        half_d = -lam0[0] / sin_half  # d/2
        moment = (lam0[1:] - half_d * np.cos(half) * axis) / sin_half
        return half * axis, half_d * axis + half * moment


def same_pose(a: DualQuat, b: DualQuat, tol: float = 1e-12) -> bool:
    """Λ ≡ −Λ: compare up to the double cover."""
    x, y = a.as_array(), b.as_array()
    return bool(min(np.max(np.abs(x - y)), np.max(np.abs(x + y))) <= tol)


def dual_div(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    """(a + s a0)/(b + s b0) = a/b + s(a0 b − a b0)/b²."""
    if b[0] == 0:
        raise BiquaternionError("division by a dual number with zero real part")
    return a[0] / b[0], (a[1] * b[0] - a[0] * b[1]) / b[0] ** 2
