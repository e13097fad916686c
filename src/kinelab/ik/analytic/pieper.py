"""Every branch of a 6R chain whose first three axes meet in a point and whose last three are general: Pieper's
decoupling (docs/analytic.md, "Three axes through a point"). The general elimination degenerates on such a chain
(its pencil is singular); a 7R arm with a spherical shoulder and its elbow joint held — the Panda's, the xArm7's —
leaves one. A chain whose last three axes meet is read from the tool (mirrored).

With s the shoulder point (axes 1, 2, 3 through it) and oMtarget = (R*, p*), the first three joints turn about s
and leave it where it is, so the last three must carry the point p = R0·R*ᵀ(s − p*) + N0 (s seen from the target,
placed as the tool is at q = 0) onto s: e^(ξ₄q₄)·e^(ξ₅q₅)·e^(ξ₆q₆)·p = s. Turning about axis 4 keeps the distance
from o₄ and the height along h₄, two equations in q₅, q₆; both are w·R₅(q₅)·z(q₆) = r(q₆) with z = R₆(q₆)(p − o₆) +
o₆ − o₅, linear in (cos q₅, sin q₅) through a 2 × 2 matrix that is a fixed one times a turn scaled by |z⊥| (z's part
across h₅), so cos²q₅ + sin²q₅ = 1 is one equation in q₆ alone: a trigonometric polynomial of degree two, up to
four roots, read by an exact five-point sampling and solved as a quartic in a tangent half-angle (with a fixed
offset, so that a root at a half-angle of ±π is ordinary). Each q₆ gives q₅, then q₄ (a turn onto s); the
rotation left for the shoulder, R₁R₂R₃ = R*·R0ᵀ·(R₄R₅R₆)ᵀ, gives q₂ (subproblem 4: two roots), q₁ and q₃
(subproblem 1 each). Up to 4 × 2 = 8 branches, each polished by Newton's method on the loop equations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.certify import Loop, chain_pose, inverse_pose, loop_of, polish
from kinelab.ik.limits import nearest_inside

SAME = 1e-5  # [rad] roots closer than this joint by joint are one branch (as the closed forms merge them)
NEAR_REAL = 1e-4  # a quartic root with |Im t| below this times (1 + |t|) is taken (a double root comes out complex)
MOST_ROOTS = 8  # the most branches the decoupling gives (4 positions × 2 shoulders): a set of 8 proved is complete
TANGENT = 1e-6  # a subproblem 4 whose |ratio| is within this of 1 is treated as tangent (its roots near a double one)
PROBE = 1e-3  # [rad] where the two roots of a tangent subproblem 4 start, either side of it
OFFSET_SEED = 20261205  # the fixed offset of q₆'s half-angle
_FIVE = 2 * np.pi * np.arange(5) / 5  # samples of a degree-2 trigonometric polynomial


@dataclass(frozen=True, eq=False)
class Pieper:
    """A chain prepared for :func:`roots`: its axes h, points o (6, 3) at q = 0 [m], tool (R0, N0), the shoulder
    point s, the plane across h₅ (e1, e2), the fixed 2 × 2 matrix's inverse (None when axes 4 and 5 meet, at
    ``meet``: then turning about either keeps the distance from that point, and the position is two subproblems),
    q₆'s offset [rad], the loop equations, and a 1-D search class the chain also fits (``also``, or None)."""

    h: np.ndarray
    o: np.ndarray
    R0: np.ndarray
    N0: np.ndarray
    s: np.ndarray
    e: np.ndarray
    W_inv: np.ndarray | None
    meet: np.ndarray | None
    phi: float
    loop: Loop
    also: object = None  # a 1-D search class the chain also fits: its roots are added (each method loses some)


def prepare(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, s: np.ndarray,
            meet: np.ndarray | None = None) -> Pieper | str:
    """The chain (h, o, R0, N0) whose axes 1, 2, 3 meet at s (and axes 4, 5 at ``meet``, when they do), prepared;
    or why the decoupling cannot take it (axes 4 and 5 parallel)."""
    h5 = h[4]
    e1 = np.cross(h5, [1.0, 0.0, 0.0] if abs(h5[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e = np.array([e1, np.cross(h5, e1)])
    phi = float(np.random.default_rng(OFFSET_SEED).uniform(-np.pi, np.pi))
    if meet is not None:
        return Pieper(h, o, R0, N0, s, e, None, meet, phi, loop_of(h, o, R0, N0))
    W = np.array([e @ (2 * (o[4] - o[3])), e @ h[3]])
    if abs(np.linalg.det(W)) < 1e-9 * max(1.0, float(np.abs(W).max()) ** 2):
        return "axes 4 and 5 parallel"
    return Pieper(h, o, R0, N0, s, e, np.linalg.inv(W), None, phi, loop_of(h, o, R0, N0))


def _turn(h: np.ndarray, q: float) -> np.ndarray:
    return np.asarray(pin.exp3(h * q))


def _z(p: Pieper, point: np.ndarray, q6: float) -> np.ndarray:
    return _turn(p.h[5], q6) @ (point - p.o[5]) + p.o[5] - p.o[4]


def _across(p: Pieper, point: np.ndarray, q6: float) -> tuple[np.ndarray, np.ndarray]:
    """g = W⁻¹·r(q₆) and ζ (z's coordinates across h₅) at q₆: (cos q₅, sin q₅) turns ζ into g."""
    h4, h5, o4, o5 = p.h[3], p.h[4], p.o[3], p.o[4]
    z = _z(p, point, q6)
    along = float(h5 @ z)
    r = np.array([float((p.s - o4) @ (p.s - o4) - (o5 - o4) @ (o5 - o4) - z @ z) - 2 * float((o5 - o4) @ h5) * along,
                  float(h4 @ (p.s - o5)) - float(h4 @ h5) * along])
    assert p.W_inv is not None
    return p.W_inv @ r, p.e @ z


def _shoulder_error(p: Pieper, point: np.ndarray, q6: float) -> float:
    g, zeta = _across(p, point, q6)
    return float(g @ g - zeta @ zeta)


def _q6_roots(p: Pieper, point: np.ndarray) -> np.ndarray:
    """The angles q₆ [rad] where the shoulder equation holds: its five Fourier coefficients from five samples, the
    quartic in t = tan((q₆ − φ)/2), its real (and nearly real) roots."""
    f = np.array([_shoulder_error(p, point, p.phi + a) for a in _FIVE])
    c = np.fft.rfft(f) / 5  # f(φ + θ) = c0 + 2 Re(c1 e^{iθ}) + 2 Re(c2 e^{2iθ})
    a0, a1, b1, a2, b2 = c[0].real, 2 * c[1].real, -2 * c[1].imag, 2 * c[2].real, -2 * c[2].imag
    # times (1 + t²)², with cos θ = (1 − t²)/(1 + t²), sin θ = 2t/(1 + t²): coefficients of t⁴ … t⁰
    quartic = (a0 * np.array([1.0, 0.0, 2.0, 0.0, 1.0]) + a1 * np.array([-1.0, 0.0, 0.0, 0.0, 1.0])
               + b1 * np.array([0.0, 2.0, 0.0, 2.0, 0.0]) + a2 * np.array([1.0, 0.0, -6.0, 0.0, 1.0])
               + b2 * np.array([0.0, -4.0, 0.0, 4.0, 0.0]))
    coeffs = np.trim_zeros(quartic, "f")
    if coeffs.size <= 1:
        return np.empty(0)
    t = np.roots(coeffs)
    t = t[np.abs(t.imag) <= NEAR_REAL * (1 + np.abs(t))].real
    return np.asarray(p.phi + 2 * np.arctan(t))  # a root at θ = π (t = ∞) has probability zero: φ is random


def _angle(k: np.ndarray, u: np.ndarray, v: np.ndarray) -> float:
    """Subproblem 1: the turn about k taking u's part across k to v's."""
    return float(np.arctan2(k @ np.cross(u, v), u @ v - (k @ u) * (k @ v)))


def _sub4(h: np.ndarray, k: np.ndarray, u: np.ndarray, d: float) -> tuple[list[float], bool]:
    """Subproblem 4: the angles θ with hᵀR(k, θ)u = d (two starts, the two roots or either side of a double one;
    none), and whether every θ serves (hᵀR(k, θ)u does not depend on θ)."""
    a = float(h @ u - (h @ k) * (k @ u))
    b = float(h @ np.cross(k, u))
    rest = d - float((h @ k) * (k @ u))
    size = float(np.hypot(a, b))
    if size < 1e-12:
        return [0.0], True
    ratio = rest / size
    if abs(ratio) > 1 + TANGENT:
        return [], False
    base = float(np.arctan2(b, a))
    # near tangency the two roots are closer than rounding places them (the ratio may even pass ±1): start
    # Newton's method PROBE to either side, and let it find them (or the double root, then merged and said so)
    spread = max(float(np.arccos(np.clip(ratio, -1.0, 1.0))), PROBE) if abs(ratio) > 1 - TANGENT else \
        float(np.arccos(ratio))
    return [base + spread, base - spread], False


def _wrist_general(p: Pieper, point: np.ndarray) -> list[tuple[float, float, float]]:
    """(q₄, q₅, q₆) [rad] carrying ``point`` onto s, axes 4 and 5 not meeting: q₆ from the quartic, then q₅, q₄."""
    out = []
    for q6 in _q6_roots(p, point):
        g, zeta = _across(p, point, q6)
        norm = float(zeta @ zeta)
        if norm < 1e-18:
            continue
        c5, s5 = (zeta[0] * g[0] + zeta[1] * g[1]) / norm, (zeta[0] * g[1] - zeta[1] * g[0]) / norm
        q5 = float(np.arctan2(s5, c5))
        x = _turn(p.h[4], q5) @ _z(p, point, q6) + p.o[4]
        out.append((_angle(p.h[3], x - p.o[3], p.s - p.o[3]), q5, float(q6)))
    return out


def _wrist_meeting(p: Pieper, point: np.ndarray) -> list[tuple[float, float, float]]:
    """(q₄, q₅, q₆) [rad] carrying ``point`` onto s, axes 4 and 5 meeting at m: turns about them keep the distance
    from m, so q₆ is subproblem 3 (two roots), q₅ subproblem 4 and q₄ subproblem 1."""
    m, h4, h5, h6 = p.meet, p.h[3], p.h[4], p.h[5]
    assert m is not None
    u, d = point - p.o[5], p.o[5] - m
    target = float((p.s - m) @ (p.s - m))
    out = []
    for q6 in _sub4(d, h6, u, 0.5 * (target - float(u @ u) - float(d @ d)))[0]:
        x = _turn(h6, q6) @ u + d
        for q5 in _sub4(h4, h5, x, float(h4 @ (p.s - m)))[0]:
            out.append((_angle(h4, _turn(h5, q5) @ x, p.s - m), q5, q6))
    return out


def _candidates(p: Pieper, H: np.ndarray) -> tuple[list[np.ndarray], list[bool]]:
    """Every (q, one of a continuum) the decoupling gives for the pose H, before polishing."""
    Rt, pt = H[:3, :3], H[:3, 3]
    point = p.R0 @ (Rt.T @ (p.s - pt)) + p.N0
    rows: list[np.ndarray] = []
    free: list[bool] = []
    for q4, q5, q6 in (_wrist_meeting if p.meet is not None else _wrist_general)(p, point):
        rest = Rt @ p.R0.T @ (_turn(p.h[3], q4) @ _turn(p.h[4], q5) @ _turn(p.h[5], q6)).T
        v = rest @ p.h[2]
        q2s, loose = _sub4(p.h[0], p.h[1], p.h[2], float(p.h[0] @ v))
        for q2 in q2s:
            u = _turn(p.h[1], q2) @ p.h[2]
            q1 = _angle(p.h[0], u, v)
            x3 = np.cross(p.h[2], p.e[0] if abs(p.e[0] @ p.h[2]) < 0.9 else p.e[1])
            R12 = _turn(p.h[0], q1) @ _turn(p.h[1], q2)
            q3 = _angle(p.h[2], x3, R12.T @ rest @ x3)
            rows.append(np.array([q1, q2, q3, q4, q5, q6]))
            free.append(loose or bool(np.linalg.norm(np.cross(p.h[0], v)) < 1e-9))
    return rows, free


def roots(p: Pieper, H: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every root of the pose H (4 × 4, base frame): (q (m, 6) [rad] in (−π, π], polished; roots merged into each
    (2 at a double root); one-of-a-continuum flags)."""
    rows, free = _candidates(p, H)
    if not rows:
        return np.empty((0, 6)), np.empty(0, dtype=np.int64), np.empty(0, dtype=np.bool_)
    q = wrap_to_pi(polish(p.loop, np.array(rows), H))
    keep: list[int] = []
    merged: list[int] = []
    for k in range(q.shape[0]):
        for n, j in enumerate(keep):
            if np.abs(wrap_to_pi(q[k] - q[j])).max() < SAME:
                merged[n] += 1
                break
        else:
            keep.append(k)
            merged.append(1)
    return q[keep], np.array(merged, dtype=np.int64), np.array(free, dtype=np.bool_)[keep]


TRIALS = 4  # seeded configurations the decoupling must recover before a chain is accepted


def usable(p: Pieper) -> str:
    """"" when the decoupling recovers TRIALS seeded configurations of its chain (to 1e-9 rad), else why not."""
    for q in np.random.default_rng(OFFSET_SEED).uniform(-np.pi, np.pi, (TRIALS, 6)):
        found = roots(p, chain_pose(p.h, p.o, p.R0, p.N0, q))[0]
        if not len(found) or np.abs(wrap_to_pi(found - q)).max(axis=1).min() > 1e-9:
            return "it misses the chain's own configurations"
    return ""


def roots_within(arm: object, H: np.ndarray, lower: np.ndarray, upper: np.ndarray, ref: np.ndarray | None,
                 slack: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arm's roots of the pose H (4 × 4, base frame) within the limits [lower, upper] (rad; a root up to
    ``slack`` outside clipped to it), each angle's copy nearest ``ref`` (None: nearest 0); with the roots merged
    into each and one-of-a-continuum flags."""
    p: Pieper = arm.solver  # type: ignore[attr-defined]
    if arm.mirrored:  # type: ignore[attr-defined]
        q, merged, free = roots(p, inverse_pose(H))
        q = -q[:, ::-1]
    else:
        q, merged, free = roots(p, H)
    q, keep = nearest_inside(q, lower, upper, ref, slack)
    return q, merged[keep], free[keep]


def merged_sets(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two solvers' roots of one pose (q (m, 6) [rad], roots merged into each, one-of-a-continuum flags), placed
    alike: their union, a root of b within SAME of one of a (joint by joint, modulo 2π) counted as that one."""
    q, merged, free = (np.array(x) for x in a)
    extra = [k for k in range(len(b[0])) if not len(q) or np.abs(wrap_to_pi(q - b[0][k])).max(axis=1).min() >= SAME]
    return (np.vstack([q.reshape(-1, 6), b[0][extra]]), np.concatenate([merged, b[1][extra]]).astype(np.int64),
            np.concatenate([free, b[2][extra]]).astype(np.bool_))
