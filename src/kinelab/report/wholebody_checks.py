"""``kinelab validate``'s whole-body checks, on a whole robot (``kinelab validate --robots talos baxter``).

Each check is against Pinocchio: the compiled tree's placements, Jacobians and centre of mass; every task's
Jacobian against finite differences of Pinocchio's FK and centre of mass; the limits over a run of steps that
starts outside them; the converged solve on reachable targets, every success judged again here.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.report.check import SHARE, Check, samples_for
from kinelab.report.collision_step_checks import collision_step_check
from kinelab.robot.tree import Robot
from kinelab.wholebody import compiled
from kinelab.wholebody import evaluate as ev
from kinelab.wholebody.solve import solve
from kinelab.wholebody.tasks import ComTask, FrameTask

FD = 1e-6  # [rad or m] the central difference's step
MET_BAR = 0.9  # reachable target sets met, by the share's 95 % lower bound
TARGETS = samples_for(MET_BAR, 4)  # reachable target sets per solver: enough for the bar with four misses
STEPS, RESTART = 2000, 200  # steps of the limits' run, a new start (every other one outside the limits) this often


def compiled_tree_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """The compiled tree's joint placements, body-frame Jacobians and centre of mass against Pinocchio's."""
    tree = robot.derived("compiled tree", compiled.pack_tree)
    if tree is None:
        return [Check(robot.name, "whole body: compiled tree (not built: the readable step serves)", 1.0, 1.0,
                      "yes/no")]
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(seed)
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    worst = 0.0
    for _ in range(min(n, 50)):
        q = robot.random_q(rng)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for fid in bodies:
            f = model.frames[fid]
            pose, J = tree.frame_jacobian(q, f.parentJoint, compiled._pose(f.placement))
            ref = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            worst = max(worst, np.abs(pose - compiled._pose(data.oMf[fid])).max(), np.abs(J - ref).max())
        c, Jc = tree.center_of_mass(q)
        worst = max(worst, np.abs(c - pin.centerOfMass(model, data, q)).max(),
                    np.abs(Jc - pin.jacobianCenterOfMass(model, data, q)).max())
    return [Check(robot.name, "whole body: compiled frames and centre of mass vs Pinocchio", worst, 1e-10, "m, rad",
                  f"{len(bodies)} body frames at {min(n, 50)} configurations")]


def task_jacobian_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """Every task's Jacobian (frames of the hands and feet, the centre of mass) against central differences of
    its error through Pinocchio's FK, along random directions."""
    rng = np.random.default_rng(seed + 1)
    frames = (robot.hands + robot.feet) or (robot.model.frames[-1].name,)
    worst = 0.0
    for _ in range(min(n, 20)):
        q, target_q = robot.random_q(rng), robot.random_q(rng)
        tasks: list[Any] = [FrameTask(f, T) for f, T in zip(frames, robot.frame_placements(target_q, frames),
                                                              strict=True)]
        tasks.append(ComTask(robot.com(target_q)))
        dv = rng.normal(size=robot.nv)
        for task in tasks:
            A = _rows_at(robot, task, q)[0]
            plus = _rows_at(robot, task, np.asarray(pin.integrate(robot.model, q, FD * dv)))[1]
            minus = _rows_at(robot, task, np.asarray(pin.integrate(robot.model, q, -FD * dv)))[1]
            fd = (plus - minus) / (2 * FD)
            worst = max(worst, float(np.abs(A @ dv - fd).max() / max(1.0, np.abs(fd).max())))
    return [Check(robot.name, "whole body: task Jacobians vs differences of Pinocchio's FK", worst, 1e-6,
                  "relative", f"{len(frames)} frames and the centre of mass at {min(n, 20)} configurations")]


def _rows_at(robot: Robot, task: Any, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A, e) of a task at q, from Pinocchio's pass."""
    ev.forward(robot, q, com=True)
    A, e, _, _ = ev.task_rows(robot, task)
    return np.array(A), np.array(e)


def limits_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """STEPS steps of 5 ms toward random targets from starts every RESTART steps, every other one outside the
    limits: no joint inside its limits leaves them, no velocity beyond its limit (1e-9 relative)."""
    from kinelab.wholebody import ComTask, FrameTask, Limits, PostureTask, step

    rng = np.random.default_rng(seed + 2)
    frames = (robot.hands + robot.feet) or (robot.model.frames[-1].name,)
    b, vmax = robot.space.bounded_q, robot.velocity_limit
    finite = np.isfinite(vmax)
    violations, outside_starts, q = 0, 0, robot.neutral()
    tasks: list[Any] = []
    for k in range(STEPS):
        if k % RESTART == 0:
            q, target_q = robot.random_q(rng), robot.random_q(rng)
            if (k // RESTART) % 2:
                q[b] += rng.choice([-1.0, 1.0], b.sum()) * rng.uniform(0, 0.3, b.sum()) * (rng.random(b.sum()) < 0.3)
                outside_starts += 1
            tasks = [FrameTask(f, T) for f, T in zip(frames, robot.frame_placements(target_q, frames), strict=True)]
            tasks += ([ComTask(robot.com(target_q))] if robot.floating else []) + [PostureTask(target_q)]
        result = step(robot, q, tasks, 0.005, limits=Limits())
        inside = (q[b] >= robot.lower[b]) & (q[b] <= robot.upper[b])
        left = inside & ((result.q[b] < robot.lower[b] - 1e-9) | (result.q[b] > robot.upper[b] + 1e-9))
        violations += int(left.sum()) + int((np.abs(result.v[finite]) > vmax[finite] * (1 + 1e-9)).sum())
        q = result.q
    return [Check(robot.name, "whole body: limit violations over the steps", float(violations), 0.0, "count",
                  f"{STEPS} steps, {outside_starts} starts outside the limits")]


def solve_checks(robot: Robot, n: int, seed: int) -> list[Check]:
    """Both solvers on TARGETS reachable target sets (the hands, the feet and the centre of mass of one random q):
    the share met, and every success met again by Pinocchio here (no false success)."""
    from kinelab.wholebody import ComTask, FrameTask, PostureTask

    rng = np.random.default_rng(seed + 3)
    frames = (robot.hands + robot.feet) or (robot.model.frames[-1].name,)
    out = []
    sets = []
    for _ in range(TARGETS):
        q_true = robot.random_q(rng)
        tasks: list[Any] = [FrameTask(f, T) for f, T in zip(frames, robot.frame_placements(q_true, frames),
                                                              strict=True)]
        com = robot.com(q_true) if robot.floating else None
        tasks += ([ComTask(com)] if com is not None else []) + [PostureTask()]
        start = robot.neutral()
        start[:7] = q_true[:7] if robot.floating else start[:7]
        sets.append((tasks, start, dict(zip(frames, robot.frame_placements(q_true, frames), strict=True)), com))
    for solver in ("step", "frdm"):
        met = false = 0
        for k, (tasks, start, placed, com) in enumerate(sets):
            res = solve(robot, tasks, q0=start, solver=solver, seed=k, time_budget=5.0)
            met += res.success
            false += res.success and not _met_by_pinocchio(robot, placed, com, res.q)
        out += [Check(robot.name, f"whole body: reachable targets met ({solver})", met / TARGETS, MET_BAR, SHARE,
                      "hands, feet and centre of mass of a random q", at_least=True, samples=TARGETS),
                Check(robot.name, f"whole body: false successes ({solver})", float(false), 0.0, "count")]
    return out


def _met_by_pinocchio(robot: Robot, placed: dict[str, pin.SE3], com: np.ndarray | None, q: np.ndarray) -> bool:
    """Every frame at its placement (``oMframe`` by name) and the centre of mass at ``com`` [m] (None: not asked)
    within 1e-6 m / 1e-6 rad by Pinocchio's own calls, within the limits: the targets as the check drew them, not
    as the tasks hold them."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    for frame, oMtarget in placed.items():
        M = data.oMf[model.getFrameId(frame)]
        if np.linalg.norm(M.translation - oMtarget.translation) > 1e-6 or \
                np.linalg.norm(pin.log3(M.rotation.T @ oMtarget.rotation)) > 1e-6:
            return False
    if com is not None and np.linalg.norm(pin.centerOfMass(model, data, q) - com) > 1e-6:
        return False
    return bool(robot.within_limits(q))


WHOLE_CHECKS = [compiled_tree_check, task_jacobian_check, limits_check, solve_checks, collision_step_check]
