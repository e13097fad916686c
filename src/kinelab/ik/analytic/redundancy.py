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
from kinelab.ik.analytic.branches import Answer, Rows, arm_roots, branch_results, judged_roots, limit_slack
from kinelab.ik.analytic.classify import AXIS_TOL, POINT_TOL, ArmClass, classify, classify_vectors
from kinelab.ik.chain import PRISMATIC, chain_model
from kinelab.ik.limits import distance
from kinelab.ik.request import Request
from kinelab.ik.result import Branches
from kinelab.ik.targets import beyond_reach
from kinelab.robot import Robot


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


def swept_arm(robot: Robot, k: object = None) -> SweptArm:
    """The robot's swept form, built once per Robot.

    Raises:
        OptionError: the chain is not 7R, or holding neither end joint leaves an analytic class (the tests
            each failed named).
    """
    found = robot.derived("analytic_swept", _swept)
    if isinstance(found, str):
        raise OptionError("redundancy", k, f"a 7R chain that is analytic with its first or last joint held "
                          f"(docs/analytic.md); {robot.name}'s is not: {found}")
    return found


def has_swept_form(robot: Robot) -> bool:
    """True when :func:`swept_arm` accepts the robot."""
    return isinstance(robot.derived("analytic_swept", _swept), SweptArm)


def _swept(robot: Robot) -> SweptArm | str:
    try:
        cm = chain_model(robot)
    except ChainError as err:
        return str(err)
    if cm.n != 7 or (cm.kind == PRISMATIC).any():
        return f"{cm.n} joints{', one prismatic' if (cm.kind == PRISMATIC).any() else ''} (a 7R chain is swept)"
    v = cm.vectors(np.zeros(7))
    reasons, held = [], []
    for joint in (0, 6):
        found = holding(v["e"], v["o"], v["R"], v["N"], joint)
        if isinstance(found, SweptArm):
            held.append(found)
        else:
            reasons.append(f"joint {joint + 1} held (the other six's axes numbered 1 to 6): {found}")
    if held:  # a closed form at either end before a search
        return min(held, key=lambda sw: sw.arm.searched)
    return "; ".join(reasons)


def holding(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, joint: int) -> SweptArm | str:
    """The 7R chain (axes h, points o at q = 0, tool R0, N0; base frame) swept at its end joint ``joint``
    (0 or 6), or why the other six are in no class."""
    keep = slice(1, 7) if joint == 0 else slice(0, 6)
    c = classify_vectors(h[keep].copy(), o[keep].copy(), R0.copy(), N0.copy())
    if c.arm is None:
        return c.reason
    if joint == 0:
        return SweptArm(0, c.arm, h[0].copy(), o[0].copy())
    return SweptArm(6, c.arm, R0.T @ h[6], R0.T @ (o[6] - N0))


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
    if isinstance(k, bool) or not isinstance(k, int | np.integer) or not 1 <= k <= 4096:
        raise OptionError("redundancy", k, "an integer in [1, 4096]: the samples of the swept joint, or "
                          "{joint name: value}, or None")
    return int(k)


def held_values(robot: Robot, redundancy: object) -> tuple[np.ndarray, str]:
    """The values [rad] of the swept joint that ``redundancy`` asks for, and how they read in ``mode``: K samples
    (:func:`samples`), or the one value of ``{joint name: value}``.

    Raises:
        OptionError: K out of range, or a mapping that does not name the swept joint once with a finite value
            within its limits (the joint and its limits named), or a chain that cannot be swept.
    """
    sw = swept_arm(robot, redundancy)
    joint = robot.joints[sw.joint]
    if not isinstance(redundancy, Mapping):
        k = check_redundancy(redundancy)
        return samples(float(robot.lower[sw.joint]), float(robot.upper[sw.joint]), k), f"swept over {k} samples"
    value = redundancy.get(joint.name) if len(redundancy) == 1 else None
    lo, hi = float(robot.lower[sw.joint]), float(robot.upper[sw.joint])
    if isinstance(value, bool) or not isinstance(value, int | float | np.number) or not lo <= float(value) <= hi:
        raise OptionError("redundancy", dict(redundancy), f"{{{joint.name!r}: a value in [{lo:.6g}, {hi:.6g}] rad}}, "
                          "the joint the closed form holds, or an integer K")
    return np.array([float(value)]), f"held at {float(value):.6g} rad"


def at_value(robot: Robot, target: pin.SE3, req: Request, theta: float,
             q_ref: np.ndarray | None = None) -> list[Answer]:
    """Every branch of ``target`` with the swept joint at ``theta`` [rad] that Pinocchio confirms within the
    limits: (q, position error [m], rotation error [rad], finished by FRDM, roots merged, one of a continuum).

    Raises:
        OptionError: the chain cannot be swept.
    """
    sw = swept_arm(robot)
    keep = np.arange(7) != sw.joint
    ref = None if q_ref is None else q_ref[keep]
    q6, found, free = arm_roots(sw.arm, sw.sub_target(target.homogeneous, theta), robot.lower[keep],
                                robot.upper[keep], ref, limit_slack(req.tol_rot))
    q = np.ascontiguousarray(np.insert(q6, sw.joint, theta, axis=1))
    return judged_roots(robot, q, found, free, target, req, {robot.joints[sw.joint].name: theta})


def redundant_all(robot: Robot, target: pin.SE3, req: Request, redundancy: object,
                  q_ref: np.ndarray | None = None, max_solutions: int | None = None) -> Branches:
    """Every branch of ``target`` (oMtarget, base frame) at the values of the swept joint ``redundancy`` asks for
    (:func:`held_values`), each judged by Pinocchio within the limits.

    Args:
        robot: a 7R robot that :func:`swept_arm` accepts.
        target: the pose.
        req: the validated request (task "pose").
        redundancy: K samples of the swept joint (:func:`samples`), or ``{joint name: value}`` for one value.
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
    values, how = held_values(robot, redundancy)
    sw = swept_arm(robot)
    answers = []
    for theta in values:
        answers += at_value(robot, target, req, float(theta), q_ref)
    if q_ref is not None:
        answers.sort(key=lambda a: distance(robot, a[0], q_ref))
    search = f"; {sw.arm.method.removeprefix('every branch by a ')} of the other six" if sw.arm.searched else ""
    mode = f"analytic ({sw.arm.name}{search}; joint {sw.joint + 1} {how})"
    return branch_results(robot, Rows.of(answers, robot.n), req, mode, time.perf_counter() - t0, max_solutions, "sweep",
                          beyond_reach(robot, target.translation)
                          or f"no branch within the joint limits with joint {sw.joint + 1} {how}")


def closed_form_summary(robot: Robot) -> str:
    """One line on the robot's closed form (``kinelab info``): its class, the joint a 7R arm holds, or none."""
    arm = classify(robot).arm
    if arm is not None:
        return f"{arm.name}: {arm.method}"
    if has_swept_form(robot):
        sw = swept_arm(robot)
        return (f"with joint {sw.joint + 1} ({robot.joints[sw.joint].name}) held: {sw.arm.name}, {sw.arm.method} of "
                "the other six (solve_all(..., redundancy=K))")
    return (f"none: no class holds to its tolerances ({AXIS_TOL:g} rad between parallel axes, {POINT_TOL:g} m between "
            "meeting ones; a calibrated arm misses them by more) — the numeric multistart; solver='analytic' names "
            "the failed tests")

