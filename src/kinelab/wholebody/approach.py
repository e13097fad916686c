"""The converged solve's first move on a free-flyer robot: the base and the limbs brought to the tasks before the
Gauss–Newton iterations start, so that a robot standing far from its targets does not have to crawl there through
its joint limits.

From the start it is given: (1) the base takes the rigid motion that best fits every task point (FRDM's weighted
Procrustes on the free-flyer, :mod:`kinelab.wholebody.frdm`); (2) each limb whose end a task places outright
(:meth:`~kinelab.wholebody.tasks.Task.placement`) is solved alone, as an arm from the link it hangs from, by
FRDM from the limb's own joints (one start, no random one: the limb goes where its joints lead from where it is);
(3) the base is shifted by what the centre of mass still misses and the limbs are solved again. A limb is the run of
joints from the root to its task frame that no other placed frame's run shares (a humanoid's legs from the pelvis,
its arms from the torso); joints shared by several limbs (a torso) are left to the iterations, and so is every
task that places no frame outright (a centre of mass, a posture, a frame in another frame).

Robots with loops are left as they are, and so is a limb with a folded mimic joint (a follower or a leader): a
limb solved alone would break what they hold.
docs/wholebody.md, "The converged solve".
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot
from kinelab.wholebody.evaluate import kept_data
from kinelab.wholebody.frdm import move_base, task_points
from kinelab.wholebody.tasks import Placement, Task

LIMB_BUDGET = 1.0  # [s] at most per limb solve (one start, no restart: it ends on its iterations well before)


@dataclass(frozen=True)
class Limb:
    """A limb a task places: its chain (from the link it hangs from to the task's frame), that link's frame and the
    indices of the limb's joints in the whole robot's q."""

    chain: Chain
    base: str
    index: np.ndarray


def approached(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, deadline: float = math.inf) -> np.ndarray:
    """q with its base and limbs brought to the tasks (see the module's docstring); q itself where there is nothing to
    bring (a fixed base, a robot with loops, no task with points).

    Args:
        robot: the whole robot.
        tasks: the solve's tasks.
        q: the start (Pinocchio's q; not changed).
        deadline: the ``time.perf_counter()`` value after which no limb is solved.

    Returns:
        A new configuration within the joint limits the limbs' solves hold (the base and shared joints as moved).
    """
    if not robot.floating or robot.closures:
        return q
    q = np.array(q, dtype=float)
    data = kept_data(robot, "the first move")
    if not _fit_base(robot, tasks, q, data):
        return q
    placements = _placements(tasks)
    frames = tuple(p.frame for p in placements)
    placed = [(p, limb) for p in placements if (limb := _limb(robot, p.frame, frames)) is not None]
    _solve_limbs(robot, placed, q, deadline)
    if _shift_to_com(robot, tasks, q, data):
        _solve_limbs(robot, placed, q, deadline)
    return q


def _placements(tasks: tuple[Task, ...]) -> list[Placement]:
    return [p for t in tasks if (p := t.placement()) is not None]


def _fit_base(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, data: pin.Data) -> bool:
    """The base's best rigid motion for every task point, q changed in place; False when no task has points."""
    pin.framesForwardKinematics(robot.model, data, q)
    com = pin.centerOfMass(robot.model, data, q) if any(t.uses_com for t in tasks) else None
    points = task_points(robot, tuple(t for t in tasks if not t.preference), data, com)
    fixed = points.carrier < 0
    if not fixed.any():
        return False
    points.w = np.where(fixed, points.w, 0.0)  # a target carried by the robot moves with the base: no evidence
    if _spread(points.p[fixed & ~points.direction]):
        points.w = np.where(points.direction, 0.0, points.w)  # three points fix the turn: a frame's axes over-weigh
    move_base(robot, q, points)
    return True


def _spread(p: np.ndarray) -> bool:
    """Whether the points span a plane (at least three, not on one line [1 mm])."""
    if len(p) < 3:
        return False
    return bool(np.linalg.svd(p - p.mean(axis=0), compute_uv=False)[1] > 1e-3)


def _shift_to_com(robot: Robot, tasks: tuple[Task, ...], q: np.ndarray, data: pin.Data) -> bool:
    """The base translated by what the centre of mass's points miss (q in place); False when no task asks for it."""
    if not any(t.uses_com for t in tasks):
        return False
    pin.framesForwardKinematics(robot.model, data, q)
    com = pin.centerOfMass(robot.model, data, q)
    points = task_points(robot, tuple(t for t in tasks if t.uses_com), data, com)
    rows = (points.frame < 0) & ~points.direction
    if not rows.any():
        return False
    q[:3] += (points.t[rows] - points.p[rows]).mean(axis=0)
    return True


def _solve_limbs(robot: Robot, placed: list[tuple[Placement, Limb]], q: np.ndarray, deadline: float) -> None:
    """Each placed limb solved alone from where it is (q in place): its base link where q puts it, the task's
    placement in that link's frame, the single-chain solve's answer (met or not) written back."""
    from kinelab.ik.api import solve  # the single-chain solvers: imported when a whole-body solve first needs them

    bases = robot.frame_placements(q, [limb.base for _, limb in placed])  # no limb moves another's base link
    for (placement, limb), oMbase in zip(placed, bases, strict=True):
        left = deadline - time.perf_counter()
        if left <= 0.0:
            return
        lo, hi = limb.chain.model.lowerPositionLimit, limb.chain.model.upperPositionLimit
        start = np.clip(limb.chain.from_pin_q(q[limb.index]), lo, hi)
        try:
            found = solve(limb.chain, oMbase.actInv(placement.target), q0=start, seed=0, max_restarts=0, solver="frdm",
                          time_budget=min(LIMB_BUDGET, left), task=placement.kind, axis=placement.axis)
        except KinelabError:
            continue  # a limb its solver refuses (a target it cannot take) is left to the iterations
        if np.isfinite(found.q).all():  # a solve refused before any step answers NaN: the limb stays
            q[limb.index] = limb.chain.to_pin_q(found.q)


def _limb(robot: Robot, frame: str, frames: tuple[str, ...]) -> Limb | None:
    """The limb of ``frame`` among the placed ``frames`` (kept on the robot), or None (no joint of its own)."""
    found: Limb | None = robot.derived(f"approach limb {frame} among {sorted(frames)}",
                                       lambda r: _build_limb(r, frame, frames))
    return found


def _build_limb(robot: Robot, frame: str, frames: tuple[str, ...]) -> Limb | None:
    """The joints on the root → ``frame`` path no other placed frame's path shares, as a chain from the link they
    hang from; None when there are none, when they are not plain one-number joints, or when the chain cannot be
    built."""
    model = robot.model

    def path(name: str) -> set[int]:
        return {j for j in model.supports[model.frames[robot.frame_id(name)].parentJoint]
                if j > 0 and model.joints[j].nq == model.joints[j].nv == 1}

    own = sorted(path(frame) - set().union(*(path(f) for f in frames if f != frame)))
    coupled = {model.getJointId(n) for m in robot.mimics for n in (m.name, m.leader) if model.existJointName(n)}
    if not own or coupled & set(own) or any(model.parents[own[k]] != own[k - 1] for k in range(1, len(own))):
        return None  # a limb's joints run one after the other, none held to another by a mimic
    parent = model.parents[own[0]]
    base = next((f.name for f in model.frames if f.parentJoint == parent and f.type == pin.FrameType.BODY
                 and f.placement.isIdentity()), None)
    if base is None:
        return None
    try:
        chain = robot.chain(base, frame)
    except KinelabError:
        return None
    if [chain.model.names[j] for j in range(1, chain.model.njoints)] != [model.names[j] for j in own]:
        return None
    return Limb(chain, base, np.array([model.joints[j].idx_q for j in own]))
