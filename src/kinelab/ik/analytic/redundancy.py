"""7R arms by their redundancy parameter: one end joint swept over K samples, the other six in closed form.

A 7R arm has a one-parameter family of answers per pose. When holding its first (or last) joint at a value
leaves six joints in an analytic class (:mod:`kinelab.ik.analytic.classify`), every branch at that value
comes from the closed form: with the first joint at θ, the rest must reach M(θ)⁻¹·oMtarget, M(θ) the
rotation by θ about the first joint's line (base frame); with the last joint at θ, oMtarget·S(θ)⁻¹, S(θ) the
rotation about the last joint's line seen from the tool at θ = 0. The first joint is tried first. Every
answer is judged by Pinocchio's FK of the whole chain within all of its limits.

The ERA (the FRDM paper's arm, joint 1 held), the Panda and the xArm7 (joint 7 held), the PR2, TALOS and
TIAGo arms are such arms; Baxter's and TIAGo Pro's are not, and are refused with the tests each end failed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import ChainError, OptionError
from kinelab.geometry import wrap_to_pi
from kinelab.ik.analytic.branches import Answer, Rows, arm_roots, branch_results, judged_roots, limit_slack
from kinelab.ik.analytic.certify import chain_pose
from kinelab.ik.analytic.classify import (
    AXIS_TOL,
    POINT_TOL,
    ArmClass,
    classify,
    classify_vectors,
    general_class,
    general_vectors,
)
from kinelab.ik.analytic.kernel import GENERAL_6R
from kinelab.ik.chain import PRISMATIC, chain_model
from kinelab.ik.limits import distance
from kinelab.ik.request import Deadline, Request
from kinelab.ik.result import Branches
from kinelab.ik.targets import beyond_reach
from kinelab.robot import Chain
from kinelab.values import is_real, is_whole


@dataclass(frozen=True, eq=False)
class SweptArm:
    """A 7R chain whose joint ``joint`` (0: the first, 6: the last) is swept and the other six solved.

    Attributes:
        joint: index of the swept joint in the chain.
        arm: the class of the other six joints, with the swept one at 0.
        axis, point: the swept joint's unit axis and a point on it [m]: in the base frame for the first
            joint, in the tool frame (at θ = 0) for the last.
    """

    joint: int
    arm: ArmClass
    axis: np.ndarray
    point: np.ndarray

    def sub_target(self, H: np.ndarray, theta: float) -> np.ndarray:
        """The 4 × 4 pose the six other joints must reach when the swept joint is at ``theta`` [rad]: H turned by
        −θ about the joint's line (on the left for the first joint, on the right for the last)."""
        back = np.eye(4)
        back[:3, :3] = pin.exp3(-theta * self.axis)
        back[:3, 3] = self.point - back[:3, :3] @ self.point
        return back @ H if self.joint == 0 else H @ back


def swept_arm(robot: Chain, k: object = None) -> SweptArm:
    """The robot's swept form, built once per Chain.

    Raises:
        OptionError: the chain is not 7R, or holding neither end joint leaves an analytic class (the tests
            each failed named).
    """
    found = robot.derived("analytic_swept", _swept)
    if isinstance(found, str):
        raise OptionError("redundancy", k, f"a 7R chain that is analytic with its first or last joint held "
                          f"(docs/analytic.md); {robot.name}'s is not: {found}")
    return found


def has_swept_form(robot: Chain) -> bool:
    """True when :func:`swept_arm` accepts the robot."""
    return isinstance(robot.derived("analytic_swept", _swept), SweptArm)


def _swept(robot: Chain) -> SweptArm | str:
    v = _chain7(robot)
    if isinstance(v, str):
        return v
    reasons, held = [], []
    for general in (False, True):  # a class at either end before the general elimination at either
        for joint in (0, 6):
            found = holding(v["e"], v["o"], v["R"], v["N"], joint, general)
            if isinstance(found, SweptArm):
                held.append(found)
            else:
                reasons.append(f"joint {joint + 1} held (the other six's axes numbered 1 to 6): {found}")
        if held:  # a closed form at either end before a search
            return min(held, key=lambda sw: (sw.arm.searched, sw.arm.kind == GENERAL_6R))
    return "; ".join(reasons)


def _chain7(robot: Chain) -> dict[str, np.ndarray] | str:
    """The 7R chain's vectors at q = 0 (``e`` axes, ``o`` points, ``R``, ``N`` the tool), or why it is not one."""
    try:
        cm = chain_model(robot)
    except ChainError as err:
        return str(err)
    if cm.n != 7 or (cm.kind == PRISMATIC).any():
        return f"{cm.n} joints{', one prismatic' if (cm.kind == PRISMATIC).any() else ''} (a 7R chain is swept)"
    return {k: np.array(a, dtype=float) for k, a in cm.vectors(np.zeros(7)).items()}


def chain7_vectors(robot: Chain) -> dict[str, np.ndarray]:
    """The 7R chain's vectors at q = 0 (:func:`_chain7`).

    Raises:
        OptionError: the robot's chain is not 7R (why named).
    """
    v = _chain7(robot)
    if isinstance(v, str):
        raise OptionError("redundancy", "SEW", f"a 7R chain; {robot.name}'s is not: {v}")
    return v


def holding(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, joint: int,
            general: bool = False) -> SweptArm | str:
    """The 7R chain (axes h, points o at q = 0, tool R0, N0; base frame) swept at its end joint ``joint``
    (0 or 6), or why the other six are in no class (with ``general``: nor taken by the general elimination)."""
    keep = slice(1, 7) if joint == 0 else slice(0, 6)
    c = (general_vectors if general else classify_vectors)(h[keep].copy(), o[keep].copy(), R0.copy(), N0.copy())
    if c.arm is None:
        return c.reason
    if joint == 0:
        return SweptArm(0, c.arm, h[0].copy(), o[0].copy())
    return SweptArm(6, c.arm, R0.T @ h[6], R0.T @ (o[6] - N0))


def fold(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, joint: int,
         theta: float) -> tuple[np.ndarray, ...]:
    """The six-joint chain left when joint ``joint`` of the chain (h, o, R0, N0) is held at ``theta`` [rad]: the
    turn M about its line moves every later axis and the tool (M·E_j(q)·M⁻¹ is the turn about M's image of line
    j), so the six are the earlier axes as they are and the later ones, and the tool, carried by M."""
    R = pin.exp3(theta * h[joint])
    t = o[joint] - R @ o[joint]
    after = np.arange(h.shape[0]) > joint
    h6, o6 = h.copy(), o.copy()
    h6[after], o6[after] = h[after] @ R.T, o[after] @ R.T + t
    keep = np.arange(h.shape[0]) != joint
    return h6[keep], o6[keep], R @ R0, R @ N0 + t


HELD_KEPT = 64  # held (joint, value) arms kept per robot: a sweep over a middle joint builds one arm per value


def arm_holding(robot: Chain, joint: int, theta: float) -> ArmClass | str:
    """The arm of the six joints left when the 7R robot's joint ``joint`` is held at ``theta`` [rad] — a class,
    else the general elimination or Pieper's decoupling (:func:`~kinelab.ik.analytic.classify.general_vectors`) —
    or why there is none."""
    kept: dict[tuple[int, float], ArmClass | str] = robot.derived("held arms", _new_held)
    key = (joint, float(theta))
    if key not in kept:
        v = _chain7(robot)
        if isinstance(v, str):
            return v
        h, o, R0, N0 = fold(v["e"], v["o"], v["R"], v["N"], joint, theta)
        found = classify_vectors(h, o, R0, N0)
        if found.arm is None or not recovers(found.arm, h, o, R0, N0):
            found = general_vectors(h, o, R0, N0)
        if len(kept) >= HELD_KEPT:
            kept.clear()
        kept[key] = found.arm if found.arm is not None else found.reason
    return kept[key]


def recovers(arm: ArmClass, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, trials: int = 3) -> bool:
    """True when the arm's solver finds seeded configurations of the chain (h, o, R0, N0) among the roots of their
    own poses (to 1e-6 rad): a class whose test holds on a chain it degenerates on (a search's shoulder with a
    third axis through its point) is caught here."""
    wide = np.full(h.shape[0], np.pi)
    for q in np.random.default_rng(1).uniform(-np.pi, np.pi, (trials, h.shape[0])):
        roots = arm_roots(arm, chain_pose(h, o, R0, N0, q), -wide, wide, None)[0]
        if not len(roots) or np.abs(wrap_to_pi(roots - q)).max(axis=1).min() > 1e-6:
            return False
    return True


def _new_held(_: Chain) -> dict[tuple[int, float], ArmClass | str]:
    return {}


def samples(lower: float, upper: float, k: int) -> np.ndarray:
    """K values of the swept joint [rad]: the midpoints of K equal cells of its range, the range cut to one
    turn (−π, π] when it spans more (θ and θ + 2π are one configuration)."""
    lo, hi = lower, upper
    if hi - lo >= 2 * math.pi:
        lo, hi = -math.pi, math.pi
    return lo + (np.arange(k) + 0.5) * (hi - lo) / k


def check_redundancy(k: object) -> int:
    """K as an int.

    Raises:
        OptionError: K is not an integer in [1, 4096].
    """
    if not is_whole(k, 1, 4096):
        raise OptionError("redundancy", k, "an integer in [1, 4096]: the samples of the swept joint, or "
                          "{joint name: value}, or None")
    return int(k)


def held_values(robot: Chain, redundancy: object) -> tuple[np.ndarray, str, int]:
    """The values [rad] of the held joint that ``redundancy`` asks for, how they read in ``mode``, and the joint's
    index: K samples of the swept end joint (:func:`samples`), or the one value of ``{joint name: value}`` for any
    joint of the 7R chain.

    Raises:
        OptionError: K out of range, or a mapping that does not name one joint with a finite value within its
            limits (the joint and its limits named), or a chain that cannot be swept (K samples) or is not 7R.
    """
    if not isinstance(redundancy, Mapping):
        sw = swept_arm(robot, redundancy)
        k = check_redundancy(redundancy)
        return samples(float(robot.lower[sw.joint]), float(robot.upper[sw.joint]), k), f"swept over {k} samples", \
            sw.joint
    index, value = _held_named(robot, redundancy)
    names = [j.name for j in robot.joints]
    lo, hi = float(robot.lower[index]), float(robot.upper[index])
    if not is_real(value, lo, hi):
        raise OptionError("redundancy", dict(redundancy), f"{{{names[index]!r}: a value in [{lo:.6g}, {hi:.6g}] rad}}"
                          " (any one joint, held at a value within its limits), or an integer K")
    return np.array([float(value)]), f"held at {float(value):.6g} rad", index


def _held_named(robot: Chain, redundancy: Mapping[object, object]) -> tuple[int, object]:
    """The index of the one joint ``{joint name: value}`` names and its value as given (None, with the swept joint
    or joint 0 to name in the error, when it names no joint or several).

    Raises:
        OptionError: the chain is not 7R.
    """
    chain = _chain7(robot)
    if isinstance(chain, str):
        raise OptionError("redundancy", dict(redundancy), f"{{joint name: value}} for a 7R chain; {robot.name}'s is "
                          f"not: {chain}")
    names = [j.name for j in robot.joints]
    named = [names.index(n) for n in redundancy if n in names] if len(redundancy) == 1 else []
    if named:
        return named[0], redundancy.get(names[named[0]])
    return (swept_arm(robot).joint if has_swept_form(robot) else 0), None


def at_value(robot: Chain, target: pin.SE3, req: Request, theta: float,
             q_ref: np.ndarray | None = None, joint: int | None = None, end: float = math.inf) -> list[Answer]:
    """Every branch of ``target`` with joint ``joint`` (None: the swept one) held at ``theta`` [rad] that Pinocchio
    confirms within the limits: (q, position error [m], rotation error [rad], finished by FRDM before ``end``
    (``time.perf_counter``'s clock [s]), roots merged, one of a continuum).

    Raises:
        OptionError: the chain cannot be swept (``joint`` None), or the six left are solved by nothing here.
    """
    if joint is None or _is_swept(robot, joint):
        sw = swept_arm(robot)
        joint, arm, H = sw.joint, sw.arm, sw.sub_target(target.homogeneous, theta)
    else:
        found = arm_holding(robot, joint, theta)
        if isinstance(found, str):
            raise OptionError("redundancy", {robot.joints[joint].name: theta}, "a joint whose holding leaves six "
                              f"joints kinelab solves; holding {robot.joints[joint].name} leaves: {found}")
        arm, H = found, target.homogeneous
    keep = np.arange(7) != joint
    ref = None if q_ref is None else q_ref[keep]
    q6, found_, free = arm_roots(arm, H, robot.lower[keep], robot.upper[keep], ref, limit_slack(req.tol_rot))
    q = np.ascontiguousarray(np.insert(q6, joint, theta, axis=1))
    return judged_roots(robot, q, found_, free, target, req, {robot.joints[joint].name: theta}, end)


def _is_swept(robot: Chain, joint: int) -> bool:
    """True when ``joint`` is the end joint the robot's swept form holds."""
    return has_swept_form(robot) and joint == swept_arm(robot).joint


def redundant_all(robot: Chain, target: pin.SE3, req: Request, redundancy: object,
                  q_ref: np.ndarray | None = None, max_solutions: int | None = None) -> Branches:
    """Every branch of ``target`` (oMtarget, base frame) at the values of the held joint ``redundancy`` asks for
    (:func:`held_values`), each judged by Pinocchio within the limits.

    Args:
        robot: a 7R robot.
        target: the pose.
        req: the validated request (task "pose").
        redundancy: K samples of the swept end joint (:func:`samples`; a robot :func:`swept_arm` accepts),
            ``{joint name: value}`` for any one joint held at one value (a SEW angle:
            :func:`~kinelab.ik.analytic.sew.sew_all`).
        q_ref: sort the answers by distance to this configuration; each angle's copy is picked nearest it.
        max_solutions: at most this many answers (the nearest ``q_ref`` first when given).

    Returns:
        One :class:`IKResult` per answer; ``diagnostics.branches`` counts them all.

    Raises:
        OptionError: the chain cannot be swept, ``redundancy`` is not valid, or the task is not "pose".
    """
    t0 = time.perf_counter()
    if req.task.name != "pose":
        raise OptionError("task", req.task_label, "'pose' with redundancy= (other tasks: solver='frdm')")
    values, how, joint = held_values(robot, redundancy)
    deadline = Deadline(t0, req.time_budget)
    answers: list[Answer] = []
    late = ""
    beyond = beyond_reach(robot, target.translation)
    for k, theta in enumerate(values if not beyond else ()):
        if deadline.near():
            late = f"after {k} of {len(values)} values of joint {joint + 1}"
            break
        answers += at_value(robot, target, req, float(theta), q_ref, joint, deadline.end)
    if q_ref is not None:
        answers.sort(key=lambda a: distance(robot, a[0], q_ref))
    arm = swept_arm(robot).arm if _is_swept(robot, joint) else arm_holding(robot, joint, float(values[0]))
    mode = f"analytic ({_arm_words(arm)}; joint {joint + 1} {how})"
    return branch_results(robot, Rows.of(answers, robot.n), req, mode, time.perf_counter() - t0, max_solutions, "sweep",
                          f"no branch within the joint limits with joint {joint + 1} {how}", beyond=beyond, late=late)


def _arm_words(arm: ArmClass | str) -> str:
    """The six joints' arm in ``mode``: its own mode's words and, when searched, of which joints."""
    if isinstance(arm, str):
        return "the other six"
    return arm.mode.removeprefix("analytic (").removesuffix(")") + (" of the other six" if arm.searched else "")


def closed_form_summary(robot: Chain) -> str:
    """One line on the robot's every-branch method and how complete its sets are (``kinelab info --verbose`` and
    JSON): its class, the joint a 7R arm holds, the general 6R elimination, or none."""
    arm = classify(robot).arm
    if arm is not None:
        return f"{arm.name}: {arm.method} ({COMPLETE['search' if arm.searched else 'closed form']})"
    if has_swept_form(robot):
        sw = swept_arm(robot)
        return (f"with joint {sw.joint + 1} ({robot.joints[sw.joint].name}) held: {sw.arm.name}, {sw.arm.method} of "
                "the other six (solve_all(..., redundancy=K); any one joint held: redundancy={joint name: value})")
    none = (f"none: no class holds to its tolerances ({AXIS_TOL:g} rad between parallel axes, {POINT_TOL:g} m between "
            "meeting ones; a calibrated arm misses them by more)")
    general = general_class(robot).arm
    if general is not None:
        return f"{none}; {general.name}: {general.method} ({COMPLETE['elimination']})"
    return f"{none} — the numeric multistart; solver='analytic' names the failed tests"


def closed_form_words(robot: Chain) -> str:
    """The same in plain words (``kinelab info``): how every branch of a pose is found, and how sure the set is."""
    arm = classify(robot).arm
    if arm is not None:
        return ("every branch by a one-dimensional search, checked complete on thousands of poses" if arm.searched
                else "every branch in closed form, each one proved")
    if has_swept_form(robot):
        sw = swept_arm(robot)
        return (f"every branch in closed form with joint {sw.joint + 1} ({robot.joints[sw.joint].name}) held at a "
                "value; the arm has one more joint than a pose needs")
    if general_class(robot).arm is not None:
        return "every branch by the general six-joint elimination, each one proved"
    return ("no formula fits this arm's geometry: its branches are found from many random starts (--verbose says "
            "which geometric tests fail)")


COMPLETE = {  # how complete each method's sets are, in words (kinelab info)
    "closed form": "certified: each branch proved a root, the set every root unless a double root is met",
    "search": "measured complete; certified by 16 proved branches, or where the general elimination takes the chain "
              "by its certified set",
    "elimination": "certified: each branch proved a root, the eigenvalues counting every root",
}
