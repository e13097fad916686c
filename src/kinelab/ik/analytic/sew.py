"""The SEW angle as a 7R arm's redundancy parameter: every branch of a pose with the elbow at a given angle.

A 7R arm reaches a pose along a one-parameter self-motion. Elias and Wen name that parameter by the arm's
shoulder S, elbow E and wrist W: with S fixed to the base and W fixed to the tool, a pose fixes the line SW and
the self-motion turns the elbow about it. The SEW angle ψ is the turn, about the unit ŵ along SW, from a
reference half-plane to the half-plane of S, E, W. In their stereographic form the reference plane's normal is
(ŵ − e_t) × e_r, e_t and e_r two perpendicular unit vectors of the base frame: the angle is defined for every
wrist direction but ŵ = e_t (one direction of the sphere, chosen where the arm does not reach: by default
straight down through its own base).

Here S is the point of joint 1's axis nearest joint 2's, E the point of joint 4's axis nearest joint 3's and W
the point of joint 7's axis nearest joint 6's: on an arm whose shoulder and wrist axes meet these are the
meeting points; on one with offsets (the Panda, the xArm7) they are the feet of the offsets. The branches at an
angle ψ₀ are the roots of seven equations in seven joints (the pose, and ψ(q) = ψ₀): the arm's swept joint is
sampled over its range, every branch with it held at each sample comes from the closed form or the elimination
(:mod:`kinelab.ik.analytic.redundancy`), each branch is followed to the next sample, and where ψ − ψ₀ changes
sign along one Newton's method on the seven equations finishes the root. A search, not a proof: the sets say
``complete == "search"``. Every answer is judged by Pinocchio's FK within all limits, and its SEW angle is
within ``tol_rot`` of ψ₀.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.geometry import wrap_angle, wrap_to_pi
from kinelab.ik.analytic.branches import Answer, Rows, arm_roots, branch_results, judged_roots
from kinelab.ik.analytic.certify import Loop, equations, loop_of
from kinelab.ik.analytic.redundancy import SweptArm, chain7_vectors, samples, swept_arm
from kinelab.ik.limits import distance, nearest_inside
from kinelab.ik.request import Deadline, Request
from kinelab.ik.result import Branches
from kinelab.ik.targets import beyond_reach
from kinelab.robot import Chain
from kinelab.typing import Configuration
from kinelab.values import is_real, is_whole

MATCH = 1.0  # rad: a branch at one sample and its nearest at the next are one branch followed when this close
NEWTON_STEPS = 30
ROOT = 1e-4  # a sample's branch is taken when its loop equations' residual (scaled) is below this (a class met to
# its tolerance leaves ~1e-6; an uncertified elimination's candidates that are no root, ~1)


def _unit(v: Any, what: str) -> np.ndarray:
    """v as a unit 3-vector.

    Raises:
        OptionError: v is not three finite numbers, or is zero.
    """
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        a = np.array([np.nan])
    if a.shape != (3,) or not np.isfinite(a).all() or np.linalg.norm(a) < 1e-9:
        raise OptionError(f"SEW.{what}", v, "three finite numbers, not all zero (a direction in the base frame)")
    return a / np.linalg.norm(a)


@dataclass(frozen=True)
class SEW:
    """The stereographic SEW angle as ``redundancy=`` of :func:`kinelab.solve_all` for a 7R arm.

    Attributes:
        angle: ψ₀ [rad], the elbow's turn about the shoulder–wrist line (kept wrapped into (−π, π]).
        singular: e_t, the wrist direction (from the shoulder, base frame) where the angle is undefined; default
            straight down.
        reference: e_r, the reference direction (base frame); its part perpendicular to ``singular`` is used.
        samples: values of the swept joint the search starts from (more find roots closer together).
    """

    angle: float
    singular: tuple[float, float, float] = (0.0, 0.0, -1.0)
    reference: tuple[float, float, float] = (1.0, 0.0, 0.0)
    samples: int = 64
    e_t: np.ndarray = field(init=False, repr=False, compare=False)
    e_r: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Checks every field.

        Raises:
            OptionError: a field out of what it accepts (named, with what is valid).
        """
        a = self.angle
        if not is_real(a):
            raise OptionError("SEW.angle", a, "a finite angle [rad]")
        object.__setattr__(self, "angle", wrap_angle(float(a)))  # the same elbow plane: ψ kept in (−π, π]
        s = self.samples
        if not is_whole(s, 8, 4096):
            raise OptionError("SEW.samples", s, "an integer in [8, 4096]")
        e_t = _unit(self.singular, "singular")
        r = _unit(self.reference, "reference")
        r = r - (r @ e_t) * e_t
        if np.linalg.norm(r) < 1e-6:
            raise OptionError("SEW.reference", self.reference, "a direction not parallel to SEW.singular")
        object.__setattr__(self, "e_t", e_t)
        object.__setattr__(self, "e_r", r / np.linalg.norm(r))

    def of(self, S: np.ndarray, E: np.ndarray, W: np.ndarray) -> float:
        """ψ [rad] of the shoulder S, elbow E and wrist W (base frame, m); NaN when the wrist is at the shoulder,
        the elbow on the line SW, or the wrist direction the singular one."""
        w = W - S
        norm = math.sqrt(float(w @ w))
        if norm < 1e-12:
            return math.nan
        w_hat = w / norm
        n_sew = cross(w, E - S)
        n_ref = cross(w_hat - self.e_t, self.e_r)
        y, x = float(n_sew @ cross(w_hat, n_ref)), float(n_sew @ n_ref)
        return math.atan2(y, x) if math.hypot(x, y) > 1e-15 else math.nan

    def gradient(self, S: np.ndarray, E: np.ndarray, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """∂ψ/∂E and ∂ψ/∂W [rad/m] at (S, E, W): the elbow's exactly (ψ is the angle of E − S's part across SW,
        about SW), the wrist's by central differences."""
        w = W - S
        w_hat = w / math.sqrt(float(w @ w))
        e = E - S
        across = e - float(e @ w_hat) * w_hat
        g_E = cross(w_hat, across) / float(across @ across)
        g_W = np.empty(3)
        for k in range(3):
            step = np.zeros(3)
            step[k] = 1e-7
            g_W[k] = wrap_angle(self.of(S, E, W + step) - self.of(S, E, W - step)) / 2e-7
        return g_E, g_W


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of 3-vectors, or column by column of 3 × k arrays (np.cross costs ten times more on small ones)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def nearest_on(h_a: np.ndarray, o_a: np.ndarray, h_b: np.ndarray, o_b: np.ndarray) -> np.ndarray:
    """The point of line a (unit h_a through o_a) nearest line b; o_a when they are parallel."""
    w = o_a - o_b
    b = float(h_a @ h_b)
    den = 1.0 - b * b
    if den < 1e-12:
        return o_a.copy()
    return o_a + (b * float(h_b @ w) - float(h_a @ w)) / den * h_a


@dataclass(frozen=True, eq=False)
class Arm7:
    """A 7R chain for the SEW angle: its loop equations (axes, points and tool at q = 0, base frame) and the
    shoulder, elbow and wrist points at q = 0 [m]."""

    loop: Loop
    shoulder: np.ndarray
    elbow: np.ndarray
    wrist: np.ndarray

    def points(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """S, E, W at q (7,) [rad], base frame: E moves with joints 1–3, W with joints 1–6."""
        E, W, _, _ = self._carried(q)
        return self.shoulder, E, W

    def moved(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """S, E, W at q (7,) [rad] and ∂E/∂q, ∂W/∂q (3 × 7 each) [m/rad], base frame: a point turned by joint k
        moves at h_k × (point − o_k), the joint's axis and point where joints 1 … k−1 carried them."""
        E, W, axes, through = self._carried(q)
        dE, dW = np.zeros((3, 7)), np.zeros((3, 7))
        dE[:, :3] = cross(axes[:3].T, (E - through[:3]).T)
        dW[:, :6] = cross(axes.T, (W - through).T)
        return self.shoulder, E, W, dE, dW

    def _carried(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """E, W at q and joints 1–6's axes and points (6 × 3 each) where the joints before each carried them."""
        R, t = np.eye(3), np.zeros(3)
        E = self.elbow
        axes, through = np.empty((6, 3)), np.empty((6, 3))
        for k in range(6):
            axes[k], through[k] = R @ self.loop.h[k], R @ self.loop.o[k] + t
            step = pin.exp3(self.loop.h[k] * q[k])
            t = R @ (self.loop.o[k] - step @ self.loop.o[k]) + t
            R = R @ step
            if k == 2:
                E = R @ self.elbow + t
        return E, R @ self.wrist + t, axes, through


def arm7(robot: Chain) -> Arm7:
    """The robot's 7R chain with its S, E, W (built once per Chain; the caller checked it is 7R)."""
    return robot.derived("sew arm", _arm7)


def _arm7(robot: Chain) -> Arm7:
    v = chain7_vectors(robot)
    h, o = v["e"], v["o"]
    return Arm7(loop_of(h, o, v["R"], v["N"]), nearest_on(h[0], o[0], h[1], o[1]), nearest_on(h[3], o[3], h[2], o[2]),
                nearest_on(h[6], o[6], h[5], o[5]))


def sew_angle(robot: Chain, q: Configuration, sew: SEW | None = None) -> float:
    """The SEW angle ψ [rad] of the 7R robot at q (rad), by ``sew``'s reference (None: the default one).

    Raises:
        OptionError: the robot is not a 7R chain, or ``sew`` is not a SEW.
        ConfigurationError: q is not a valid configuration.
    """
    if sew is not None and not isinstance(sew, SEW):
        raise OptionError("sew", sew, "a kinelab.SEW(angle, singular=, reference=), or None (the default reference)")
    chain7_vectors(robot)
    arm = arm7(robot)
    return (sew or SEW(0.0)).of(*arm.points(robot.check_q(q)))


def _residual(arm: Arm7, sew: SEW, q: np.ndarray, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The seven equations' residual (6 loop components scaled, the SEW angle's gap [rad]) at q and its 7 × 7
    derivative."""
    F, J = equations(arm.loop, q[None, :], H)
    S, E, W, dE, dW = arm.moved(q)
    g_E, g_W = sew.gradient(S, E, W)
    return np.append(F[0], wrap_angle(sew.of(S, E, W) - sew.angle)), np.vstack([J[0], g_E @ dE + g_W @ dW])


def finish(arm: Arm7, sew: SEW, q: np.ndarray, H: np.ndarray) -> np.ndarray | None:
    """Newton's method on the seven equations from q [rad]: the root (residual below 1e-10), or None."""
    x = q.copy()
    best, low, stalls = None, math.inf, 0
    for _ in range(NEWTON_STEPS):
        r, J = _residual(arm, sew, x, H)
        size = float(np.linalg.norm(r))
        if not math.isfinite(size):
            break
        if size < low:
            best, low, stalls = x.copy(), size, 0
        else:
            stalls += 1
        if size < 1e-14 or stalls >= 3:
            break
        try:
            x = x - np.linalg.solve(J, r)
        except np.linalg.LinAlgError:
            break
    return best if low < 1e-10 else None


def _pairs(A: np.ndarray, B: np.ndarray, same: bool) -> tuple[set[tuple[int, int]], np.ndarray]:
    """The branches of A (m, 7) and B (k, 7) taken as one branch followed: each one's nearest at the other (every
    pair of A when ``same``, A and B one sample), and their distances (m × k, rad, the largest joint's gap)."""
    d = np.abs(wrap_to_pi(A[:, None, :] - B[None, :, :])).max(axis=2)
    if same:
        return {(a, b) for a in range(len(A)) for b in range(a + 1, len(A))}, d
    return {(a, int(d[a].argmin())) for a in range(len(A))} | {(int(d[:, b].argmin()), b) for b in range(len(B))}, d


def _crossing(fa: float, fb: float) -> bool:
    """True when ψ − ψ₀ changes sign between gaps fa and fb [rad] (not by wrapping through ±π)."""
    return fa * fb <= 0.0 and abs(fa - fb) < math.pi


def starts(sets: list[np.ndarray], gaps: list[np.ndarray], around: bool) -> list[np.ndarray]:
    """Newton's starts: where ψ − ψ₀ changes sign along a branch followed from one sample of the swept joint to the
    next, or between two branches of one sample that meet at a fold just beyond it, the configuration interpolated
    at the zero of the gap; beside a fold (the number of branches changes), every branch there. ``sets[i]``: the
    branches at sample i (m, 7); ``gaps[i]``: their ψ − ψ₀ wrapped [rad]; ``around``: the last sample is followed
    to the first, the range a whole turn."""
    found = []
    pairs = [(i, i + 1) for i in range(len(sets) - 1)] + ([(len(sets) - 1, 0)] if around else [])
    for i, j in pairs + [(i, i) for i in range(len(sets))]:
        A, B = sets[i], sets[j]
        if len(A) != len(B):  # a fold in this (finest) cell: Newton from every branch beside it too
            found += [*A, *B]
        if not len(A) or not len(B):
            continue
        found += _crossings(A, gaps[i], B, gaps[j], i == j)
    return found


def _crossings(A: np.ndarray, gA: np.ndarray, B: np.ndarray, gB: np.ndarray, same: bool) -> list[np.ndarray]:
    """Newton's starts where a branch of A (m, 7) followed to B (gaps gA, gB [rad]) crosses ψ₀: the configuration
    interpolated at the zero of the gap, and both ends where the branch turns fast; ``same``: A and B are one
    sample's branches (two meeting at a fold)."""
    found = []
    matched, d = _pairs(A, B, same)
    for a, b in matched:
        fa, fb = float(gA[a]), float(gB[b])
        if not _crossing(fa, fb) or (d[a, b] >= MATCH and same):
            continue
        s = 0.0 if fa == fb else fa / (fa - fb)
        found.append(A[a] + s * wrap_to_pi(B[b] - A[a]))
        if d[a, b] >= FOLLOWED:  # a fast turn the interpolation may not follow: Newton from either end too
            found += [A[a], B[b]]
    return found


REFINE = 6  # halvings of a cell of the swept joint where a branch is not followed or crosses ψ₀
FOLLOWED = 0.2  # rad: a branch is followed across a cell when its nearest at the other end is this close …
SPEED = 4.0  # … or within this many times the cell's width (a branch turns joints faster than the swept one)


def _refined(A: np.ndarray, gA: np.ndarray, B: np.ndarray, gB: np.ndarray, width: float) -> bool:
    """True when the cell between the branches A (m, 7) and B (gaps gA, gB [rad]), ``width`` [rad] apart, is to be
    halved: their numbers differ, one has none at the other within FOLLOWED or SPEED × width, or a branch followed
    across it crosses ψ₀ (two crossings in one cell would give Newton one start for two roots)."""
    if len(A) != len(B):
        return True
    if not len(A):
        return False
    matched, d = _pairs(A, B, False)
    if max(d.min(axis=1).max(), d.min(axis=0).max()) > max(FOLLOWED, SPEED * width):
        return True
    return any(d[a, b] < MATCH and _crossing(float(gA[a]), float(gB[b])) for a, b in matched)


def sampled(robot: Chain, arm: Arm7, sew: SEW, H: np.ndarray, sw: SweptArm,
            deadline: Deadline | None = None) -> tuple[list[np.ndarray], list[np.ndarray], bool, str]:
    """The branches (m, 7) at the samples of the swept joint, in order, each a root of the loop equations to ROOT
    with every joint but the swept one unbounded (a branch is followed past the limits it crosses; the limits judge
    the answers), their ψ − ψ₀ [rad], whether the swept joint's range is a whole turn, and how far it got when
    ``deadline`` came (a :class:`Deadline`; "" when it did not): ``sew.samples`` values spread
    over its range (its ends included unless it is a whole turn), and midpoints added, REFINE times over, in every
    cell :func:`_refined` names."""
    lo, hi = float(robot.lower[sw.joint]), float(robot.upper[sw.joint])
    around = hi - lo >= 2 * math.pi
    values = list(samples(lo, hi, sew.samples) if around else np.linspace(lo, hi, sew.samples))
    wide = np.full(6, math.pi)

    def at(v: float) -> tuple[np.ndarray, np.ndarray]:
        q = np.insert(arm_roots(sw.arm, sw.sub_target(H, v), -wide, wide, None)[0], sw.joint, v, axis=1)
        if len(q):
            F, _ = equations(arm.loop, q, H)  # an uncertified elimination may offer candidates that are not roots
            q = q[np.linalg.norm(F, axis=1) <= ROOT]
        return q, np.array([wrap_angle(sew.of(*arm.points(x)) - sew.angle) for x in q])

    found = []
    deadline = deadline or Deadline(0.0, None)
    for k, v in enumerate(values):
        if deadline.near():
            return [], [], around, f"after {k} of {len(values)} samples of joint {sw.joint + 1}"
        found.append(at(float(v)))
    if not _refine(values, found, at, deadline):
        return [], [], around, f"while refining the {len(values)} samples of joint {sw.joint + 1}"
    return [f[0] for f in found], [f[1] for f in found], around, ""


def _refine(values: list[float], found: list[tuple[np.ndarray, np.ndarray]],
            at: Callable[[float], tuple[np.ndarray, np.ndarray]], deadline: Deadline) -> bool:
    """Insert midpoints, REFINE times over, into every cell :func:`_refined` names (``values`` [rad] of the swept
    joint and ``found``, the branches and gaps ``at`` gives there, grow in place); False when ``deadline`` came."""
    for _ in range(REFINE):
        cells = [i for i in range(len(values) - 1)
                 if _refined(*found[i], *found[i + 1], values[i + 1] - values[i])]
        for i in reversed(cells):
            if deadline.near():
                return False
            mid = 0.5 * (values[i] + values[i + 1])
            values.insert(i + 1, mid)
            found.insert(i + 1, at(mid))
    return True


def distinct(q: list[np.ndarray], apart: float = 1e-6) -> np.ndarray:
    """The rows of q (each (7,), rad) more than ``apart`` from every earlier one (modulo 2π), as (m, 7)."""
    kept: list[np.ndarray] = []
    for row in q:
        if all(np.abs(wrap_to_pi(row - k)).max() > apart for k in kept):
            kept.append(row)
    return np.array(kept, dtype=float).reshape(len(kept), 7)


def sew_all(robot: Chain, target: pin.SE3, req: Request, sew: SEW, q_ref: np.ndarray | None = None,
            max_solutions: int | None = None) -> Branches:
    """Every branch of ``target`` (oMtarget, base frame) with the SEW angle ``sew.angle`` that the search finds,
    each judged by Pinocchio within the limits and its angle within ``req.tol_rot``.

    Raises:
        OptionError: the robot is not a 7R arm with a swept form (:func:`~kinelab.ik.analytic.redundancy.swept_arm`),
            or the task is not "pose".
    """
    if req.task.name != "pose":
        raise OptionError("task", req.task_label, "'pose' with redundancy= (other tasks: solver='frdm')")
    sw = swept_arm(robot, sew)  # built once per robot, before the clock starts
    arm, H = arm7(robot), target.homogeneous
    t0 = time.perf_counter()
    deadline = Deadline(t0, req.time_budget)
    beyond = beyond_reach(robot, target.translation)
    sets, gaps, around, late = ([], [], False, "") if beyond else sampled(robot, arm, sew, H, sw, deadline)
    roots = []
    for x in starts(sets, gaps, around):
        if deadline.near():
            late = late or "while finishing the roots found"
            break
        if (r := finish(arm, sew, x, H)) is not None:
            roots.append(r)
    answers = _judged(robot, distinct(roots), target, req, sew, q_ref)
    mode = f"analytic (SEW angle {float(sew.angle):.6g} rad; joint {sw.joint + 1} searched over {sew.samples} samples)"
    return branch_results(robot, Rows.of(answers, 7), req, mode, time.perf_counter() - t0, max_solutions, "search",
                          "no branch found at this SEW angle",
                          uncertified=f"the SEW angle's branches come from a search over joint {sw.joint + 1}'s "
                                      f"{sew.samples} samples: not proved complete", beyond=beyond, late=late)


def _judged(robot: Chain, q: np.ndarray, target: pin.SE3, req: Request, sew: SEW,
            q_ref: np.ndarray | None) -> list[Answer]:
    """The roots q (m, 7) turned into the limits (each angle's copy nearest ``q_ref``), judged by Pinocchio, and
    kept where the SEW angle of the judged q is within ``req.tol_rot`` of ψ₀; nearest ``q_ref`` first."""
    q, _ = nearest_inside(q, robot.lower, robot.upper, q_ref, 0.0)
    m = q.shape[0]
    arm = arm7(robot)
    answers = [a for a in judged_roots(robot, q, np.ones(m, dtype=np.int64), np.zeros(m, dtype=np.bool_), target, req)
               if abs(wrap_angle(sew.of(*arm.points(a[0])) - sew.angle)) <= req.tol_rot]
    if q_ref is not None:
        answers.sort(key=lambda a: distance(robot, a[0], q_ref))
    return answers
