"""Tracking: follow a Cartesian path in small steps, each FRDM solve warm-started from the last answer.

This is FRDM's direct-control use (Danilov 2019): no restarts, so every jump or stall is visible. With
no bypass named, the whole path runs in the compiled follower (:mod:`kinelab.core._follow`),
which on an arm with more joints than the task constrains prefers, among the answers, the one nearest
the previous sample (a rest term, then plain FRDM to the tolerance). With a bypass, a policy or a
restriction named, the monitored loop below runs instead. Two monitors watch each of its samples:
FRDM's own (Σ|Δq| = 0 short of the target, see
:mod:`kinelab.ik.frdm.solver`), and a jump monitor (a joint moving more than ``jump_limit`` between
consecutive samples: the links spinning through a singularity). When a monitor fires and the policy
has a restriction (``intervals`` or ``freeze``), the sample is solved again with it switched on, and it
stays on for ``hold`` samples before it is released. A restriction named in ``restrict`` is on for the
whole path instead: the paper's constraints set as parameters for a path that stays near a singular
point (the ERA wrist and shoulder passages), where no monitor fires before the damage is done.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.core._chain import rotation_steps, running_events
from kinelab.errors import OptionError
from kinelab.ik import options as opt
from kinelab.ik.frdm import solver
from kinelab.ik.frdm.follower import Run, effective_rest_weight, follow, path_pace, steps_from
from kinelab.ik.frdm.options import FRDMOptions
from kinelab.ik.frdm.rejoin import jumped, rejoined
from kinelab.ik.limits import wrap_q
from kinelab.ik.registry import SolverOptions
from kinelab.ik.request import Request
from kinelab.ik.result import Attempt, BypassRecord, SingularEvent, Status, TrackResult
from kinelab.ik.targets import TargetArrays
from kinelab.ik.tasks import Task
from kinelab.robot import Chain

RESTRICTIONS = ("intervals", "freeze")
# FRDM's defaults on a path: a longer sweep cap and stall window than a single solve's, since a warm start
# that is slow at first (a singular passage) must not be abandoned: there is no restart on a path
PATH_DEFAULTS = {"max_sweeps": 2000, "stall_window": 100, "stall_rel": 1e-6}


@dataclass(frozen=True)
class PathSettings:
    """How :func:`kinelab.track` follows a path, beside the solver's options.

    Attributes:
        jump_limit: largest joint step [rad or m] between samples before the jump monitor fires (None: off).
        restrict: restrictions ("intervals", "freeze") held on every sample of the path.
        hold: samples a restriction stays on after the monitor switched it on (an integer ≥ 1).
        rest_weight: compiled follower only: weight of the rest term (None: 0.01 beyond six joints, else 0).
    """

    jump_limit: float | None = 0.2
    restrict: tuple[str, ...] = ()
    hold: int = 10
    rest_weight: float | None = None

    def __post_init__(self) -> None:
        opt.positive("jump_limit", self.jump_limit, allow_none=True)
        opt.positive("hold", self.hold, integer=True)
        opt.positive("rest_weight", self.rest_weight, allow_none=True, zero=True)
        restrict = self.restrict
        if isinstance(restrict, str) or not isinstance(restrict, (tuple, list)) \
                or any(s not in RESTRICTIONS for s in restrict):
            raise OptionError("restrict", restrict, "a tuple of 'intervals' and 'freeze'")
        object.__setattr__(self, "restrict", tuple(restrict))


def path_options(options: SolverOptions, solver_options: dict[str, Any]) -> dict[str, Any]:
    """The FRDM option keywords of a path: :data:`PATH_DEFAULTS` under the caller's (none when an options
    object is given: it is taken as it is)."""
    return solver_options if options is not None else {**PATH_DEFAULTS, **solver_options}


def run_track(robot: Chain, targets: TargetArrays, q0: np.ndarray, req: Request, settings: PathSettings,
              t_start: float | None = None) -> TrackResult:
    """Solve each target in turn, warm-started from the previous answer, each sample judged by Pinocchio.

    Args:
        robot: the robot.
        targets: oMtarget per sample (base frame), checked.
        q0: the checked configuration at the start of the path [rad or m].
        req: the validated request (solver "frdm"; its options hold the bypass tables and the policy).
        settings: the path's own settings.
        t_start: the ``time.perf_counter()`` value ``req.time_budget`` counts from (None: now).

    Returns:
        One row of q per sample, Pinocchio's errors on the task's components, statuses, the monitor log.

    Raises:
        OptionError: a restriction named without its table.
    """
    opts: FRDMOptions = req.options
    _check_restrict(settings.restrict, opts.intervals, opts.freeze)
    points, rotations = targets
    if _followable(opts) and not settings.restrict:
        followed = _compiled(robot, targets, q0, req, settings, t_start)
        followed.events += jump_events(followed.q, q0, settings.jump_limit)
    else:
        policy = opts.policy or ()
        attempt_opts = replace(opts, policy=tuple(s for s in policy if s not in RESTRICTIONS))
        path = _Path(robot, req, attempt_opts, settings, [s for s in policy if s in RESTRICTIONS])
        q_prev = q0
        for k in range(points.shape[0]):
            q_prev = path.sample(k, pin.SE3(rotations[k], points[k]), q_prev)
        followed = path.result()
    mark_jumps(followed, q0, settings.jump_limit)
    followed.add_events_later(self_motion_check(robot, followed.q, q0, points, rotations, req.task))
    return followed


# a paced path whose largest joint step is above FAST × its pace is followed again without the pace, and the smoother
# of the two kept: near a singular configuration the paced push can hold the arm where the task's own step is large
FAST = 6.0


def _compiled(robot: Chain, targets: TargetArrays, q0: np.ndarray, req: Request, settings: PathSettings,
              t_start: float | None) -> TrackResult:
    """The compiled follower's path. On a redundant arm the path's pace is measured first (a pilot pass,
    :func:`~kinelab.ik.frdm.follower.path_pace`) and given to the push; each jump is undone where
    :mod:`kinelab.ik.frdm.rejoin` can; a path that then turns a joint faster than :data:`FAST` × its pace is
    followed again without the pace, and the one with the smaller largest step kept (if it meets as many samples)."""
    opts: FRDMOptions = req.options

    def at(pace: float) -> Run:
        def run(path: TargetArrays, start: np.ndarray, toward: np.ndarray | None) -> TrackResult:
            return follow(robot, path, start, req.tol_pos, req.tol_rot, opts.sweep_cap, settings.rest_weight, opts,
                          req.task, req.seed, req.time_budget, t_start, toward, pace)
        return run

    if effective_rest_weight(robot, settings.rest_weight) <= 0.0:
        return at(0.0)(targets, q0, None)
    pace = path_pace(targets, q0, at(0.0))
    paced = rejoined(targets, q0, at(pace)(targets, q0, None), settings.jump_limit, at(pace))
    largest = _largest_step(paced, q0)
    if not pace > 0.0 or largest <= FAST * pace:
        return paced
    plain = rejoined(targets, q0, at(0.0)(targets, q0, None), settings.jump_limit, at(0.0))
    met = Status.CONVERGED.code
    if np.sum(plain.status_code == met) >= np.sum(paced.status_code == met) and _largest_step(plain, q0) < largest:
        return plain
    return paced


def _largest_step(path: TrackResult, q0: np.ndarray) -> float:
    """The largest joint step [rad or m] between two samples of the path (q0 before the first), NaN rows skipped."""
    steps = steps_from(q0, path.q)
    return float(np.nanmax(steps)) if np.isfinite(steps).any() else 0.0


def mark_jumps(path: TrackResult, q0: np.ndarray, jump_limit: float | None) -> None:
    """Mark ``jump`` every sample the path reached by a joint step [rad or m] larger than ``jump_limit`` from the last
    sample before it that met its pose (q0 before the first): its pose is met, but not by following the path (None:
    no limit). A missed sample is skipped (a controller holds where it was); after a jump the path goes on from
    where it jumped to."""
    if jump_limit is None or path.q.shape[0] == 0:
        return
    path.status_code[jumped(path, np.asarray(q0, dtype=float), jump_limit)] = Status.JUMP.code


SELF_MOTION = 5.0  # a self-motion event: the joints' drift along the task's null space beyond 5 × the path's step


def self_motion_events(robot: Chain, Q: np.ndarray, q0: np.ndarray, points: np.ndarray, rotations: np.ndarray,
                       task: Task) -> list[SingularEvent]:
    """A ``self_motion`` event wherever the answers have drifted along the task's null space (the motion the task
    does not ask for: Δq less its least-norm part J⁺JΔq, summed since the last event) by more than SELF_MOTION times
    the path's own largest step (the least-norm joint step J⁺Δx that each target's motion asks for) [rad or m]. Only
    on a chain with more joints than its task constrains; samples left unsolved (NaN) are skipped."""
    return self_motion_check(robot, Q, q0, points, rotations, task)()


def self_motion_check(robot: Chain, Q: np.ndarray, q0: np.ndarray, points: np.ndarray, rotations: np.ndarray,
                      task: Task) -> Callable[[], list[SingularEvent]]:
    """:func:`self_motion_events` as a maker: the path's steps taken now (copies of Q and the targets' motion), the
    null-space drift and its events when called (a tracked path's events are made when first read)."""
    if robot.n <= task.dimension or Q.shape[0] < 2:
        return list
    prev = np.vstack([q0, Q[:-1]])
    dx = np.zeros((Q.shape[0], 6))
    dx[:, :3] = np.diff(np.vstack([points[:1], points]), axis=0)
    rotation_steps(np.ascontiguousarray(rotations, dtype=float), dx[:, 3:])
    Q, rows = Q.copy(), task.rows

    def events() -> list[SingularEvent]:
        arrays = robot._judge_arrays()
        drift, own = (null_drift(robot, prev, Q, dx, rows) if arrays is None
                      else arrays.null_drift(prev, Q, dx, tuple(rows)))
        return _drift_events(drift, max(float(own.max()), 1e-12))
    return events


def null_drift(robot: Chain, prev: np.ndarray, Q: np.ndarray, dx: np.ndarray, rows: list[int]
               ) -> tuple[np.ndarray, np.ndarray]:
    """The joint motion along the task's null space, sample by sample, with Pinocchio's Jacobians (a chain the
    compiled FK does not judge): with J the task's rows of the tool Jacobian at prev[k] (base axes at the tool origin)
    and J⁺v = Jᵀ(JJᵀ + 1e-12 I)⁻¹v, the drift dq − J⁺J dq (dq = Q[k] − prev[k], NaN taken as 0) and the least-norm
    step max|J⁺dx[k]| [rad or m]; both 0 where prev is not finite.

    Returns:
        (drift (K, n), own (K,)).
    """
    finite = np.isfinite(prev).all(axis=1)
    J = np.zeros((Q.shape[0], 6, robot.n))
    J[finite] = robot.jacobian_batch(prev[finite], frame="local_world_aligned")
    J = J[:, rows]
    dq = np.nan_to_num(Q - prev)
    JJt = J @ J.transpose(0, 2, 1) + 1e-12 * np.eye(len(rows))
    least = np.linalg.solve(JJt, np.stack([dx[:, rows], np.einsum("kij,kj->ki", J, dq)], axis=2))
    own = np.abs(np.einsum("kji,kj->ki", J, least[..., 0])).max(axis=1)
    drift = dq - np.einsum("kji,kj->ki", J, least[..., 1])
    drift[~finite] = 0.0
    return drift, np.nan_to_num(own)


def _drift_events(drift: np.ndarray, largest: float) -> list[SingularEvent]:
    """The self-motion events of per-sample drifts (K, n) [rad or m]: where the drift summed since the last event
    exceeds SELF_MOTION × ``largest`` (a running total, reset at each event, in one compiled pass)."""
    sample, moved = np.empty(drift.shape[0], dtype=np.int64), np.empty(drift.shape[0])
    count = running_events(np.ascontiguousarray(drift, dtype=float), SELF_MOTION * largest, sample, moved)
    return [SingularEvent("self_motion", f"the joints moved {m:.3g} along the task's null space (the path's largest "
                          f"step: {largest:.3g})", sample=int(k), max_joint_step=float(m))
            for k, m in zip(sample[:count], moved[:count], strict=True)]


def jump_events(Q: np.ndarray, q0: np.ndarray, jump_limit: float | None) -> list[SingularEvent]:
    """A "jump" event for every sample whose largest joint step from the sample before (q0 before the first) exceeds
    ``jump_limit`` [rad or m] (None: none); samples left unsolved (NaN) are skipped."""
    if jump_limit is None or Q.shape[0] == 0:
        return []
    steps = steps_from(q0, Q)
    return [SingularEvent("jump", sample=int(k), max_joint_step=float(steps[k]))
            for k in np.flatnonzero(np.nan_to_num(steps, nan=0.0) > jump_limit)]


def _followable(opts: FRDMOptions) -> bool:
    """The compiled follower serves the path: no bypass table, policy or trace named (the polish it has)."""
    return (opts.kicks is None and opts.intervals is None and opts.freeze is None and opts.policy is None
            and opts.active is None and not opts.trace)


def _check_restrict(restrict: tuple[str, ...], intervals: Any, freeze: Any) -> None:
    for name, table in (("intervals", intervals), ("freeze", freeze)):
        if name in restrict and not table:
            raise OptionError("restrict", restrict, f"a restriction with its table: restrict names {name!r} but "
                              f"no {name} table was given ({name}={{joint: ...}})")


class _Path:
    """The samples solved so far, the restrictions held and the monitor log of one tracked path."""

    def __init__(self, robot: Chain, req: Request, opts: FRDMOptions, settings: PathSettings,
                 restrictions: list[str]):
        self.robot, self.req, self.opts, self.settings = robot, req, opts, settings
        self.restrictions = restrictions
        self._by_active: dict[tuple[str, ...], FRDMOptions] = {}
        self.held: dict[str, int] = {}
        self.rows: list[np.ndarray] = []
        self.figures: list[tuple[float, float, int, int, float]] = []
        self.events: list[SingularEvent] = []
        self.bypasses: list[BypassRecord] = [BypassRecord(s, sample=0, hold="path") for s in settings.restrict]
        budget = req.time_budget
        self.deadline = np.inf if budget is None else time.perf_counter() + budget

    def _solve(self, target: pin.SE3, q_start: np.ndarray, active: tuple[str, ...]) -> Attempt:
        opts = self._by_active.get(active)
        if opts is None:  # built (and checked) once per set of active restrictions, not once per sample
            opts = self._by_active[active] = replace(self.opts, active=active)
        return solver.attempt(self.robot, target, q_start, self.req.tol_pos, self.req.tol_rot, self.deadline, opts)

    def sample(self, k: int, target: pin.SE3, q_prev: np.ndarray) -> np.ndarray:
        """Solve sample k warm-started from q_prev, switching a restriction on if a monitor fires."""
        t0 = time.perf_counter()
        active = self._active()
        att = self._solve(target, q_prev, active)
        jumped = self._jumped(k, att, q_prev)
        self.events += [ev.at_sample(k) for ev in att.events]
        if jumped or (att.events and att.status != Status.CONVERGED):
            att = self._restricted(k, target, q_prev, active) or att
        self.bypasses += [b.at_sample(k) for b in att.bypasses if b.bypass not in RESTRICTIONS]
        self.held = {s: left - 1 for s, left in self.held.items() if left > 1}
        dp, dr, status = self._judged(att, target)
        self.rows.append(att.q)
        self.figures.append((dp, dr, status.code, att.iterations, time.perf_counter() - t0))
        return att.q

    def _active(self) -> tuple[str, ...]:
        """The restrictions on for the next sample: those asked for, then those a monitor switched on and still held."""
        restrict = self.settings.restrict
        return (*restrict, *(s for s, left in self.held.items() if left > 0 and s not in restrict))

    def _restricted(self, k: int, target: pin.SE3, q_prev: np.ndarray, active: tuple[str, ...]) -> Attempt | None:
        """Sample k solved again with the next restriction not yet active switched on (held for ``hold`` samples,
        logged), or None when every one is active."""
        pending = [s for s in self.restrictions if s not in active]
        if not pending:
            return None
        self.held[pending[0]] = self.settings.hold
        self.bypasses.append(BypassRecord(pending[0], sample=k, hold=self.settings.hold))
        return self._solve(target, q_prev, (*active, pending[0]))

    def _jumped(self, k: int, att: Attempt, q_prev: np.ndarray) -> bool:
        """Sample k's answer moved a joint more than the jump limit from q_prev (the event logged when it did)."""
        step = float(np.max(np.abs(att.q - q_prev)))
        limit = self.settings.jump_limit
        if limit is None or step <= limit:
            return False
        self.events.append(SingularEvent("jump", sample=k, max_joint_step=step))
        return True

    def _judged(self, att: Attempt, target: pin.SE3) -> tuple[float, float, Status]:
        """Pinocchio's verdict on the sample: the task's components within tolerance and q within the limits
        (the solver's own status is kept only to say why a sample failed)."""
        robot, req = self.robot, self.req
        att.q = np.ascontiguousarray(wrap_q(robot, att.q), dtype=float)  # whole turns into the limits: the same pose
        dp, dr = req.task.errors(target, robot.tool_pose_of_float_q(att.q))
        met = req.task.met(dp, dr, req.tol_pos, req.tol_rot)
        within = bool(np.all(np.isfinite(att.q))) and robot.within_limits(att.q)
        if met and within:
            return dp, dr, Status.CONVERGED
        if met:
            return dp, dr, Status.OUTSIDE_LIMITS
        return dp, dr, Status.STALLED if att.status == Status.CONVERGED else att.status

    def result(self) -> TrackResult:
        """The path's TrackResult."""
        dp, dr, status, sweeps, times = zip(*self.figures, strict=True) if self.figures else ([],) * 5
        return TrackResult(np.array(self.rows), np.array(dp), np.array(dr), np.array(status, dtype=np.int8),
                           np.array(sweeps, dtype=np.int64),
                           np.array(times), self.events, self.bypasses)
