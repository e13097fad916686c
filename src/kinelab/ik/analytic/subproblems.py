"""The canonical geometric subproblems (Paden–Kahan, in the form of Elias & Wen's IK-Geo), compiled.

Each solves one rotation about a unit axis k [rad] in closed form (docs/analytic.md):

- subproblem 1: the angle θ with R(k, θ)·p₁ = p₂ (p₁, p₂ with the same component along k);
- subproblem 4: the angles θ with hᵀ·R(k, θ)·p = d (none, one double root, or two);
- subproblem 3, the angles θ with ‖R(k, θ)·p₁ − p₂‖ = d, is subproblem 4 with h = p₂ and
  d' = (‖p₁‖² + ‖p₂‖² − d²)/2, and is written that way where it is used.

Degenerate cases are reported, not guessed: subproblem 1 when p₁ lies on k (every θ serves), subproblem 4
when hᵀ·R(k, θ)·p does not depend on θ.

Vectors are 3-tuples and rotations 9-tuples (row by row): numba keeps them in registers, where 3-vector
arrays would each be a heap allocation (a branch costs about a hundred of these operations).
"""

from __future__ import annotations

import numpy as np
from numba import njit

DEGENERATE = -1  # every angle serves (the caller picks one and marks the answer a continuum)
TANGENT_SLACK = 1e-9  # |cos| above 1 by this much is a double root met to rounding, beyond it no root
FLAT = 1e-12  # a length below this is treated as zero


@njit(cache=True, inline="always")
def row3(a, i):
    """Row i of an (m, 3) array as a 3-tuple."""
    return (a[i, 0], a[i, 1], a[i, 2])


@njit(cache=True, inline="always")
def dot3(a, b):
    """a·b."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def cross3(a, b):
    """a × b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def sub3(a, b):
    """a − b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, inline="always")
def add3(a, b):
    """a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True, inline="always")
def scale3(a, s):
    """s·a."""
    return (a[0] * s, a[1] * s, a[2] * s)


@njit(cache=True, inline="always")
def mv(M, v):
    """M·v."""
    return (M[0] * v[0] + M[1] * v[1] + M[2] * v[2], M[3] * v[0] + M[4] * v[1] + M[5] * v[2],
            M[6] * v[0] + M[7] * v[1] + M[8] * v[2])


@njit(cache=True, inline="always")
def mtv(M, v):
    """Mᵀ·v."""
    return (M[0] * v[0] + M[3] * v[1] + M[6] * v[2], M[1] * v[0] + M[4] * v[1] + M[7] * v[2],
            M[2] * v[0] + M[5] * v[1] + M[8] * v[2])


@njit(cache=True, inline="always")
def mm(A, B):
    """A·B."""
    return (A[0] * B[0] + A[1] * B[3] + A[2] * B[6], A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
            A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
            A[3] * B[0] + A[4] * B[3] + A[5] * B[6], A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
            A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
            A[6] * B[0] + A[7] * B[3] + A[8] * B[6], A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
            A[6] * B[2] + A[7] * B[5] + A[8] * B[8])


@njit(cache=True, inline="always")
def transpose(M):
    """Mᵀ."""
    return (M[0], M[3], M[6], M[1], M[4], M[7], M[2], M[5], M[8])


@njit(cache=True, inline="always")
def rotation(k, theta):
    """R(k, θ): rotation by θ [rad] about the unit axis k (Rodrigues), row by row."""
    c, s = np.cos(theta), np.sin(theta)
    C = 1.0 - c
    x, y, z = k[0], k[1], k[2]
    return (c + x * x * C, x * y * C - z * s, x * z * C + y * s,
            y * x * C + z * s, c + y * y * C, y * z * C - x * s,
            z * x * C - y * s, z * y * C + x * s, c + z * z * C)


@njit(cache=True, inline="always")
def wrap(theta):
    """θ wrapped into (−π, π]."""
    return np.arctan2(np.sin(theta), np.cos(theta))


@njit(cache=True)
def sp1(k, p1, p2):
    """Subproblem 1: (status, θ) with R(k, θ)·p₁ = p₂ in the plane normal to k; status DEGENERATE (θ = 0)
    when p₁ or p₂ lies on k, else 1 (the least-squares angle when their lengths across k differ)."""
    cos_part = dot3(p1, p2) - dot3(k, p1) * dot3(k, p2)
    sin_part = dot3(k, cross3(p1, p2))
    if np.hypot(cos_part, sin_part) < FLAT:
        return DEGENERATE, 0.0
    return 1, np.arctan2(sin_part, cos_part)


@njit(cache=True)
def sp4_range(h, k, p):
    """(centre, half-width) of the values hᵀ·R(k, θ)·p takes over θ (subproblem 4's reachable d)."""
    kp = dot3(k, p)
    return dot3(h, k) * kp, np.hypot(dot3(h, p) - dot3(h, k) * kp, dot3(h, cross3(k, p)))


@njit(cache=True)
def sp4(h, k, p, d):
    """Subproblem 4: (count, θ₁, θ₂) with hᵀ·R(k, θ)·p = d.

    hᵀ·R(k, θ)·p = a·cos θ + b·sin θ + c₀ with a = hᵀ(p − k kᵀp), b = hᵀ(k × p), c₀ = (hᵀk)(kᵀp): count 2
    (θ₁ = θ₂ at a double root), 0 when |d − c₀| exceeds √(a² + b²) by more than TANGENT_SLACK relatively, or
    DEGENERATE when a = b = 0 (every θ serves if d = c₀, none otherwise: the caller tells).
    """
    kp = dot3(k, p)
    a = dot3(h, p) - dot3(h, k) * kp
    b = dot3(h, cross3(k, p))
    r = np.hypot(a, b)
    if r < FLAT:
        return DEGENERATE, 0.0, 0.0
    x = (d - dot3(h, k) * kp) / r
    if abs(x) > 1.0:
        if abs(x) - 1.0 > TANGENT_SLACK:
            return 0, 0.0, 0.0
        x = 1.0 if x > 0 else -1.0
    phi = np.arctan2(b, a)
    alpha = np.arccos(x)
    return 2, phi + alpha, phi - alpha
