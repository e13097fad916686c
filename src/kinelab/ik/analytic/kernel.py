"""All the branches of one pose, compiled (:mod:`kinelab.core._analytic`), for the arms of the classes of
docs/analytic.md.

The chain is written as a product of exponentials at q = 0, everything in the base frame: unit axes h_i,
points o_i on them, the tool's rotation R0 and point N0. With R = R_target·R0ᵀ and v the target point less
what the last joints carry, the parallel triple leaves joint 1 one scalar equation (subproblem 4), the wrist
angles follow from the orientation (subproblems 4 and 1), the sum θ₂ + θ₃ + θ₄ from the rotation left over
(subproblem 1), and the planar elbow from a distance (subproblem 3) and an angle (subproblem 1).

Rows are written into ``out`` (angles in (−π, π], one row per root combination; coincident roots are
written twice and merged by the caller); ``free`` marks rows where a subproblem was degenerate and its
angle was set to 0 (a continuum of answers: a wrist or shoulder singularity).

A spherical wrist (axes 4, 5, 6 meeting at w) with h₂ ∥ h₃ is solved the classical way: the target fixes
the wrist point, which joints 1–3 alone move (joint 1 from its component along h₂, subproblem 4; joint 3
from its distance to axis 2's point, subproblem 3; joint 2 by subproblem 1); the rotation left for the wrist
gives joint 5 (subproblem 4), then joints 4 and 6 (subproblem 1 each). With axes 1 and 2 meeting at s
instead, the wrist point's distance from s fixes joint 3 (subproblem 3) and the turn of joints 1 and 2 onto
it is subproblem 2 (here subproblem 4 for joint 1, then subproblem 1 for joint 2).

With h₁ ∥ h₂ and h₃ ∥ h₄ ∥ h₅ (a turning platform carrying a planar arm, the youBot's heading and arm), the
rotation is R(h₁, θ₁)·R(h₃, θ₃)·R(h₆, q₆) with θ₁ = q₁ ± q₂ and θ₃ = q₃ ± q₄ ± q₅: θ₃ by subproblem 4, θ₁
and q₆ by subproblem 1; the point then fixes q₂ through the component along h₃ that the planar joints keep
(subproblem 4), and the planar elbow gives q₄ (subproblem 3) and q₃ (subproblem 1).
"""

from __future__ import annotations

import numpy as np

from kinelab.core import _analytic, threads

MAX_ROWS = 16  # distinct branches a pose can have (a cuspidal 6R has 16)
PARALLEL_5R, PARALLEL_6R, SPHERICAL_6R, MEETING_6R, TWO_THREE_6R = 0, 1, 2, 3, 4  # kernel codes (ArmClass.kind)
SEARCH_6R = 5  # the search classes' first code: 5 + 3·pair + shoulder (pair 0: axes 4, 5 meet, t = q6; 1: axes
# 5, 6 meet, t = q4; shoulder 0: h₂ ∥ h₃, 1: axes 1, 2 meet, 2: axes 2, 3 meet), core/_search.pxi
GENERAL_6R = 100  # any other 6R chain: the algebraic elimination (kinelab.ik.analytic.general; compiled: _general.pxi)
PIEPER_6R = 101  # axes 1, 2, 3 (or 4, 5, 6) through a point, the rest general: Pieper's decoupling (pieper.py)


def branches(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, H: np.ndarray,
             lower: np.ndarray, upper: np.ndarray, ref: np.ndarray, use_ref: bool, same: float, slack: float,
             out: np.ndarray, found: np.ndarray, free: np.ndarray) -> int:
    """Every distinct branch of the pose H (4 × 4, base frame) within the limits, in the robot's joint order.

    Roots closer than ``same`` [rad] joint by joint (modulo 2π) are one branch (``found`` counts them); each angle
    is moved to its copy within the limits (``slack`` [rad] allowed, then clipped) nearest ``ref`` (with
    ``use_ref``; else nearest 0). A mirrored class solves H⁻¹ with the chain read from the tool back.

    Returns:
        The number of branches written into ``out`` (MAX_ROWS × n rows), ``found`` (int64) and ``free`` (bool: one
        of a continuum).
    """
    h, o, lower, upper = _c(h, o, lower, upper)
    return _analytic.branches(kind, mirrored, h, o, R0, N0, H, lower, upper, ref, use_ref, same, slack, out, found,
                              free.view(np.uint8))


def branches_batch(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray,
                   H: np.ndarray, lower: np.ndarray, upper: np.ndarray, same: float, slack: float, out: np.ndarray,
                   found: np.ndarray, free: np.ndarray, count: np.ndarray) -> None:
    """:func:`branches` for every pose of the (B, 4, 4) stack H, in threads (copies nearest 0): out
    (B, MAX_ROWS, n), found and free (B, MAX_ROWS), count (B,) written."""
    h, o, lower, upper = _c(h, o, lower, upper)
    _analytic.branches_batch(kind, mirrored, h, o, R0, N0, H, lower, upper, same, slack, out, found,
                             free.view(np.uint8), count, threads.count())


def _c(*arrays: np.ndarray) -> list[np.ndarray]:
    return [np.ascontiguousarray(a, dtype=float) for a in arrays]
