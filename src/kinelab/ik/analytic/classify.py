"""Which arms the subproblems solve: the chain's class, read from its joint axes and points at q = 0.

Three classes are solved in closed form (docs/analytic.md), each also in its mirror image (the chain read
from the tool back to the base, which solves the inverse pose):

- **6R, h₂ ∥ h₃ ∥ h₄, axes 5 and 6 meeting** (the UR arms, the Unitree Z1): up to 8 branches;
- **6R, h₂ ∥ h₃, axes 4, 5 and 6 meeting** (a spherical wrist: the Kinova Jaco 2 j2s6s200): up to 8;
- **6R, axes 1 and 2 meeting, axes 4, 5 and 6 meeting**: up to 8 (mirrored: a spherical shoulder and axes 5
  and 6 meeting — the Panda's and the xArm7's first six joints);
- **6R, h₁ ∥ h₂, h₃ ∥ h₄ ∥ h₅** (a turning platform carrying a planar arm: the youBot's heading and arm):
  up to 8;
- **5R, h₂ ∥ h₃ ∥ h₄** (the SO-101): up to 4 candidates, of which a pose keeps those that meet it.

Outside them, a **6R arm with two consecutive wrist axes meeting** (4 and 5, or 5 and 6) and a shoulder that
places a point in closed form (h₂ ∥ h₃, axes 1 and 2 meeting, or axes 2 and 3 meeting) gets every branch by a
1-D search over the wrist joint not in the pair (the xArm6, the FANUC CRX, Baxter's first six joints): up to 16.

Axes count as parallel when their angle is below AXIS_TOL and as meeting when their distance is below
POINT_TOL; a chain that misses a test by more gets the numeric path, with the tests it failed named.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from kinelab.errors import ChainError
from kinelab.ik.analytic.certify import loop_of
from kinelab.ik.analytic.general import prepare, usable
from kinelab.ik.analytic.kernel import (
    GENERAL_6R,
    MEETING_6R,
    PARALLEL_5R,
    PARALLEL_6R,
    PIEPER_6R,
    SEARCH_6R,
    SPHERICAL_6R,
    TWO_THREE_6R,
)
from kinelab.ik.chain import PRISMATIC, chain_model
from kinelab.robot import Chain

AXIS_TOL = 1e-5  # [rad] axes closer to parallel are parallel (URDF numbers are rounded: 1.5708 is π/2 + 3.7e-6)
POINT_TOL = 1e-5  # [m] axes closer than this meet


@dataclass(frozen=True, eq=False)
class ArmClass:
    """An arm the subproblems solve, in the orientation they solve it.

    Attributes:
        name: the class, in words; kind: its kernel code (:mod:`kinelab.ik.analytic.kernel`); mirrored: the
            chain is solved read from the tool back (inverse pose, joints reversed and negated).
        h, o: (n, 3) unit axes and points on them at q = 0 [m], in the solved orientation's base frame.
        R0, N0: the tool's rotation and point at q = 0 in that frame.
        solver: for the general 6R class, its prepared elimination (:mod:`kinelab.ik.analytic.general`) and
            loop equations (:mod:`kinelab.ik.analytic.certify`); for Pieper's, its prepared decoupling
            (:mod:`kinelab.ik.analytic.pieper`); None for the others.
    """

    name: str
    kind: int
    mirrored: bool
    h: np.ndarray
    o: np.ndarray
    R0: np.ndarray
    N0: np.ndarray
    solver: Any = field(default=None, repr=False)  # the general 6R class's prepared elimination and loop equations

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.h.shape[0])

    @property
    def searched(self) -> bool:
        """True when the branches come from the 1-D search (a root finder) or the elimination, not a closed form."""
        return SEARCH_6R <= self.kind <= GENERAL_6R

    @property
    def method(self) -> str:
        """How the branches are found, in words (``kinelab info``)."""
        if self.kind == PIEPER_6R:
            return "every branch in closed form (Pieper's decoupling, a quartic)"
        if not self.searched:
            return "every branch in closed form"
        if self.kind == GENERAL_6R:
            return "every branch by algebraic elimination"
        joint = 4 if (self.kind - SEARCH_6R) // 3 else 6
        if self.mirrored:
            joint = 7 - joint
        return f"every branch by a 1-D search over joint {joint}"

    @property
    def mode(self) -> str:
        """The answers' ``mode``: the class, and the search joint when searched."""
        if self.kind == GENERAL_6R:
            return f"analytic ({self.name}; algebraic elimination)"
        return f"analytic ({self.name}; {self.method.removeprefix('every branch by a ')})" if self.searched \
            else f"analytic ({self.name})"


@dataclass(frozen=True, eq=False)
class Classification:
    """The chain's class (``arm``), or None with ``reason`` naming the tests it failed."""

    arm: ArmClass | None
    reason: str


def classify(robot: Chain) -> Classification:
    """The analytic class of ``robot``'s chain, built once per Chain (see the module's docstring)."""
    return robot.derived("analytic_class", _classify)


def general_class(robot: Chain) -> Classification:
    """The general 6R class of ``robot``'s chain (the algebraic elimination, :mod:`kinelab.ik.analytic.general`), or
    None with the reason: not 6R, a prismatic joint, or a structure the elimination cannot take. Built once per
    Chain; an arm in a closed-form or search class has its own (:func:`classify`) and is not offered this one."""
    return robot.derived("general_class", _general)


def _general(robot: Chain) -> Classification:
    if classify(robot).arm is not None:
        return Classification(None, "the chain has a class of its own: " + classify(robot).arm.name)  # type: ignore[union-attr]
    try:
        cm = chain_model(robot)
    except ChainError as err:
        return Classification(None, str(err))
    if (cm.kind == PRISMATIC).any() or cm.n != 6:
        return Classification(None, "the general solver takes 6R chains (this one: "
                              f"{cm.n} joints{', a prismatic one' if (cm.kind == PRISMATIC).any() else ''})")
    v = cm.vectors(np.zeros(cm.n))
    return general_vectors(v["e"].copy(), v["o"].copy(), v["R"].copy(), v["N"].copy())


def general_vectors(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> Classification:
    """The general 6R class of the chain (h, o, R0, N0) at q = 0 (base frame, metres), read from the base or else
    from the tool (the elimination's joints 1 and 2 are then the last two), or None with the structure the
    elimination cannot take either way (it misses seeded configurations of the chain). A reading whose pencil is
    regular is preferred, then Pieper's decoupling where three axes at an end meet (:func:`pieper_vectors`); a
    reading whose pencil is singular is taken only when nothing else is (its sets are then never certified)."""
    failed, singular = [], []
    for mirrored in (False, True):
        arm, why, regular = _general_reading(h, o, R0, N0, mirrored)
        if not why and regular:
            return Classification(arm, "")
        if not why:
            singular.append(arm)
        failed.append(("read from the tool: " if mirrored else "") + (why or "its pencil is singular"))
    decoupled = pieper_vectors(h, o, R0, N0)
    if decoupled.arm is not None:
        return decoupled
    if singular:
        return Classification(singular[0], "")
    return Classification(None, f"the general 6R elimination degenerates on this chain's structure ({special(h, o)}): "
                          + " | ".join(failed) + f"; Pieper's decoupling: {decoupled.reason}")


def _general_reading(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray,
                     mirrored: bool) -> tuple[ArmClass, str, bool]:
    """The general elimination of the chain read from the base (or, ``mirrored``, from the tool): the class, why
    the elimination cannot take it ("" when it can) and whether its pencil is regular."""
    hh, oo, RR, NN = reverse(h, o, R0, N0) if mirrored else (h, o, R0, N0)
    solver = (prepare(hh, oo, RR, NN), loop_of(hh, oo, RR, NN))
    why, regular = usable(*solver)
    name = "general 6R" + (" (mirrored: read from the tool)" if mirrored else "")
    return ArmClass(name, GENERAL_6R, mirrored, hh, oo, RR, NN, solver), why, regular


def _shoulder_meets(h: np.ndarray, o: np.ndarray) -> bool:
    """True when axes 1, 2, 3 pass through one point, no two of them parallel (class tolerances)."""
    return (max(line_distance(o[i], h[i], o[j], h[j]) for i, j in ((0, 1), (0, 2), (1, 2))) < POINT_TOL
            and _angle(h[0], h[1]) >= AXIS_TOL and _angle(h[1], h[2]) >= AXIS_TOL)


def pieper_vectors(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> Classification:
    """Pieper's class of the chain (h, o, R0, N0) at q = 0 (base frame, metres): axes 1, 2, 3 through one point
    (read from the base) or axes 4, 5, 6 (read from the tool), the decoupling recovering seeded configurations;
    or None with why not."""
    from kinelab.ik.analytic.pieper import prepare, usable

    failed = []
    for mirrored in (False, True):
        hh, oo, RR, NN = reverse(h, o, R0, N0) if mirrored else (h, o, R0, N0)
        where = "read from the tool: " if mirrored else ""
        if not _shoulder_meets(hh, oo):
            failed.append(where + "axes 1, 2, 3 do not meet in one point")
            continue
        meets = line_distance(oo[3], hh[3], oo[4], hh[4]) < POINT_TOL and _angle(hh[3], hh[4]) >= AXIS_TOL
        prepared = prepare(hh, oo, RR, NN, meeting_point(oo[0], hh[0], oo[1], hh[1]),
                           meeting_point(oo[3], hh[3], oo[4], hh[4]) if meets else None)
        why = prepared if isinstance(prepared, str) else usable(prepared)
        if not why:
            name = "spherical shoulder, general 3R" + (" (mirrored: read from the tool)" if mirrored else "")
            return Classification(ArmClass(name, PIEPER_6R, mirrored, hh, oo, RR, NN, prepared), "")
        failed.append(where + why)
    return Classification(None, " | ".join(failed))


def with_search(decoupled: ArmClass, search: ArmClass) -> ArmClass:
    """Pieper's class ``decoupled`` with the 1-D search class the chain also fits, whose roots it adds."""
    return replace(decoupled, name=decoupled.name + " and a 1-D search", solver=replace(decoupled.solver, also=search))


def special(h: np.ndarray, o: np.ndarray) -> str:
    """The special structure of a chain's axes, in words: which pairs of axes are parallel or meet, to the class
    tolerances ("no two axes parallel or meeting" when none)."""
    n, found = h.shape[0], []
    for i in range(n):
        for j in range(i + 1, n):
            if _angle(h[i], h[j]) < AXIS_TOL:
                found.append(f"axes {i + 1} and {j + 1} parallel")
            elif line_distance(o[i], h[i], o[j], h[j]) < POINT_TOL:
                found.append(f"axes {i + 1} and {j + 1} meeting")
    return ", ".join(found) or "no two axes parallel or meeting"


def _classify(robot: Chain) -> Classification:
    try:
        cm = chain_model(robot)
    except ChainError as err:
        return Classification(None, str(err))
    if (cm.kind == PRISMATIC).any():
        return Classification(None, "a prismatic joint (the subproblems here solve revolute chains)")
    if cm.n not in (5, 6):
        return Classification(None, f"{cm.n} joints (the subproblems here solve 5R and 6R chains)")
    v = cm.vectors(np.zeros(cm.n))
    return classify_vectors(v["e"].copy(), v["o"].copy(), v["R"].copy(), v["N"].copy())


def classify_vectors(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> Classification:
    """The analytic class of a revolute chain given by its (n, 3) unit axes h and points o at q = 0 and its
    tool's rotation R0 and point N0 there (base frame, metres), n = 5 or 6: a closed form in either orientation
    before a search class in either — except where three axes at an end meet: Pieper's decoupling takes the chain,
    the search's roots added to its own (a search whose shoulder has a third axis through its point misses roots,
    and the decoupling some near its own singular configurations: on the xArm7's six with joint 4 held, 989 and
    966 of 1,000 poses, together 998)."""
    failed = []
    for searched in (False, True):
        for mirrored in (False, True):
            found = _class_read(h, o, R0, N0, searched, mirrored)
            if isinstance(found, ArmClass):
                return Classification(found, "")
            if not searched:
                failed.append(("read from the tool: " if mirrored else "") + found)
    if h.shape[0] == 6:
        failed.append("nor a 1-D search class (two consecutive wrist axes meeting, with axes 2, 3 parallel or axes "
                      "1, 2 or 2, 3 meeting, read either way)")
    return Classification(None, " | ".join(failed))


def _class_read(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, searched: bool,
                mirrored: bool) -> ArmClass | str:
    """The chain's first closed form (or, with ``searched``, search class) read from the base (or, ``mirrored``,
    from the tool) — a search class with Pieper's decoupling where that also takes the chain — or the tests missed,
    in words."""
    hh, oo, RR, NN = reverse(h, o, R0, N0) if mirrored else (h, o, R0, N0)
    arm, misses = _first_class(hh, oo, RR, NN, searched, mirrored)
    if arm is None:
        return " / ".join(misses)
    decoupled = pieper_vectors(h, o, R0, N0).arm if searched else None
    return arm if decoupled is None else with_search(decoupled, arm)


def _first_class(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, searched: bool,
                 mirrored: bool) -> tuple[ArmClass | None, list[str]]:
    """The first class of the chain (h, o, R0, N0) among the closed forms (or, with ``searched``, the search
    classes), and the tests each class before it failed."""
    misses: list[str] = []
    for kind, name, test in CLASSES[h.shape[0]]:
        if (kind >= SEARCH_6R) != searched:
            continue
        missed = test(h, o)
        if isinstance(missed, np.ndarray):  # in the class: the points it solves with
            label = name + (" (mirrored: read from the tool)" if mirrored else "")
            return ArmClass(label, kind, mirrored, h, missed, R0, N0), misses
        misses.append(missed)
    return None, misses


def _parallel(h: np.ndarray, o: np.ndarray) -> np.ndarray | str:
    """The points the class h₂ ∥ h₃ ∥ h₄ (axes 5 and 6 meeting, in 6R) solves with, or the tests failed."""
    misses = _misses(h, o)
    if misses:
        return "; ".join(misses)
    oo: np.ndarray = o.copy()
    if h.shape[0] == 6:
        oo[4] = oo[5] = meeting_point(oo[4], h[4], oo[5], h[5])
    return oo


def _spherical(h: np.ndarray, o: np.ndarray) -> np.ndarray | str:
    """The points the class h₂ ∥ h₃, axes 4, 5, 6 meeting solves with (o[3..5] the wrist point), or the tests
    failed."""
    return _with_wrist(h, o, _unparallel(h, ((1, 2),)) + _shoulder_parallel(h))


def _meeting(h: np.ndarray, o: np.ndarray) -> np.ndarray | str:
    """The points the class axes 1, 2 meeting, axes 4, 5, 6 meeting solves with (o[0..1] the shoulder point,
    o[3..5] the wrist point), or the tests failed."""
    if _angle(h[0], h[1]) <= AXIS_TOL:
        return "axes 1 and 2 are parallel"
    gap = line_distance(o[0], h[0], o[1], h[1])
    if gap > POINT_TOL:
        return f"axes 1 and 2 are {gap:.2g} m apart (tolerance {POINT_TOL:g})"
    found = _with_wrist(h, o, [])
    if isinstance(found, np.ndarray):
        found[0] = found[1] = meeting_point(o[0], h[0], o[1], h[1])
    return found


def _two_three(h: np.ndarray, o: np.ndarray) -> np.ndarray | str:
    """The points the class h₁ ∥ h₂, h₃ ∥ h₄ ∥ h₅ solves with (as given), or the tests failed."""
    misses = _unparallel(h, ((0, 1), (2, 3), (2, 4)))
    if _angle(h[0], h[2]) <= AXIS_TOL or _angle(h[2], h[5]) <= AXIS_TOL:
        misses.append("axis 3 is parallel to axis 1 or 6")
    if not misses and line_distance(o[0], h[0], o[1], h[1]) <= POINT_TOL:
        misses.append("axes 1 and 2 are one line")
    return "; ".join(misses) if misses else o.copy()


def _with_wrist(h: np.ndarray, o: np.ndarray, misses: list[str]) -> np.ndarray | str:
    """o with o[3..5] moved to the point where axes 4, 5, 6 meet, or ``misses`` and the wrist's failed tests."""
    if _angle(h[3], h[4]) <= AXIS_TOL or _angle(h[4], h[5]) <= AXIS_TOL:
        misses.append("axis 5 is parallel to axis 4 or 6")
        return "; ".join(misses)
    w = meeting_point(o[3], h[3], o[4], h[4])
    gap = max(line_distance(o[3], h[3], o[4], h[4]), line_distance(w, h[5], o[5], h[5]))
    if gap > POINT_TOL:
        misses.append(f"axes 4, 5 and 6 miss a common point by {gap:.2g} m (tolerance {POINT_TOL:g})")
    if misses:
        return "; ".join(misses)
    oo: np.ndarray = o.copy()
    oo[3] = oo[4] = oo[5] = w
    return oo


_SHOULDERS = ("axes 2, 3 parallel", "axes 1, 2 meeting", "axes 2, 3 meeting")
_PAIRS = ((3, "axes 4, 5 meeting"), (4, "axes 5, 6 meeting"))


def _searched(pair: int, shoulder: int) -> tuple[int, str, Any]:
    """The search class (kernel code, name, test) of a wrist pair (0: axes 4, 5; 1: axes 5, 6) and a shoulder
    (0: h₂ ∥ h₃; 1: axes 1, 2 meeting; 2: axes 2, 3 meeting)."""
    a, pair_name = _PAIRS[pair]

    def test(h: np.ndarray, o: np.ndarray) -> np.ndarray | str:
        misses = _shoulder_places(h, o, shoulder)
        if _angle(h[a], h[a + 1]) <= AXIS_TOL:
            misses.append(f"axes {a + 1} and {a + 2} are parallel")
        elif (gap := line_distance(o[a], h[a], o[a + 1], h[a + 1])) > POINT_TOL:
            misses.append(f"axes {a + 1} and {a + 2} are {gap:.2g} m apart")
        if misses:
            return "; ".join(misses)
        oo: np.ndarray = o.copy()
        oo[a] = oo[a + 1] = meeting_point(o[a], h[a], o[a + 1], h[a + 1])
        if shoulder:
            i = shoulder - 1
            oo[i] = oo[i + 1] = meeting_point(o[i], h[i], o[i + 1], h[i + 1])
        return oo

    name = f"6R, {_SHOULDERS[shoulder]}, {pair_name}"
    return SEARCH_6R + 3 * pair + shoulder, name, test


def _shoulder_places(h: np.ndarray, o: np.ndarray, shoulder: int) -> list[str]:
    """The tests, in words, that keep joints 1–3 from placing a point in closed form the way ``shoulder`` does."""
    if shoulder == 0:
        return _unparallel(h, ((1, 2),)) + _shoulder_parallel(h)
    i = shoulder - 1
    if _angle(h[i], h[i + 1]) <= AXIS_TOL:
        return [f"axes {i + 1} and {i + 2} are parallel"]
    if (gap := line_distance(o[i], h[i], o[i + 1], h[i + 1])) > POINT_TOL:
        return [f"axes {i + 1} and {i + 2} are {gap:.2g} m apart"]
    if shoulder == 2 and line_distance(o[0], h[0], meeting_point(o[1], h[1], o[2], h[2]), h[0]) <= POINT_TOL:
        return ["axes 1, 2 and 3 meet (joint 1 would not move the point's distance from them)"]
    return []


CLASSES = {6: ((PARALLEL_6R, "6R, axes 2, 3, 4 parallel, axes 5 and 6 meeting", _parallel),
               (SPHERICAL_6R, "6R, axes 2, 3 parallel, axes 4, 5, 6 meeting (spherical wrist)", _spherical),
               (MEETING_6R, "6R, axes 1, 2 meeting, axes 4, 5, 6 meeting (spherical wrist)", _meeting),
               (TWO_THREE_6R, "6R, axes 1, 2 parallel, axes 3, 4, 5 parallel", _two_three),
               *(_searched(pair, shoulder) for pair in (0, 1) for shoulder in (0, 1, 2))),
           5: ((PARALLEL_5R, "5R, axes 2, 3, 4 parallel", _parallel),)}


def _misses(h: np.ndarray, o: np.ndarray) -> list[str]:
    """The class tests these axes fail, in words (empty: in the class)."""
    misses = _unparallel(h, ((1, 2), (1, 3))) + _shoulder_parallel(h)
    if h.shape[0] == 6:
        gap = line_distance(o[4], h[4], o[5], h[5])
        if gap > POINT_TOL:
            misses.append(f"axes 5 and 6 are {gap:.2g} m apart (tolerance {POINT_TOL:g})")
        if _angle(h[4], h[5]) <= AXIS_TOL:
            misses.append("axes 5 and 6 are parallel")
    elif _angle(h[4], h[1]) <= AXIS_TOL:
        misses.append("axis 5 is parallel to axis 2 (the wrist could not turn the tool out of the arm's plane)")
    return misses


def _unparallel(h: np.ndarray, pairs: tuple[tuple[int, int], ...]) -> list[str]:
    """The pairs of axes (0-based indices) that are not parallel within AXIS_TOL, in words."""
    return [f"axes {i + 1} and {j + 1} are {angle:.2g} rad from parallel (tolerance {AXIS_TOL:g})"
            for i, j in pairs if (angle := _angle(h[i], h[j])) > AXIS_TOL]


def _shoulder_parallel(h: np.ndarray) -> list[str]:
    """The failed test, in words, when axes 1 and 2 are parallel (joint 1 would then not fix the elbow's plane)."""
    if _angle(h[0], h[1]) <= AXIS_TOL:
        return ["axes 1 and 2 are parallel (joint 1 would not fix the plane of the elbow)"]
    return []


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between two lines' directions [rad], in [0, π/2]."""
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), abs(np.dot(a, b))))


def line_distance(p: np.ndarray, a: np.ndarray, q: np.ndarray, b: np.ndarray) -> float:
    """The distance [m] between the line through p along a and the line through q along b (unit a, b)."""
    n = np.cross(a, b)
    if np.linalg.norm(n) < AXIS_TOL:
        d = q - p
        return float(np.linalg.norm(d - a * np.dot(a, d)))
    return float(abs(np.dot(q - p, n)) / np.linalg.norm(n))


def meeting_point(p: np.ndarray, a: np.ndarray, q: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The midpoint of the closest points of two non-parallel lines (their meeting point when they meet)."""
    w = p - q
    A, B, C = float(np.dot(a, a)), float(np.dot(a, b)), float(np.dot(b, b))
    D, E = float(np.dot(a, w)), float(np.dot(b, w))
    den = A * C - B * B
    s, t = (B * E - C * D) / den, (A * E - B * D) / den
    return np.asarray(0.5 * ((p + s * a) + (q + t * b)), dtype=float)


def reverse(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray) -> tuple[np.ndarray, ...]:
    """The chain read from the tool back: T(q)⁻¹ = T'(q') with q' = −q reversed, axes R0ᵀ·h and points
    R0ᵀ·(o − N0) in reverse order, and tool pose at q' = 0 the inverse of T(0)."""
    return (h[::-1] @ R0, (o[::-1] - N0) @ R0, R0.T.copy(), -R0.T @ N0)
