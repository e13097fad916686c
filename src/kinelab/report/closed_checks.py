"""``kinelab validate``'s checks of a robot that closes loops (``kinelab validate --robots fourbar delta``).

Each is against Pinocchio or a closed form: every closure's error against Pinocchio 4's constraint models and its
Jacobian against central differences; assemblies from random motor configurations re-judged by Pinocchio's FK (and
the four-bar's and the delta's against their closed forms); the loops after every step of a run toward moving
targets; the converged solve on reachable targets, every success judged again here with its loops.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import AssemblyError
from kinelab.report.check import SHARE, Check, samples_for
from kinelab.robot.assembly import actuated_indices
from kinelab.robot.tree import Robot

FD = 1e-6  # [rad or m] the central difference's step
LOOP_TOL = 1e-10  # [m, rad] an assembly's and a converged solve's loops
STEP_TOL = 1e-9  # [m, rad] the loops after a step
MET_BAR = 0.95  # reachable targets met, by the share's 95 % lower bound
TARGETS = samples_for(MET_BAR, 2)
STEPS = 1000


def loops_of(robot: Robot, data: pin.Data, q: np.ndarray) -> float:
    """The largest closure error at q, computed here from Pinocchio's frame placements (not kinelab's own)."""
    pin.framesForwardKinematics(robot.model, data, q)
    worst = 0.0
    for c in robot.closures:
        aMb = data.oMf[robot.frame_id(c.frame_a)].actInv(data.oMf[robot.frame_id(c.frame_b)])
        e = np.concatenate([aMb.translation, pin.log3(aMb.rotation)])
        worst = max(worst, float(np.abs(e[np.flatnonzero(c.mask)]).max()))
    return worst


def closure_model_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """Every closure's error against Pinocchio's PointAnchor (translation) and FrameAnchor (rotation) constraint
    models, and its Jacobian against central differences of the error along random directions."""
    rng = np.random.default_rng(seed + 10)
    model, data = robot.model, robot.model.createData()
    err = jac = 0.0
    for _ in range(min(n, 50)):
        q = robot.random_q(rng)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        pinocchio = np.concatenate([_anchor_error(robot, data, c) for c in robot.closures])
        err = max(err, float(np.abs(robot.closure_error(q) - pinocchio).max()))
        dv = rng.normal(size=robot.nv)
        fd = (robot.closure_error(robot.integrate(q, FD * dv)) - robot.closure_error(robot.integrate(q, -FD * dv)))
        fd /= 2 * FD
        jac = max(jac, float(np.abs(robot.closure_jacobian(q) @ dv - fd).max() / max(1.0, np.abs(fd).max())))
    where = f"{len(robot.closures)} closures at {min(n, 50)} configurations"
    return [Check(robot.name, "loops: closure errors vs Pinocchio's constraint models", err, 1e-12, "m, rad", where),
            Check(robot.name, "loops: closure Jacobians vs differences", jac, 1e-6, "relative", where)]


def _anchor_error(robot: Robot, data: pin.Data, closure: Any) -> np.ndarray:
    """A closure's held components by Pinocchio's constraint models: PointAnchor's residual (the translation) and
    FrameAnchor's angular part (the rotation's log)."""
    fa = robot.model.frames[robot.frame_id(closure.frame_a)]
    fb = robot.model.frames[robot.frame_id(closure.frame_b)]
    out = []
    for kind in (pin.PointAnchorConstraintModel, pin.FrameAnchorConstraintModel):
        cm = kind(robot.model, fa.parentJoint, fa.placement, fb.parentJoint, fb.placement)
        cd = cm.createData()
        cm.calc(robot.model, data, cd)
        out.append(np.asarray(cd.constraint_position_error))
    return np.concatenate([out[0], out[1][3:]])[np.flatnonzero(closure.mask)]


def assembly_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """Assemblies from ``n`` random motor configurations (the passive joints from the home pose): every one claimed
    closes the loops to 1e-10 by Pinocchio's FK within the limits, and where a closed form exists (fourbar,
    delta) the claims and refusals are its, the place its point."""
    rng = np.random.default_rng(seed + 11)
    data = robot.model.createData()
    home = robot.standing()
    actuated = actuated_indices(robot)[0]
    reference = CLOSED_FORMS.get(robot.name)
    false = disagree = claimed = 0
    for _ in range(n):
        q = home.copy()
        q[actuated] = robot.random_q(rng)[actuated]
        try:
            found: np.ndarray | None = robot.assemble(q)
        except AssemblyError:
            found = None
        if found is not None:
            claimed += 1
            false += loops_of(robot, data, found) > LOOP_TOL or not robot.within_limits(found)
        if reference is not None:
            disagree += not reference(robot, q[actuated], found)
    out = [Check(robot.name, "loops: assemblies claimed that do not close", float(false), 0.0, "count",
                 f"{claimed} of {n} random motor configurations assembled")]
    if reference is not None:
        out.append(Check(robot.name, "loops: assemblies against the closed form", float(disagree), 0.0, "count",
                         f"{n} motor configurations: claimed where it has one, at its point (1e-10)"))
    return out


def _fourbar(robot: Robot, motors: np.ndarray, found: np.ndarray | None) -> bool:
    """The four-bar's C (two circles' intersection) agrees with the assembly, or both say there is none."""
    a, b, c, d = 0.10, 0.28, 0.22, 0.30
    B, D = a * np.array([np.cos(motors[0]), np.sin(motors[0])]), np.array([d, 0.0])
    r = float(np.linalg.norm(D - B))
    if r > b + c or r < abs(b - c):
        return found is None
    along = (b * b - c * c + r * r) / (2 * r)
    h = np.sqrt(max(b * b - along * along, 0.0))
    mid, normal = B + along * (D - B) / r, np.array([-(D - B)[1], (D - B)[0]]) / r
    if found is None:
        return False
    tip = robot.frame_placement(found, "rocker_tip").translation[:2]
    return min(np.abs(tip - (mid + s * h * normal)).max() for s in (1.0, -1.0)) <= LOOP_TOL


def _delta(robot: Robot, motors: np.ndarray, found: np.ndarray | None) -> bool:
    """The delta's platform (three spheres' intersection) agrees with the assembly, or both say there is none."""
    R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04
    c = np.array([(R + LA * np.cos(t) - RP) * np.array([np.cos(p), np.sin(p), 0.0]) + [0.0, 0.0, -LA * np.sin(t)]
                  for p, t in zip((0.0, 2 * np.pi / 3, 4 * np.pi / 3), motors, strict=True)])
    A, rhs = 2 * (c[1:] - c[0]), (c[1:] ** 2).sum(1) - (c[0] ** 2).sum()
    n = np.cross(A[0], A[1])
    p0 = np.linalg.lstsq(A, rhs, rcond=None)[0]
    qa, qb, qc = n @ n, 2 * (p0 - c[0]) @ n, (p0 - c[0]) @ (p0 - c[0]) - LB**2
    disc = qb * qb - 4 * qa * qc
    if disc < 0:
        return found is None
    if found is None:
        return False
    P = robot.frame_placement(found, "platform_centre").translation
    return min(np.abs(P - (p0 + s * n)).max() for s in ((-qb - np.sqrt(disc)) / (2 * qa),
                                                          (-qb + np.sqrt(disc)) / (2 * qa))) <= LOOP_TOL


CLOSED_FORMS = {"fourbar": _fourbar, "delta": _delta}


def held_loops_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """STEPS steps of 10 ms of the first hand toward targets that move every 100 steps (each the hand's place at a
    random assembled configuration): the loops after every step, by Pinocchio's FK."""
    from kinelab.wholebody import FrameTask, WholeBody

    rng = np.random.default_rng(seed + 12)
    data = robot.model.createData()
    hand = robot.hands[0]
    q = robot.standing()
    worst, failed = 0.0, 0
    problem = WholeBody(robot, [FrameTask(hand, robot.frame_placement(q, hand).translation, task="position")])
    for k in range(STEPS):
        if k % 100 == 0:
            problem.set_target(0, robot.frame_placement(_random_assembly(robot, q, rng), hand).translation)
        result = problem.step(q, 0.01)
        failed += not result.solved
        q = result.q
        worst = max(worst, loops_of(robot, data, q))
    return [Check(robot.name, "loops: closure error after every step", worst, STEP_TOL, "m, rad",
                  f"{STEPS} steps of 10 ms, {STEPS // 100} targets, {failed} steps not solved")]


def _random_assembly(robot: Robot, near: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """An assembly with the motors at random (retried until one assembles)."""
    actuated = actuated_indices(robot)[0]
    for _ in range(100):
        q = near.copy()
        q[actuated] = robot.random_q(rng)[actuated]
        try:
            return robot.assemble(q)
        except AssemblyError:
            continue
    return near


def solve_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """The converged solve on TARGETS reachable positions of the first hand (its place at random assemblies): the
    share met, and every success met again here (the hand within 1e-6 m and the loops within 1e-10 by Pinocchio's
    FK, within the limits)."""
    from kinelab.wholebody.solve import solve
    from kinelab.wholebody.tasks import FrameTask

    rng = np.random.default_rng(seed + 13)
    data = robot.model.createData()
    hand, home = robot.hands[0], robot.standing()
    met = false = 0
    for k in range(TARGETS):
        target = robot.frame_placement(_random_assembly(robot, home, rng), hand).translation
        res = solve(robot, FrameTask(hand, target, task="position"), q0=home, seed=k, max_restarts=20)
        met += int(res.success)
        wrong = bool(np.linalg.norm(robot.frame_placement(res.q, hand).translation - target) > 1e-6
                 or loops_of(robot, data, res.q) > LOOP_TOL or not robot.within_limits(res.q))
        false += int(res.success and wrong)
    return [Check(robot.name, "loops: reachable targets met (step)", met / TARGETS, MET_BAR, SHARE,
                  f"{hand} at random assemblies", at_least=True, samples=TARGETS),
            Check(robot.name, "loops: false successes (step)", float(false), 0.0, "count")]


CLOSED_CHECKS = [closure_model_check, assembly_check, held_loops_check, solve_check]
