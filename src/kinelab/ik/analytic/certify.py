"""Proofs that an answer is a root, and that a set of branches is every root: Newton–Kantorovich on the loop
equations, and the eigenvalue count of the general 6R elimination (docs/analytic.md, "Certificates").

The loop equations of a 6R chain (h, o, R0, N0) at a target (R*, p*) are six: F(q) = ((p(q) − p*)/ℓ,
½ Σ_k R*e_k × R(q)e_k), ℓ a length scale (the reach bound). Their Jacobian's columns are (ω_j × (p − o_j)/ℓ,
½(ω_j tr(R*ᵀR) − R R*ᵀ ω_j)) and, turning joint i moving ω_j by ω_i × ω_j (i < j) and p by ω_i × (p − o_i),
change by at most 2D_j/ℓ or D_i/ℓ (position, i < j or i ≥ j) and 3.5 or 1.5 (rotation), D_j the distance from
axis j's point to the tool point bounded by the sum of the fixed segments between them. So F′ is Lipschitz with
L = ‖(those bounds)‖_F over all of R⁶, and Kantorovich's theorem applies: with β ≥ ‖F′(q)⁻¹‖ and
η ≥ ‖F′(q)⁻¹F(q)‖, h = βLη ≤ ½ proves exactly one root in the ball of radius (1 − √(1 − 2h))/(βL) about q and
no other within (1 + √(1 − 2h))/(βL). Floating-point evaluation is covered by a margin of 1e-13 on each
component of F and on F′'s singular values (ten times a bound on the FK's rounding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.core import _loop
from kinelab.geometry import wrap_to_pi

F_MARGIN = 1e-13  # rounding allowance on each component of F (scaled units) and on F′'s singular values: ten times
# a bound on the FK's rounding (six rotation products, entries of order one: ~1e-14)
MAX_STEPS = 60  # Newton steps at most when polishing: beside a double root Newton's method only halves the error a
# step; the steps stop as soon as no row's residual shrinks
SPLIT = 5e-8  # [rad] two roots beside a fold at least this far apart are two
F_ROUNDING = 1e-14  # a bound on the rounding of F's components (scaled units): beside a fold of curvature c the two
# roots are told apart only when σ² > 2|c|·F_ROUNDING, i.e. farther apart than ~2√(2·F_ROUNDING/|c|)


@dataclass(frozen=True, eq=False)
class Loop:
    """A 6R chain's loop equations for certificates: the chain (h, o, R0, N0) at q = 0 (base frame, metres),
    ``scale`` ℓ [m] and ``lipschitz`` L (scaled units)."""

    h: np.ndarray
    o: np.ndarray
    R0: np.ndarray
    N0: np.ndarray
    scale: float
    lipschitz: float


def loop_of(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> Loop:
    """The loop equations of the chain (h (n, 3) unit axes, o (n, 3) points on them, R0, N0 the tool at q = 0)."""
    n = h.shape[0]
    segments = np.linalg.norm(np.diff(np.vstack([o, N0]), axis=0), axis=1)
    D = np.cumsum(segments[::-1])[::-1]  # D[j]: bound on ‖p − o_j‖ over every configuration
    scale = max(float(D[0]), 1e-3)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    position = np.where(i < j, 2 * D[j], D[i]) / scale
    rotation = np.where(i < j, 3.5, 1.5)
    h, o, R0, N0 = (np.ascontiguousarray(a, dtype=float) for a in (h, o, R0, N0))
    return Loop(h, o, R0, N0, scale, float(np.sqrt((position**2).sum() + (rotation**2).sum())))


def chain_pose(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The 4 × 4 tool pose of the chain (unit axes h through points o at q = 0, the tool at (R0, N0); base frame)
    at q [rad]: the product of exponentials."""
    M = np.eye(4)
    for k in range(len(q)):
        turn = np.eye(4)
        turn[:3, :3] = pin.exp3(h[k] * q[k])
        turn[:3, 3] = o[k] - turn[:3, :3] @ o[k]
        M = M @ turn
    tool = np.eye(4)
    tool[:3, :3], tool[:3, 3] = R0, N0
    return M @ tool


def inverse_pose(T: np.ndarray) -> np.ndarray:
    """The inverse of a rigid transform T (4 × 4)."""
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def equations(loop: Loop, q: np.ndarray, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """F (m, 6) and F′ (m, 6, n) of the loop equations at q (m, n) for the target H (4 × 4, base frame), compiled
    (:mod:`kinelab.core._loop`)."""
    q = np.ascontiguousarray(q, dtype=float)
    F, J = np.empty((q.shape[0], 6)), np.empty((q.shape[0], 6, q.shape[1]))
    _loop.equations(loop.h, loop.o, loop.R0, loop.N0, loop.scale, q, np.ascontiguousarray(H, dtype=float), F, J)
    return F, J


def polish(loop: Loop, q: np.ndarray, H: np.ndarray) -> np.ndarray:
    """Newton's method on the loop equations from q (m, n) [rad], at most MAX_STEPS steps, each row kept at its
    smallest residual ‖F‖ (beside a double root F′ is nearly singular and a step can run along the valley)."""
    best = np.array(q, dtype=float)
    if best.shape[0] == 0:
        return best
    F, J = equations(loop, best, H)
    low = np.linalg.norm(F, axis=1)
    x = best.copy()
    for _ in range(MAX_STEPS):
        if not np.isfinite(F).all() or low.max() < 1e-15:
            break
        x = x - _steps(J, F)
        F, J = equations(loop, x, H)
        size = np.linalg.norm(F, axis=1)
        better = size < low
        if not better.any():  # rounding reached on every row
            break
        best[better], low[better] = x[better], size[better]
    return best


def _steps(J: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Newton's steps J⁻¹F row by row (least squares where J is singular)."""
    try:
        return np.linalg.solve(J, F[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.array([np.linalg.lstsq(J[k], F[k], rcond=None)[0] for k in range(F.shape[0])])


@dataclass(frozen=True, eq=False)
class Proof:
    """Kantorovich's test at each row of q: ``proved`` (m,) h ≤ ½; ``inside`` (m,) [rad] the radius of the ball
    about q holding exactly one root; ``alone`` (m,) [rad] the radius within which it is the only root."""

    proved: np.ndarray
    inside: np.ndarray
    alone: np.ndarray


def kantorovich(loop: Loop, q: np.ndarray, H: np.ndarray) -> Proof:
    """Kantorovich's test of each configuration q (m, 6) [rad] as a root of the pose H's loop equations."""
    F, J = equations(loop, q, H)
    sigma = np.linalg.svd(J, compute_uv=False)
    smallest = sigma[:, -1] - F_MARGIN * (1 + sigma[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = np.where(smallest > 0, 1 / smallest, np.inf)
        eta = beta * (np.linalg.norm(F, axis=1) + np.sqrt(6) * F_MARGIN)
        bl = beta * loop.lipschitz
        h = bl * eta
        root = np.sqrt(np.clip(1 - 2 * h, 0, None))
        inside = np.where(h <= 0.5, (1 - root) / bl, np.inf)
        alone = np.where(h <= 0.5, (1 + root) / bl, 0.0)
    return Proof(np.isfinite(h) & (h <= 0.5), inside, alone)


def set_certificate(loop: Loop | None, H: np.ndarray, q: np.ndarray, merged: np.ndarray,
                    continuum: np.ndarray) -> tuple[str, str]:
    """("certified", "") when a closed form's branches q (k, 6) [rad] of the pose H are each proved a root, apart
    from one another, none a double root (``merged``) or one of a continuum: the closed form gives every root of
    its subproblems, so the set is every root within the limits; else ("search", why not)."""
    if loop is None:
        return "search", "a chain that is not 6R: its answers are not a square system Kantorovich's test takes"
    if (np.asarray(merged) > 1).any() or np.asarray(continuum).any():
        return "search", "a double root or a continuum of answers (a singular pose)"
    if q.shape[0] == 0:
        return "certified", ""
    proof = kantorovich(loop, q, H)
    if not proof.proved.all():
        return "search", "a branch Kantorovich's test does not prove (a singular configuration)"
    gap = np.abs(wrap_to_pi(q[:, None] - q[None]))
    apart = np.linalg.norm(gap, axis=2) > proof.inside[:, None] + proof.inside[None]
    np.fill_diagonal(apart, True)
    return ("certified", "") if apart.all() else ("search", "two branches whose balls meet")


MOST_ROOTS = 16  # the most isolated roots a 6R pose has (Raghavan and Roth)


def search_certificate(loop: Loop | None, H: np.ndarray, q: np.ndarray, merged: np.ndarray,
                       continuum: np.ndarray, most: int = MOST_ROOTS, who: str = "the 1-D search") -> tuple[str, str]:
    """A search's set of branches q (k, 6) [rad] of the pose H: ("certified", "") when it holds ``most`` branches
    each proved a root and apart (no pose has more), else ("search", why not)."""
    if q.shape[0] < most:
        return "search", (f"{who} is measured complete, not proved ({q.shape[0]} branches; {most} proved ones would "
                          "be)")
    return set_certificate(loop, H, q, merged, continuum)


def beside_fold(loop: Loop, x: np.ndarray, H: np.ndarray,
                within: float = 1e-5) -> tuple[np.ndarray, np.ndarray] | None:
    """The two real roots beside x (6,) [rad] along F′'s most nearly singular direction, polished and SPLIT apart,
    or None (x is a double root to rounding, or the pair beside it is complex). With J v = σ u the smallest singular
    pair, the equations along v are, on u, uᵀF(x + t·v) ≈ uᵀF(x) + σt + ½ct² with c = uᵀF″(v, v) (a central
    difference): its two roots t give the two starting points (one is x itself when x is already one of them).
    Where σ² ≤ 2|c|·F_ROUNDING the two are closer than rounding can tell (about 3e-6 rad at c = 0.01): None; so
    is a pair not both within ``within`` [rad] of x (the model led to a root elsewhere)."""
    F, J = equations(loop, x[None], H)
    U, sigma, Vt = np.linalg.svd(J[0])
    u, v, s = U[:, -1], Vt[-1], float(sigma[-1])
    step = 1e-3
    ahead, back = equations(loop, np.array([x + step * v, x - step * v]), H)[0]
    c = float(u @ (ahead - 2 * F[0] + back)) / step**2
    disc = s * s - 2 * c * float(u @ F[0])
    if c == 0 or disc < 0 or s * s <= 2 * abs(c) * F_ROUNDING:  # complex, or closer than rounding can tell
        return None
    t = (-s + np.array([1.0, -1.0]) * np.sqrt(disc)) / c
    two = polish(loop, x + t[:, None] * v, H)
    apart = _gap(two[0], two[1]) > SPLIT
    return (two[0], two[1]) if apart and max(_gap(two[0], x), _gap(two[1], x)) <= within else None


def _gap(a: np.ndarray, b: np.ndarray) -> float:
    """The largest joint difference [rad] of two configurations, modulo 2π."""
    return float(np.abs(wrap_to_pi(a - b)).max())


def split_merged(loop: Loop | None, H: np.ndarray, q: np.ndarray, merged: np.ndarray,
                 continuum: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed form's or a search's roots (q (m, 6) [rad], roots merged into each, one-of-a-continuum flags) with
    each merged row that is two close real roots (:func:`beside_fold`) given back as those two: roots closer than
    the kernels' merging distance are merged there, which beside a fold is two roots answered as one."""
    if loop is None or not ((merged > 1) & ~continuum).any():
        return q, merged, continuum
    rows, counts, flags = [], [], []
    for k in range(q.shape[0]):
        pair = beside_fold(loop, q[k], H) if merged[k] > 1 and not continuum[k] else None
        rows += [q[k]] if pair is None else list(pair)
        counts += [int(merged[k])] if pair is None else [1, 1]
        flags += [bool(continuum[k])] * (1 if pair is None else 2)
    return np.array(rows), np.array(counts, dtype=np.int64), np.array(flags, dtype=np.bool_)
