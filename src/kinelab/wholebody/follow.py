"""Following a path on a chain by the whole-body step (``kinelab.track(..., follower="step")``).

A redundant arm's answers to a path are a family: each sample's pose is met along a self-motion, and a follower
that only meets the pose lets the arm slide along it. Here each sample is one QP step at two priorities, then
corrections:

1. the task (the tool's pose, position, axis or orientation) at priority 1, exactly;
2. in the task's null space, at priority 2, a posture: keep the joints moving as the sample before moved them (the
   least change of the motion, what a smooth path does), turned away from a limit as it nears one (the Newton step
   of the barrier 1/(q − lower)² + 1/(upper − q)², weighted by its curvature: at 0.3 rad from a limit the barrier
   and the motion weigh the same);

within the position limits and a box about the previous sample: the posture's step moves no joint more than the
task's own least step (the first level alone, solved first) plus ``FLOOR``, the corrections after it keep every
joint within twice that step plus ``FLOOR`` of the sample before, and never beyond ``jump_limit``. A sample that
cannot be met within that box is left unmet (an honest miss, the path goes on), never met by a jump. Corrections
(the task alone, at most ``CORRECTIONS`` steps) meet each sample to its tolerance; the chain's judge judges every
sample. With ``collisions=``, every step keeps each pair apart by the margin (:mod:`kinelab.wholebody.clearance`):
a sample the obstacles keep the tool from is left unmet where they stop it, and a row nearer than the margin is no
success (status ``collision``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.collision.model import Collisions, as_collisions
from kinelab.errors import OptionError
from kinelab.ik import api as chain_api
from kinelab.ik import options as opt
from kinelab.ik.frdm.follower import judged_path
from kinelab.ik.request import Request, make_request
from kinelab.ik.result import Status, TrackResult
from kinelab.ik.targets import as_target_arrays
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot
from kinelab.typing import CollisionSpec, Configuration, Targets
from kinelab.wholebody.clearance import step_collisions
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.problem import step
from kinelab.wholebody.step import StepOptions
from kinelab.wholebody.subject import as_robot
from kinelab.wholebody.tasks import FrameTask, PostureTask

FLOOR = 1e-4  # [rad or m] room beyond the task's least step: the corrections of a path at rest
CORRECTIONS = 10  # steps with the task alone after the posture's, until the sample is met
NEAR = 1.0 / 600.0  # the barrier's curvature times this weighs against the motion's own 1 (equal at 0.3 rad)
OPTIONS = StepOptions(damping=1e-9)
MODE = "whole-body step (posture, limits)"


@dataclass
class Follower:
    """One path's follower: the chain's whole-body view, the tasks it moves per sample, its last motion."""

    chain: Chain
    robot: Robot
    frame: FrameTask
    posture: PostureTask
    req: Request
    jump_limit: float
    collisions: Collisions | None = None

    def limits(self, velocity: Any) -> Limits:
        """The step's limits: positions, ``velocity`` (None: none), the path's collisions."""
        return Limits(velocity=velocity, collisions=self.collisions)

    def sample(self, oMtarget: pin.SE3, q_prev: np.ndarray, v_prev: np.ndarray) -> tuple[np.ndarray, int]:
        """One sample: the task's least step, the step with the posture in a box about q_prev, the corrections.

        Returns:
            (q, the steps taken).
        """
        frame = self.frame.moved(oMtarget)
        alone = step(self.robot, q_prev, frame, 1.0, limits=self.limits(None), options=OPTIONS)
        need = float(np.abs(alone.v).max())
        cap = min(2.0 * need + FLOOR, self.jump_limit)  # the box about q_prev, corrections included
        posture = self.posture.moved(*preferred(self.robot, q_prev, v_prev))
        moved = step(self.robot, q_prev, [frame, posture], 1.0, limits=self.limits(min(need + FLOOR, cap)),
                     options=OPTIONS)
        q = moved.q if moved.solved else q_prev
        for used in range(CORRECTIONS):
            room = cap - np.abs(pin.difference(self.robot.model, q_prev, q))  # what is left of the box
            fixed = step(self.robot, q, frame, 1.0, limits=self.limits(np.maximum(room, 1e-12)), options=OPTIONS)
            if _met(fixed.errors[0], self.req, frame.task) or not fixed.solved:
                return q, used + 2
            q = fixed.q
        return q, CORRECTIONS + 2


def follow_by_step(chain: Chain, points: np.ndarray, rotations: np.ndarray, q0: np.ndarray, req: Request,
                   jump_limit: float | None, t_start: float, collisions: Collisions | None = None) -> TrackResult:
    """Every sample of a path by the step (see the module's docstring).

    Args:
        chain: the chain.
        points: (K, 3) target positions [m], base frame.
        rotations: (K, 3, 3) target rotations, base frame.
        q0: the checked start [rad or m], within the limits.
        req: the checked request (task, tolerances, time budget).
        jump_limit: the largest joint change between two samples [rad or m] (None: the task's least step alone
            bounds it).
        t_start: the ``time.perf_counter()`` value the budget counts from.
        collisions: what every step keeps apart (None: nothing).

    Returns:
        The :class:`TrackResult`, mode "whole-body step (posture, limits)", every sample judged.
    """
    robot = as_robot(chain)
    count = points.shape[0]
    Q = np.full((count, chain.n), np.nan)
    iterations = np.zeros(count, dtype=np.int64)
    deadline = np.inf if req.time_budget is None else t_start + float(req.time_budget)
    q = chain.to_pin_q(q0)
    axis = "xyz"[req.task.axis] if req.task.axis >= 0 else "z"
    follower = Follower(chain, robot, FrameTask(chain.tool, pin.SE3(rotations[0], points[0]), task=req.task.name,
                                                axis=axis),
                        PostureTask(q, weight=np.ones(robot.nv), priority=2), req,
                        np.inf if jump_limit is None else float(jump_limit), collisions)
    v = np.zeros(robot.nv)
    t0 = time.perf_counter()
    for k in range(count):
        if time.perf_counter() > deadline:
            break
        q_next, iterations[k] = follower.sample(pin.SE3(rotations[k], points[k]), q, v)
        v = np.asarray(pin.difference(robot.model, q, q_next), dtype=float)
        q = q_next
        Q[k] = chain.from_pin_q(q)
    per_sample = (time.perf_counter() - t0) / max(count, 1)
    return _judged(chain, Q, points, rotations, req, iterations, per_sample, collisions)


def _judged(chain: Chain, Q: np.ndarray, points: np.ndarray, rotations: np.ndarray, req: Request,
            iterations: np.ndarray, per_sample: float, collisions: Collisions | None) -> TrackResult:
    """The path's result, every started sample judged (the others: status ``time_budget``; a met sample nearer
    than the margin: ``collision``)."""
    dp, dr, ok = judged_path(chain, Q, points, rotations, req.task, req.tol_pos, req.tol_rot)
    started = np.isfinite(Q).all(axis=1)
    codes = np.where(ok, Status.CONVERGED.code, np.where(started, Status.MAX_ITERATIONS.code,
                                                          Status.TIME_BUDGET.code)).astype(np.int8)
    if collisions is not None:
        found = step_collisions(as_robot(chain), collisions)
        for k in np.flatnonzero(ok):
            if found.closest(chain.to_pin_q(Q[k]))[1] < 0.0:
                codes[k] = Status.COLLISION.code
    return TrackResult(Q, dp, dr, codes, iterations, np.full(Q.shape[0], per_sample), mode=MODE)


def _met(error: Any, req: Request, task: str) -> bool:
    """The step's own measure of the sample's error within half the tolerance (the judge decides in the end)."""
    position = error.position <= req.tol_pos * 0.5 or task == "orientation"
    rotation = error.rotation <= req.tol_rot * 0.5 or task == "position"
    return bool(position and rotation)


def preferred(robot: Robot, q: np.ndarray, v_prev: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The priority-2 posture at q (see the module's docstring).

    Args:
        robot: the whole robot (a chain's view).
        q: the configuration (Pinocchio's q).
        v_prev: the joints' motion of the sample before [rad or m] (nv).

    Returns:
        (reference q, weight per velocity, the largest 1).
    """
    space = robot.space
    b, bv = space.bounded_q, space.bounded_v
    low = np.maximum(q[b] - space.lower[b], 1e-6)
    high = np.maximum(space.upper[b] - q[b], 1e-6)
    full = 6.0 / low**4 + 6.0 / high**4
    newton = (2.0 / low**3 - 2.0 / high**3) / full
    curve = NEAR * full
    weight = np.ones(robot.nv)
    weight[bv] += curve
    d = np.array(v_prev, dtype=float)
    d[bv] = (d[bv] + curve * newton) / (1.0 + curve)
    return np.asarray(pin.integrate(robot.model, q, d), dtype=float), weight / weight.max()


def track(chain: Chain, targets: Targets, *, q0: Configuration | None = None, seed: int | None = None,
          tol_pos: float = 1e-6,
          tol_rot: float = 1e-6, time_budget: float | None = None, task: str = "pose", axis: str = "z",
          jump_limit: float | None = 0.2, collisions: CollisionSpec = None) -> TrackResult:
    """Follow a path by the step (see the module's docstring): ``kinelab.track(chain, targets, follower="step")``.

    Args:
        chain: the chain.
        targets: oMtarget per sample (a sequence of ``pin.SE3`` or an (N, 4, 4) array, base frame).
        q0: the start [rad or m], within the limits; None: the first target's answer (:func:`kinelab.solve`,
            with ``seed``).
        seed: seed of that first solve (None: fresh entropy).
        tol_pos: position tolerance per sample [m].
        tol_rot: rotation tolerance per sample [rad].
        time_budget: wall-clock budget [s] of the whole path (None: none); samples not started are NaN rows with
            status ``time_budget``.
        task: the components met per sample: "pose", "position", "axis" or "orientation".
        axis: the tool axis of task "axis".
        jump_limit: no joint moves more than this between two rows [rad or m] (None: the task's least step alone
            bounds the motion). The rows are one continuous motion, missed samples included (a missed sample's row
            is where the arm went, within the box): no row is ever reached by a jump.
        collisions: None, "self", an ``Environment`` or a ``Collisions``: every step keeps each pair apart by the
            margin (the start must be clear).

    Returns:
        One row of q per sample, the judge's errors, statuses (:class:`TrackResult`).

    Raises:
        OptionError, ConfigurationError, JointLimitError, TargetError: a bad setting, q0 or target, named.
    """
    t_start = time.perf_counter()
    opt.positive("jump_limit", jump_limit, allow_none=True)
    req = make_request("frdm", seed, tol_pos, tol_rot, time_budget, 0, "refuse", None, task, axis)
    points, rotations = as_target_arrays(targets)
    if q0 is None:
        first = chain_api.solve(chain, pin.SE3(rotations[0], points[0]), seed=seed, tol_pos=tol_pos,
                                tol_rot=tol_rot, task=task, axis=axis)
        if not first.success:
            raise OptionError("q0", None, "a start configuration: the path's first target could not be solved "
                                  f"({first.status.value}: {first.message})")
        q0 = first.q
    start = chain.check_q(q0, limits=True, what="q0")
    return follow_by_step(chain, points, rotations, start, req, jump_limit, t_start, as_collisions(collisions))
