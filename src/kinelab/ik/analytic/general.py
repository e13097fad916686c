"""Every branch of a general 6R arm by algebraic elimination (Raghavan and Roth's invariants, Manocha and Canny's
eigenproblem), in the product-of-exponentials form kinelab reads from the model (docs/analytic.md, "Any 6R arm").

The chain at q is G₀·Rz(θ₁)·G₁·Rz(θ₂)·…·Rz(θ₆)·G₆ with G_i constant frames and θ_i = q_i − φ_i (φ a fixed
draw of offsets, so that no root sits at a half-angle of ±π for a pose that is not built for it). With
T' = G₀⁻¹·oMtarget·G₆⁻¹ and (l₀, p₀) its z axis and point, the loop
G₂·Rz(θ₃)·G₃·Rz(θ₄)·G₄·Rz(θ₅)·G₅·(e_z, 0) = Rz(−θ₂)·G₁⁻¹·Rz(−θ₁)·(l₀, p₀) holds; 14 invariants of (l, p)
(p, l, p·p, p·l, p×l, (p·p)l − 2(p·l)p) are, on the left, trigonometric polynomials of degree one in each of
θ₃, θ₄, θ₅ and, on the right, of degree one in each of θ₁, θ₂: P(θ₃)·m₄₅ = r₀ + Q·m₁₂. The six rows N with
N·Q = 0 leave six equations in θ₃, θ₄, θ₅; with tangent half-angles and the six multiplied by x₄ they are a
12 × 12 matrix quadratic in x₃, whose 24 eigenvalues are the pose's 16 roots and 8 at ±i. Each real root gives
θ₄, θ₅ from its eigenvector, θ₁, θ₂ from Q, θ₆ from the rest of the rotation, and Newton's method polishes it
on the whole pose. The coefficients are read by sampling each side at three angles a joint (an exact discrete
Fourier transform): the left side once per arm, the right side once per pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinelab.core import _blas
from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.certify import Loop, Proof, beside_fold, chain_pose, inverse_pose, kantorovich, polish
from kinelab.ik.limits import nearest_inside

SPURIOUS = 8  # eigenvalues at x₃ = ±i that every pose's determinant carries: (1 + x₃²)⁴
SPURIOUS_TOL = 1e-6  # [chordal] an eigenvalue this close to ±i is one of them (found within ~1e-13; a root nearer
# is rare and leaves the set uncertified, never wrong)
SINGULAR_PENCIL = "the pencil is singular or nearly so"
QZ_FAILED = -1.0  # Eigen.rank when LAPACK's QZ did not converge
RANK_TOL = 1e-9  # Q's smallest kept singular value relative to its largest: below it the elimination is refused
_ANGLES = np.array([0.0, 2 * np.pi / 3, 4 * np.pi / 3])
_FOURIER = np.linalg.inv(np.stack([np.ones(3), np.cos(_ANGLES), np.sin(_ANGLES)]).T)  # samples → (1, cos, sin)
_HALF = np.array([[1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [0.0, 2.0, 0.0]])  # (1, c, s)·(1 + x²) over (1, x, x²)
_FROM_TRIG = np.linalg.inv(np.kron(_HALF, _HALF)).T  # (1, c, s)⊗(1, c, s) rows → x₄ⁱx₅ʲ over (1+x₄²)(1+x₅²)
OFFSET_SEED = 20261204  # the offsets φ: one fixed draw, so a pose's answers do not change between calls


@dataclass(frozen=True, eq=False)
class General6R:
    """A 6R chain prepared for :func:`solve`: its frames and the left side's coefficients.

    Attributes:
        h, o, R0, N0: the chain at q = 0 (unit axes, points on them [m], tool rotation and point; base frame).
        phi: (6,) the offsets φ [rad]; frames: (7, 4, 4) G₀ … G₆.
        left: (3, 14, 9) P's coefficients of 1, cos θ₃, sin θ₃, already over the monomials x₄ⁱx₅ʲ (i, j ≤ 2).
        one: (9,) the constant monomial's row over x₄ⁱx₅ʲ.
        right_R: (9, 3, 3), right_t: (9, 3): Rz(−b)·G₁⁻¹·Rz(−a) at the nine sample pairs (a, b).
    """

    h: np.ndarray
    o: np.ndarray
    R0: np.ndarray
    N0: np.ndarray
    phi: np.ndarray
    frames: np.ndarray
    left: np.ndarray
    one: np.ndarray
    right_R: np.ndarray
    right_t: np.ndarray


@dataclass(frozen=True, eq=False)
class Eigen:
    """The pose's eigenproblem, kept for the certificate: ``alpha``, ``beta`` (24,) homogeneous eigenvalues
    (x₃ = α/β), ``kappa`` (24,) their condition numbers (chordal metric), ``scale`` the pencil's Frobenius norm
    (a bound on its 2-norm), ``rank`` Q's smallest singular value relative to its largest, ``picked`` the indices
    of the eigenvalues that may be real, one root each."""

    alpha: np.ndarray
    beta: np.ndarray
    kappa: np.ndarray
    scale: float
    rank: float
    picked: np.ndarray  # the eigenvalues that may be real, one root each, in the order of the roots


def rz(theta: np.ndarray | float) -> np.ndarray:
    """Homogeneous rotations about z by ``theta`` [rad]: (..., 4, 4)."""
    c, s = np.cos(theta), np.sin(theta)
    out = np.zeros(np.shape(theta) + (4, 4))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = out[..., 3, 3] = 1.0
    return out


def _frame(h: np.ndarray, o: np.ndarray) -> np.ndarray:
    """A frame at o whose z axis is h."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(h[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, h)
    x /= np.linalg.norm(x)
    out = np.eye(4)
    out[:3, 0], out[:3, 1], out[:3, 2], out[:3, 3] = x, np.cross(h, x), h, o
    return out


def invariants(line: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Raghavan and Roth's 14 invariants of a unit direction ``line`` and a point p: (..., 14)."""
    pp = np.einsum("...i,...i->...", p, p)[..., None]
    pl = np.einsum("...i,...i->...", p, line)[..., None]
    return np.concatenate([p, line, pp, pl, np.cross(p, line), pp * line - 2 * pl * p], axis=-1)


def prepare(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> General6R:
    """The chain (h, o, R0, N0) at q = 0 (base frame, metres) prepared for :func:`solve`."""
    phi = np.random.default_rng(OFFSET_SEED).uniform(-np.pi, np.pi, 6)
    Z = [_frame(h[i] / np.linalg.norm(h[i]), o[i]) for i in range(6)]
    tool = np.eye(4)
    tool[:3, :3], tool[:3, 3] = R0, N0
    G = np.array([Z[0] @ rz(phi[0])] + [inverse_pose(Z[i]) @ Z[i + 1] @ rz(phi[i + 1]) for i in range(5)]
                 + [inverse_pose(Z[5]) @ tool])
    turns = rz(_ANGLES)
    chain = np.einsum("ij,ajk->aik", G[2], turns) @ G[3]
    chain = np.einsum("aij,bjk->abik", chain, turns) @ G[4]
    chain = np.einsum("abij,cjk->abcik", chain, turns) @ G[5]
    samples = invariants(chain[..., :3, 2], chain[..., :3, 3])  # (3, 3, 3, 14) over θ₃, θ₄, θ₅
    coeff = np.einsum("ia,jb,kc,abce->ijke", _FOURIER, _FOURIER, _FOURIER, samples)
    half = np.kron(_HALF, _HALF)
    left = np.einsum("ime,mn->ien", coeff.reshape(3, 9, 14), half)
    G1i = inverse_pose(G[1])
    pairs = rz(-_ANGLES)[None, :] @ G1i @ rz(-_ANGLES)[:, None]  # [a, b] = Rz(−b)·G₁⁻¹·Rz(−a)
    return General6R(h, o, R0, N0, phi, G, left, half[0].copy(), pairs[..., :3, :3].reshape(9, 3, 3),
                     pairs[..., :3, 3].reshape(9, 3))


PACKED_SIZE = 776  # the compiled elimination's packed data (kinelab/core/_general.pxi, layout G_*)


def packed(g: General6R, loop: Loop) -> np.ndarray:
    """The prepared chain ``g`` and its loop equations' length scale as the compiled elimination reads them
    (kinelab/core/_general.pxi): φ, G₀⁻¹, G₆⁻¹, G₁ … G₅, P's coefficients, the constant monomial's row, the right
    side's sample frames, the two Fourier matrices, ℓ."""
    out = np.concatenate([g.phi, inverse_pose(g.frames[0]).ravel(), inverse_pose(g.frames[6]).ravel(),
                          g.frames[1:6].ravel(), g.left.ravel(), g.one, g.right_R.ravel(), g.right_t.ravel(),
                          np.kron(_FOURIER, _FOURIER).ravel(), _FROM_TRIG.ravel(), [loop.scale]])
    if out.size != PACKED_SIZE:
        raise AssertionError(f"the packed elimination has {out.size} numbers, the compiled one reads {PACKED_SIZE}")
    return out


def _right(g: General6R, H: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The right side of the pose H: r₀ (14,), Q (14, 8) over (c₂, s₂, c₁, c₁c₂, c₁s₂, s₁, s₁c₂, s₁s₂), and T'."""
    Tp = inverse_pose(g.frames[0]) @ H @ inverse_pose(g.frames[6])
    line = g.right_R @ Tp[:3, 2]
    point = g.right_R @ Tp[:3, 3] + g.right_t
    coeff = np.kron(_FOURIER, _FOURIER) @ invariants(line, point)  # (9, 14)
    return coeff[0], coeff[1:].T, Tp


def _pencil(g: General6R, r0: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """The 24 × 24 pencil (A, B) whose eigenvalues are x₃ = tan(θ₃/2), Q's rank margin (smallest singular value
    over the largest) and Q's pseudo-inverse."""
    U, s, Vt = np.linalg.svd(Q)
    N = U[:, 8:].T
    E = N @ g.left  # (3, 6, 9): the six equations' coefficients of 1, cos θ₃, sin θ₃
    E[0] -= np.outer(N @ r0, g.one)
    quad = (E[0] - E[1], 2 * E[2], E[0] + E[1])  # times (1 + x₃²): coefficients of x₃², x₃, 1
    M = np.zeros((3, 12, 12))
    for k, A in enumerate(quad):
        M[k, :6, :9], M[k, 6:, 3:] = A, A
    eye, zero = np.eye(12), np.zeros((12, 12))
    A = np.block([[zero, eye], [-M[2], -M[1]]])
    B = np.block([[eye, zero], [zero, M[0]]])
    with np.errstate(divide="ignore"):
        pinv = (Vt.T / s) @ U[:, :8].T
    return A, B, float(s[7] / s[0]), pinv


def _angles(v: np.ndarray) -> np.ndarray:
    """The angles θ [rad] of rows proportional to (1, x, x², …), x = tan(θ/2), each from its best-scaled pair."""
    k = np.argmax(np.abs(v[:, :-1]) + np.abs(v[:, 1:]), axis=1)
    rows = np.arange(v.shape[0])
    return 2 * np.arctan2(v[rows, k + 1], v[rows, k])


def _real_rank_one(w: np.ndarray) -> np.ndarray:
    """The real unit vectors of rows w (m, k) that are complex multiples of real ones (phase removed)."""
    big = w[np.arange(w.shape[0]), np.argmax(np.abs(w), axis=1)]
    return (w * (np.conj(big) / np.abs(big))[:, None]).real


def _wrist(vectors: np.ndarray, x3: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """θ₄, θ₅ [rad] from eigenvectors (24, m): x₄ⁱx₅ʲ over i ≤ 3, j ≤ 2, then x₃ times them."""
    w = np.where(np.abs(x3)[None, :] <= 1, vectors[:12], vectors[12:]).T.reshape(-1, 4, 3)
    u, _, vt = np.linalg.svd(w)
    return _angles(_real_rank_one(u[:, :, 0])), _angles(_real_rank_one(vt[:, 0, :]))


def _shoulder_and_tool(g: General6R, r0: np.ndarray, pinv: np.ndarray, Tp: np.ndarray, t3: np.ndarray,
                       t4: np.ndarray, t5: np.ndarray) -> np.ndarray:
    """θ₁ … θ₆ [rad] (m, 6) from θ₃, θ₄, θ₅ (m,): θ₁, θ₂ by least squares on Q·m₁₂ = P(θ₃)·m₄₅ − r₀, θ₆ from the
    rotation left."""
    c4, s4, c5, s5 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    m4 = np.stack([np.ones_like(t4), c4, s4], axis=1)
    m5 = np.stack([np.ones_like(t5), c5, s5], axis=1)
    m45 = (m4[:, :, None] * m5[:, None, :]).reshape(-1, 9) @ _FROM_TRIG
    P = g.left[0] + np.cos(t3)[:, None, None] * g.left[1] + np.sin(t3)[:, None, None] * g.left[2]
    m12 = (np.einsum("mej,mj->me", P, m45) - r0) @ pinv.T
    t1, t2 = np.arctan2(m12[:, 5], m12[:, 2]), np.arctan2(m12[:, 1], m12[:, 0])
    turns = rz(np.stack([t1, t2, t3, t4, t5], axis=1))  # (m, 5, 4, 4)
    M = turns[:, 0] @ g.frames[1] @ turns[:, 1] @ g.frames[2] @ turns[:, 2] @ g.frames[3] @ turns[:, 3] \
        @ g.frames[4] @ turns[:, 4] @ g.frames[5]
    last = np.swapaxes(M[:, :3, :3], 1, 2) @ Tp[:3, :3]
    return np.stack([t1, t2, t3, t4, t5, np.arctan2(last[:, 1, 0], last[:, 0, 0])], axis=1)


def real_root(alpha: np.ndarray, beta: np.ndarray, kappa: np.ndarray, scale: float) -> np.ndarray:
    """Which eigenvalues α/β may be real: their distance to the real line (:func:`chordal_to_real`) is within their
    perturbation bound (a few roundings times the condition number) or within 1e-6 (a close pair's imaginary
    part: Newton's method then settles it)."""
    return chordal_to_real(alpha, beta) <= np.maximum(1e-6, _radius(kappa, scale))


def chordal_to_real(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """A lower bound on the chordal distance from the eigenvalues α/β (homogeneous, ∞ allowed) to the real line:
    |Im(a·b̄)| with (a, b) = (α, β)/‖(α, β)‖ (0 exactly when the eigenvalue is real or ∞)."""
    norm = np.hypot(np.abs(alpha), np.abs(beta))
    return np.abs((alpha * np.conj(beta)).imag) / norm**2


def solve(g: General6R, H: np.ndarray) -> tuple[np.ndarray, Eigen]:
    """The real roots of the pose H (4 × 4, base frame) before polishing: (m, 6) joint angles [rad] in (−π, π]
    (m ≤ 16), one per eigenvalue that may be real, and the eigenproblem."""
    r0, Q, Tp = _right(g, H)
    A, B, rank, pinv = _pencil(g, r0, Q)
    if rank < RANK_TOL:
        return np.empty((0, 6)), Eigen(np.empty(0), np.empty(0), np.empty(0), 0.0, rank, np.empty(0, dtype=int))
    try:
        alpha, beta, vl, vr = _ggev(A, B)
    except np.linalg.LinAlgError:  # QZ did not converge (seen on a singular pencil): no root, and said so
        return np.empty((0, 6)), Eigen(np.empty(0), np.empty(0), np.empty(0), 0.0, QZ_FAILED, np.empty(0, dtype=int))
    kappa = _conditions(A, B, vl, vr)
    scale = float(np.hypot(np.linalg.norm(A), np.linalg.norm(B)))  # Frobenius: a bound on the 2-norm, and no SVD
    real = np.flatnonzero(real_root(alpha, beta, kappa, scale))
    eigen = Eigen(alpha, beta, kappa, scale, rank, real)
    if real.size == 0:
        return np.empty((0, 6)), eigen
    a, b = alpha[real], beta[real]
    big = np.where(np.abs(a) > np.abs(b), a, b)
    phase = np.conj(big) / np.abs(big)  # (α, β) turned real: x₃ = α/β, ∞ included
    t3 = 2 * np.arctan2((a * phase).real, (b * phase).real)
    with np.errstate(divide="ignore", invalid="ignore"):
        x3 = np.where(np.abs(b) > 0, np.abs(a) / np.abs(b), np.inf)
    t4, t5 = _wrist(vr[:, real], x3)
    q = _shoulder_and_tool(g, r0, pinv, Tp, t3, t4, t5) + g.phi
    return wrap_to_pi(q), eigen


def _ggev(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """LAPACK's QZ (``dggev``) of the pencil (A, B): homogeneous eigenvalues α (complex), β (real) and the left and
    right eigenvectors as complex columns (LAPACK packs a complex pair's as two real ones)."""
    alphar, alphai, beta, vl, vr, info = _blas.ggev(A, B)
    if info != 0:
        raise np.linalg.LinAlgError(f"dggev failed (info {info})")
    return alphar + 1j * alphai, beta.astype(complex), _unpacked(vl, alphai), _unpacked(vr, alphai)


def _unpacked(v: np.ndarray, alphai: np.ndarray) -> np.ndarray:
    """LAPACK's real eigenvector columns as complex ones: a pair (α_j, α_j+1) with α_j's imaginary part > 0 holds
    the real and imaginary parts of the first vector; the second is its conjugate."""
    out = v.astype(complex)
    first = np.flatnonzero(alphai > 0)
    out[:, first] = v[:, first] + 1j * v[:, first + 1]
    out[:, first + 1] = np.conj(out[:, first])
    return out


def _conditions(A: np.ndarray, B: np.ndarray, vl: np.ndarray, vr: np.ndarray) -> np.ndarray:
    """Each eigenvalue's condition number in the chordal metric: ‖x‖‖y‖ / |(yᴴAx, yᴴBx)| (∞ where defective)."""
    ya = np.einsum("ik,ij,jk->k", vl.conj(), A, vr)
    yb = np.einsum("ik,ij,jk->k", vl.conj(), B, vr)
    den = np.hypot(np.abs(ya), np.abs(yb))
    with np.errstate(divide="ignore"):
        return np.where(den > 0, np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0) / den, np.inf)


def radii(eigen: Eigen) -> np.ndarray:
    """Each eigenvalue's perturbation bound in the chordal metric (:func:`_radius`)."""
    return _radius(eigen.kappa, eigen.scale)


def _radius(kappa: np.ndarray, scale: float) -> np.ndarray:
    """The chordal perturbation bound of eigenvalues of condition ``kappa`` in a pencil of norm ``scale``: 64
    roundings of the pencil times the condition."""
    return 64 * np.finfo(float).eps * kappa * scale


def _unit(alpha: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    norm = np.hypot(np.abs(alpha), np.abs(beta))
    return alpha / norm, beta / norm


def counted(eigen: Eigen, q: np.ndarray, proved: np.ndarray, phi3: float) -> str:
    """Why the eigenvalues do not prove that the distinct roots q (m, 6) [rad] (``proved``: Kantorovich's test
    held) are every real root ("" when they do). SPURIOUS eigenvalues must sit at ±i; the others are grouped in
    clusters of overlapping disks (each eigenvalue's perturbation bound, :func:`radii`). A cluster whose disks all
    stay off the real line holds no real root; any other, of k eigenvalues, must hold k proved roots (their x₃ on
    its disks): a real pencil's k eigenvalues there are then all real, and all found. Every root must lie on a
    cluster's disks."""
    if eigen.rank == QZ_FAILED:
        return f"LAPACK's QZ did not converge at this pose: {SINGULAR_PENCIL}"
    if eigen.rank < RANK_TOL:
        return f"the elimination is degenerate at this pose (Q's rank margin {eigen.rank:.1e})"
    a, b = _unit(eigen.alpha, eigen.beta)
    at_i = np.minimum(np.abs(a - 1j * b), np.abs(a + 1j * b)) / np.sqrt(2) < SPURIOUS_TOL
    if at_i.sum() != SPURIOUS:
        return f"{int(at_i.sum())} eigenvalues near ±i, not {SPURIOUS}: {SINGULAR_PENCIL}"
    r = radii(eigen)
    if not np.isfinite(r[~at_i]).all():
        return "a defective eigenvalue (a double root the eigenvalues cannot separate)"
    half = (q[:, 2] - phi3) / 2
    on = np.abs(a[None, :] * np.cos(half)[:, None] - b[None, :] * np.sin(half)[:, None]) <= r[None, :] + 1e-9
    off_line = chordal_to_real(eigen.alpha, eigen.beta) > r
    held = np.zeros(q.shape[0], dtype=np.bool_)
    for cluster in _clusters(a, b, r, ~at_i):
        if off_line[cluster].all():
            continue
        inside = on[:, cluster].any(axis=1)
        held |= inside
        if int((inside & proved).sum()) != len(cluster):
            return (f"a near-double root: {len(cluster)} eigenvalues too close to tell apart, "
                    f"{int((inside & proved).sum())} proved roots among them")
    if not held.all():
        return "a root polished away from its eigenvalue"
    return ""


def _clusters(a: np.ndarray, b: np.ndarray, r: np.ndarray, among: np.ndarray) -> list[list[int]]:
    """The eigenvalues ``among`` grouped by overlapping disks (chordal distance |a_i b_j − a_j b_i| ≤ r_i + r_j)."""
    index = np.flatnonzero(among)
    near = np.abs(a[index, None] * b[None, index] - a[None, index] * b[index, None]) <= r[index, None] + r[None, index]
    group = list(range(index.size))
    for i, j in zip(*np.nonzero(np.triu(near, 1)), strict=True):
        gi, gj = group[i], group[j]
        if gi != gj:
            group = [gi if g == gj else g for g in group]
    out: dict[int, list[int]] = {}
    for k, g in enumerate(group):
        out.setdefault(g, []).append(int(index[k]))
    return list(out.values())


@dataclass(frozen=True, eq=False)
class Found:
    """Every root of a pose: ``q`` (m, 6) [rad] in (−π, π], polished; ``proved`` (m,) Kantorovich's test held;
    ``merged`` (m,) how many eigenvalues gave the root; ``reason`` why the set is not certified complete ("" when
    it is)."""

    q: np.ndarray
    proved: np.ndarray
    merged: np.ndarray
    reason: str


def every_root(g: General6R, loop: Loop, H: np.ndarray) -> Found:
    """Every real root of the pose H (4 × 4, base frame), polished, two that coincide beside a fold split into the
    two real roots there (:func:`split_pairs`), each tested by Kantorovich, distinct, and whether they are certified
    to be all of them (:func:`counted`)."""
    q, eigen = solve(g, H)
    q = split_pairs(loop, polish(loop, q, H), H)
    proof = kantorovich(loop, q, H)
    q = wrap_to_pi(q)
    keep, merged = _distinct(q, proof)
    reason = counted(eigen, q[keep], proof.proved[keep], float(g.phi[2]))
    if not reason and not proof.proved[keep].all():
        reason = "a root Kantorovich's test does not prove (a singular configuration)"
    return Found(q[keep], proof.proved[keep], merged, reason)


def split_pairs(loop: Loop, q: np.ndarray, H: np.ndarray) -> np.ndarray:
    """q (m, 6) [rad] with each pair of rows that coincide (to 1e-9 rad) moved to the two real roots beside them when
    there are two (:func:`~kinelab.ik.analytic.certify.beside_fold`): a close pair that the eigenvalues saw as a
    complex pair gives one point between its roots."""
    out = np.array(q, dtype=float)
    used: set[int] = set()
    for i in range(out.shape[0]):
        for j in range(i + 1, out.shape[0]):
            if i in used or j in used or np.abs(wrap_to_pi(out[i] - out[j])).max() > 1e-9:
                continue
            pair = beside_fold(loop, out[i], H)
            if pair is not None:
                out[i], out[j] = pair
                used |= {i, j}
    return out


def _distinct(q: np.ndarray, proof: Proof) -> tuple[list[int], np.ndarray]:
    """The rows of q that are distinct roots (a row within another's uniqueness ball, or within 1e-9 rad of it, is
    that root: two unproved rows farther apart stay two answers, which a double root may give and a close pair
    must) and how many rows each stands for."""
    keep: list[int] = []
    merged: list[int] = []
    for k in range(q.shape[0]):
        for n, j in enumerate(keep):
            if float(np.linalg.norm(wrap_to_pi(q[k] - q[j]))) < max(proof.alone[j], 1e-9):
                merged[n] += 1
                break
        else:
            keep.append(k)
            merged.append(1)
    return keep, np.array(merged, dtype=np.int64)


TRIALS = 4  # seeded configurations the elimination must recover before a chain is accepted


def usable(g: General6R, loop: Loop) -> tuple[str, bool]:
    """("", regular) when the elimination recovers TRIALS seeded configurations of the chain (each among the roots of
    its own pose, to 1e-9 rad), ``regular`` False when its pencil was singular at any of them (its eigenvalues are
    then whatever rounding makes them: a root found on one machine may be missed on another, and no set is
    certified); else (the structure it cannot take, in words, False)."""
    rng = np.random.default_rng(OFFSET_SEED)
    regular = True
    for q in rng.uniform(-np.pi, np.pi, (TRIALS, 6)):
        found = every_root(g, loop, chain_pose(loop.h, loop.o, loop.R0, loop.N0, q))
        if found.reason.startswith("the elimination is degenerate"):
            return "joints 1 and 2's invariants are dependent", False
        regular = regular and not found.reason.endswith(SINGULAR_PENCIL)
        gaps = np.abs(wrap_to_pi(found.q - q)).max(axis=1, initial=0.0)
        if found.q.shape[0] == 0 or gaps.min() > 1e-9:
            return f"it misses the chain's own configurations: {found.reason or 'roots lost'}", False
    return "", regular


def roots_within(arm: object, H: np.ndarray, lower: np.ndarray, upper: np.ndarray, ref: np.ndarray | None,
                 slack: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """The general 6R arm's roots of the pose H (4 × 4, base frame) within the limits [lower, upper] (rad; a root up
    to ``slack`` outside clipped to it): each angle's copy nearest ``ref`` (None: nearest 0) moved inside; with the
    eigenvalues merged into each root, one-of-a-continuum flags (none) and why the set is not certified ("" when
    it is)."""
    g, loop = arm.solver  # type: ignore[attr-defined]
    if arm.mirrored:  # type: ignore[attr-defined]
        found = every_root(g, loop, inverse_pose(H))
        found = Found(-found.q[:, ::-1], found.proved, found.merged, found.reason)
    else:
        found = every_root(g, loop, H)
    q, keep = nearest_inside(found.q, lower, upper, ref, slack)
    return q, found.merged[keep], np.zeros(int(keep.sum()), dtype=np.bool_), found.reason
