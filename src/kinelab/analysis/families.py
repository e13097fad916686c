"""Singular families of a chain: batched σ sweeps, refinement onto the singular set, joint relations.

See :mod:`kinelab.analysis.singular` for units and frames (the scaled Jacobian, the rank threshold).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.optimize import minimize

from kinelab.analysis.singular import NEAR_SINGULAR, analyze, scaled_jacobian
from kinelab.errors import KinelabError
from kinelab.ik.request import check_seed
from kinelab.progress import bar
from kinelab.robot import Chain
from kinelab.values import is_whole

RELATION_TOL = 1e-3  # [rad or m] a joint relation holds within this
SPECIAL_VALUES = (0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 2 * np.pi, -2 * np.pi)
FAMILY_MARGIN = 0.1  # [rad] a sample this close to every relation of a known family is explained by it


def sigma_ratio_batch(robot: Chain, qs: np.ndarray, length: float | None = None,
                      progress: bool | None = False) -> np.ndarray:
    """σ_min/σ_max of the scaled Jacobian for each row of ``qs`` (one batched SVD)."""
    L = length or robot.characteristic_length()
    model, data, fid = robot.model, robot.data, robot.tool_frame_id
    Js = np.empty((len(qs), 6, robot.nv))
    for i, q in enumerate(bar(qs, progress=progress, desc="jacobians", unit="q", leave=False)):
        Js[i] = pin.computeFrameJacobian(model, data, robot.to_pin_q(q), fid, pin.LOCAL_WORLD_ALIGNED).reshape(6, -1)
    Js[:, :3] /= L
    s = np.linalg.svd(Js, compute_uv=False)
    full = min(6, robot.n)
    return s[:, full - 1] / s[:, 0]


def refine(robot: Chain, q0, lower=None, upper=None, length: float | None = None) -> np.ndarray:
    """Move q0 onto the singular set: minimise σ_min/σ_max within the joint box (L-BFGS-B)."""
    L = length or robot.characteristic_length()
    lo = robot.lower if lower is None else lower
    hi = robot.upper if upper is None else upper

    def ratio(q):
        s = np.linalg.svd(scaled_jacobian(robot, q, L), compute_uv=False)
        return s[min(6, robot.n) - 1] / s[0]

    res = minimize(ratio, np.asarray(q0, float), method="L-BFGS-B", bounds=list(zip(lo, hi, strict=True)),
                   options={"maxiter": 300, "ftol": 1e-16, "gtol": 1e-12})
    return res.x


@dataclass(frozen=True)
class Relation:
    """Σ sign_k q[index_k] = value: a joint relation a family of singular configurations satisfies."""

    index: tuple[int, ...]
    sign: tuple[int, ...]
    value: float
    text: str
    period: float | None = None  # 2π for a relation of angles (its value taken modulo 2π), None for a slide's

    def residual(self, q) -> float:
        """How far q is from meeting the family's relations (0 on them; a relation of angles modulo 2π)."""
        gap = sum(s * q[i] for i, s in zip(self.index, self.sign, strict=True)) - self.value
        return abs(math.remainder(gap, self.period)) if self.period else abs(gap)


def _label(c: float) -> str:
    for value, text in ((0.0, "0"), (np.pi / 2, "π/2"), (np.pi, "π"), (2 * np.pi, "2π")):
        if abs(abs(c) - value) < 1e-12:
            return text if c >= 0 else "−" + text
    return f"{c:.6g}"


def _values(robot: Chain, index: tuple[int, ...]) -> list[float]:
    """Values a relation on these joints is tried at: 0, ±π/2, ±π, ±2π (angles), and a single joint's limits."""
    out = [0.0] if robot.joint_kinds[index[0]] == "prismatic" and len(index) == 1 else list(SPECIAL_VALUES)
    if len(index) == 1:
        i = index[0]
        out += [v for v in (robot.lower[i], robot.upper[i]) if np.isfinite(v)]
    return out


def _combos(robot: Chain) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """Single joints (any kind), sums and differences of two and of three angular joints."""
    angular = [i for i, k in enumerate(robot.joint_kinds) if k != "prismatic"]
    combos: list[tuple[tuple[int, ...], tuple[int, ...]]] = [((i,), (1,)) for i in range(robot.n)]
    combos += [((i, j), (1, s)) for i, j in itertools.combinations(angular, 2) for s in (1, -1)]
    combos += [((a, b, d), (1, s, t)) for a, b, d in itertools.combinations(angular, 3)
               for s in (1, -1) for t in (1, -1)]
    return combos


def joint_relations(robot: Chain, q, tol: float = RELATION_TOL) -> list[Relation]:
    """Simple relations the configuration satisfies: single joints at 0, ±π/2, ±π, ±2π or at a limit; sums
    and differences of two or three angular joints at 0, ±π/2, ±π, ±2π (joint names in the text); relations
    implied by single-joint ones (θ2 = 0 and θ3 = 0 imply θ2 ± θ3 = 0) are left out."""
    names = robot.joint_names
    out: list[Relation] = []
    fixed: set[int] = set()
    for index, sign in _combos(robot):
        if len(index) > 1 and sum(i not in fixed for i in index) < 2:
            continue
        total = sum(s * q[i] for i, s in zip(index, sign, strict=True))
        c = next((c for c in _values(robot, index) if abs(total - c) < tol), None)
        if c is None:
            continue
        out.append(_relation(robot, names, index, sign, c))
        if len(index) == 1:
            fixed.add(index[0])
    return out


def _relation(robot: Chain, names: list[str], index: tuple[int, ...], sign: tuple[int, ...], c: float) -> Relation:
    """The relation Σ sign·q[index] = c, named by its joints; an angular one at a special value is one family
    for every turn (2π is 0, −π is π)."""
    lhs = names[index[0]] + "".join(f" {'+' if s > 0 else '−'} {names[i]}"
                                    for i, s in zip(index[1:], sign[1:], strict=True))
    angular = all(robot.joint_kinds[i] != "prismatic" for i in index) and c in SPECIAL_VALUES
    if angular:
        c = math.remainder(c, 2 * np.pi) if abs(abs(math.remainder(c, 2 * np.pi)) - np.pi) > 1e-12 else np.pi
    return Relation(index, sign, float(c), f"{lhs} = {_label(c)}", 2 * np.pi if angular else None)


MOVES = 8  # configurations a relation set is tested at, away from the one it was found at
MOVE = 0.5  # [rad] (a tenth of the range for a slide) how far the other joints move


def moved_along(robot: Chain, relations: list[Relation], q, rng: np.random.Generator) -> np.ndarray | None:
    """q with every joint moved at random, then put back on the relations (the nearest point satisfying all of
    them); None when that leaves the limits."""
    span = np.where(np.isfinite(robot.upper - robot.lower), robot.upper - robot.lower, 2 * np.pi)
    step = np.where([k == "prismatic" for k in robot.joint_kinds], 0.1 * span, MOVE)
    moved = np.asarray(q, dtype=float) + rng.uniform(-1.0, 1.0, robot.n) * step
    if relations:  # the nearest point of the relations' affine set (they may share joints)
        A = np.zeros((len(relations), robot.n))
        for row, r in enumerate(relations):
            A[row, list(r.index)] = r.sign
        b = np.array([r.value for r in relations])
        moved += np.linalg.pinv(A) @ (b - A @ moved)
    if any(r.residual(moved) > 1e-9 for r in relations) or not robot.within_limits(moved):
        return None
    return moved


def holds_along(robot: Chain, relations: list[Relation], q, seed: int = 0, length: float | None = None) -> float:
    """The share of MOVES configurations satisfying ``relations`` (moved from q, see :func:`moved_along`) at
    which the Jacobian loses rank: 1.0 when the relations are enough for the singularity."""
    rng = np.random.default_rng(seed)
    hits = tries = 0
    for _ in range(4 * MOVES):
        moved = moved_along(robot, relations, q, rng)
        if moved is None:
            continue
        tries += 1
        hits += analyze(robot, moved, length).singular
        if tries == MOVES:
            break
    return hits / tries if tries else 0.0


def characterise(robot: Chain, q, length: float | None = None) -> tuple[list[Relation], bool]:
    """The relations that explain the singularity at q, and whether they do: the simple relations q satisfies,
    pruned to those without which the rank drop no longer holds along the family (coincidences such as a
    last joint at π/2 go); (relations found, False) when even all of them do not keep the rank down."""
    found = joint_relations(robot, q)
    if not found or holds_along(robot, found, q, length=length) < 1.0:
        return found, False
    kept = list(found)
    for r in sorted(found, key=lambda r: -len(r.index)):  # try to drop sums before single joints
        trial = [k for k in kept if k is not r]
        if trial and holds_along(robot, trial, q, length=length) == 1.0:
            kept = trial
    return kept, True


def _merge_coincidences(groups: dict[tuple, list]) -> dict[tuple, list]:
    """A verified relation set that strictly contains another verified family's carries a chance coincidence:
    merge it there. Keys are (relations, verified)."""
    merged: dict[tuple, list] = {}
    for key in sorted(groups, key=lambda k: len(k[0])):
        rel, verified = key
        home = next((k for k in merged if k[0] and verified and k[1] and set(k[0]) < set(rel)), None)
        merged.setdefault(home or key, []).extend(groups[key])
    return merged


def _merge_half_turns(groups: dict[tuple, list]) -> dict[tuple, list]:
    """Two verified families of one angle relation whose values differ by π (a wrist at 0 and at π: its axes
    parallel either way) are one family, "= 0 or π"; the singular configurations no simple relation explains are
    one family (the relations that hold at each by chance do not split it)."""
    merged: dict[tuple, list] = {}
    for key in sorted(groups, key=lambda k: [r.value for r in k[0]]):
        rel, verified = key
        if not verified:
            merged.setdefault(((), False), []).extend(groups[key])
            continue
        partner = next((k for k in merged if k[1] and _half_turn_apart(rel, k[0])), None)
        if partner is None:
            merged[key] = list(groups[key])
            continue
        first = partner[0][0]
        both = Relation(first.index, first.sign, first.value,
                        f"{first.text} or {_label(rel[0].value)}", np.pi)
        merged[((both,), True)] = merged.pop(partner) + list(groups[key])
    return merged


def _half_turn_apart(a: tuple[Relation, ...], b: tuple[Relation, ...]) -> bool:
    """True for two single periodic relations of the same joints whose values differ by π."""
    if not (len(a) == len(b) == 1 and a[0].period):
        return False
    return (a[0].index, a[0].sign) == (b[0].index, b[0].sign) and abs(abs(a[0].value - b[0].value) - np.pi) < 1e-9


@dataclass
class Family:
    """Singular configurations that share the same joint relations."""

    relations: list[Relation]
    count: int
    representative: np.ndarray
    rank: int
    sigma_ratio: float
    verified: bool = True  # the relations keep the rank down along the family (False: they hold at q only)

    @property
    def text(self) -> str:
        """The relations in words."""
        joined = " and ".join(r.text for r in self.relations)
        if self.verified and joined:
            return joined
        return "(no simple relation" + (f"; at these q: {joined}, which alone do not keep it singular)" if joined
                                        else ")")

    def to_dict(self) -> dict:
        """The JSON form of the sweep (``kinelab singular --sweep --json``)."""
        return {"relations": [r.text for r in self.relations], "verified": self.verified, "text": self.text,
                "count": self.count, "representative_q": self.representative.tolist(), "rank": self.rank,
                "sigma_min_over_max": self.sigma_ratio}


def sweep_limits(robot: Chain) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The box a sweep samples, and notes for joints whose range is not a finite limit."""
    notes = []
    for j in robot.joints:
        if j.kind == "continuous":
            notes.append(f"{j.name} is continuous: sampled on [−π, π]")
    return robot.lower.copy(), robot.upper.copy(), notes


def grid(robot: Chain, samples: int, rng: np.random.Generator) -> np.ndarray:
    """A stratified grid over the joint box: k cells per joint (k^n ≤ samples, k ≥ 2), one sample per cell,
    jittered within it. (A plain grid puts joints on 0 and ±π/2 together, where every relation holds.)"""
    k = max(2, int(np.floor(samples ** (1.0 / robot.n) + 1e-9)))
    cells = np.array(np.meshgrid(*[np.arange(k)] * robot.n, indexing="ij")).reshape(robot.n, -1).T
    width = (robot.upper - robot.lower) / k
    return robot.lower + (cells + rng.uniform(size=cells.shape)) * width


MAX_SWEEP_BYTES = 2**30  # [bytes] the largest sweep that runs without force=True


def sweep_bytes(robot: Chain, samples: int) -> int:
    """Memory a sweep of ``samples`` configurations needs: the samples, their 6 × n Jacobians and σ."""
    return 8 * samples * (robot.n + 6 * robot.n + min(6, robot.n) + 1)


def check_sweep_size(robot: Chain, samples: int, force: bool = False) -> None:
    """Refuse a sweep whose memory estimate passes MAX_SWEEP_BYTES (unless ``force``), or a count < 1.

    Raises:
        KinelabError: with the estimate and how to run it anyway.
    """
    if not is_whole(samples, 1):
        raise KinelabError(f"a sweep needs at least one sample (an integer ≥ 1), got {samples!r}")
    need = sweep_bytes(robot, samples)
    if need > MAX_SWEEP_BYTES and not force:
        raise KinelabError(f"a sweep of {samples} samples of {robot.name} needs about {need / 2**30:.1f} GiB; the "
                           f"limit is {MAX_SWEEP_BYTES / 2**30:g} GiB (--force, or force=True, runs it anyway)")


@dataclass(frozen=True)
class SweepResult:
    """What a sweep found.

    Attributes:
        families: the singular families, largest first.
        samples: configurations sampled; near_singular: how many had σ_min/σ_max < NEAR_SINGULAR.
        refined: samples moved onto the singular set; singular: how many of those were singular.
        notes: how the joint box was sampled (continuous joints, unbounded slides).
        sigma_ratio: σ_min/σ_max of every sample (not in the JSON form).
    """

    families: list[Family]
    samples: int
    near_singular: int
    refined: int
    singular: int
    notes: list[str]
    sigma_ratio: np.ndarray

    def to_dict(self) -> dict:
        """The JSON form of ``kinelab singular --sweep``."""
        return {"samples": self.samples, "near_singular": self.near_singular, "refined": self.refined,
                "singular": self.singular, "notes": self.notes, "families": [f.to_dict() for f in self.families]}


def sweep(robot: Chain, samples: int = 5000, seed: int = 0, refine_top: int = 40, progress: bool = False,
          method: str = "random") -> SweepResult:
    """Sample the joint box (seeded uniform samples, or a full grid), keep near-singular configurations,
    refine them onto the singular set, and group those that are singular into families by the joint
    relations they satisfy (relations that hold there; for a redundant arm one relation can be a necessary
    condition only, the refinement supplies the rest).

    Raises:
        KinelabError: no sample asked for, or an unknown method.
    """
    if samples < 1:
        raise KinelabError("a sweep needs at least one sample")
    lower, upper, notes = sweep_limits(robot)
    if method not in ("random", "grid"):
        raise KinelabError(f"unknown sweep method {method!r}; use 'random' or 'grid'")
    check_seed(seed)
    rng = np.random.default_rng(seed)
    qs = rng.uniform(lower, upper, size=(samples, robot.n)) if method == "random" else grid(robot, samples, rng)
    L = robot.characteristic_length()
    ratios = sigma_ratio_batch(robot, qs, L, progress)
    order = [i for i in np.argsort(ratios) if ratios[i] < NEAR_SINGULAR]
    groups, refined, singular_count = _refine_samples(robot, qs, order, lower, upper, L, refine_top, progress)
    families = []
    merged = _merge_half_turns(_merge_coincidences(groups))
    for (rel, verified), members in sorted(merged.items(), key=lambda kv: -len(kv[1])):
        a = analyze(robot, members[0], L)
        families.append(Family(list(rel), len(members), members[0], a.rank,
                               float(a.singular_values[a.full_rank - 1] / a.singular_values[0]), verified))
    return SweepResult(families, len(qs), int(np.sum(ratios < NEAR_SINGULAR)), refined, singular_count, notes,
                       ratios)


def _unexplained(qs: np.ndarray, order: list[int], known: list[tuple[Relation, ...]]) -> int | None:
    """The first sample in ``order`` that no known family's relations hold at (within FAMILY_MARGIN), or None."""
    return next((i for i in order if not any(all(r.residual(qs[i]) < FAMILY_MARGIN for r in rel) for rel in known)),
                None)


def _refine_samples(robot: Chain, qs: np.ndarray, order: list[int], lower: np.ndarray, upper: np.ndarray,
                    L: float, refine_top: int, progress: bool) -> tuple[dict, int, int]:
    """Refine the most singular samples that no family found so far explains; group the singular ones.

    A family of lower dimension (the youBot's θ2 = θ3 = 0) is sampled far less often than one of
    codimension 1; leaving the explained samples out is what lets a sweep find it.
    """
    groups: dict[tuple[tuple[Relation, ...], bool], list[np.ndarray]] = {}
    refined = singular_count = 0
    with bar(total=refine_top, progress=progress, desc="refine", unit="q", leave=False) as shown:
        while refined < refine_top and order:
            pick = _unexplained(qs, order, [rel for rel, verified in groups if rel and verified])
            if pick is None:
                break
            order.remove(pick)
            q = refine(robot, qs[pick], lower, upper, L)
            refined += 1
            shown.update()
            if analyze(robot, q, L).singular:
                singular_count += 1
                relations, verified = characterise(robot, q, L)
                groups.setdefault((tuple(relations), verified), []).append(q)
    return groups, refined, singular_count
