"""Tracking: follow a Cartesian path in small steps, each FRDM solve warm-started from the last answer.

This is FRDM's direct-control use (Danilov 2019): no restarts, so every jump or stall is visible. With
no bypass named, the whole path runs in the compiled follower (:mod:`kinelab.ik.frdm.path_kernel`),
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
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.ik.frdm import solver
from kinelab.ik.frdm.follower import follow
from kinelab.ik.frdm.options import FRDMOptions
from kinelab.ik.result import Attempt, BypassRecord, SingularEvent, Status, TrackResult
from kinelab.robot import Robot


def track(
    robot: Robot,
    targets: list[pin.SE3],
    q0: np.ndarray,
    *,
    tol_pos: float = 1e-6,
    tol_rot: float = 1e-6,
    max_sweeps: int = 2000,
    jump_limit: float | None = 0.2,
    kicks: dict | None = None,
    intervals: dict | None = None,
    freeze: dict | None = None,
    policy: tuple[str, ...] | None = None,
    restrict: tuple[str, ...] = (),
    hold: int = 10,
    stall_window: int = 100,
    stall_rel: float = 1e-6,
    rest_weight: float | None = None,
    **frdm_options: Any,
) -> TrackResult:
    """Solve each target in turn, warm-started from the previous answer.

    Args:
        robot: the robot.
        targets: oMtarget per sample (base frame).
        q0: the configuration at the start of the path [rad or m].
        tol_pos: position tolerance per sample [m].
        tol_rot: rotation tolerance per sample [rad].
        max_sweeps: sweep cap per sample.
        jump_limit: largest joint step [rad or m] before the jump monitor fires (None: off).
        kicks: the bypass kicks (see :class:`~kinelab.ik.frdm.options.FRDMOptions`).
        intervals: the bypass intervals.
        freeze: the joints to freeze.
        policy: None (default, no bypass table): the compiled follower; ``()``: the monitored loop, no bypass.
        restrict: restrictions ("intervals", "freeze") held on every sample of the path.
        hold: samples a restriction stays on after the monitor switched it on.
        stall_window: the monitor's window [sweeps] (long: a slow start on a path escapes a singularity).
        stall_rel: the relative fall required over the window.
        rest_weight: compiled follower only: weight of the rest term (None: 0.01 beyond six joints, else 0).
        **frdm_options: other :class:`~kinelab.ik.frdm.options.FRDMOptions` fields (order, w_p, accel, ...).

    Returns:
        One row of q per sample, Pinocchio's errors, statuses, the monitor log (:class:`TrackResult`).

    Raises:
        ConfigurationError: a bad q0; KinelabError: a restriction named without its table.
    """
    q_prev = robot.check_q(q0, limits=True, what="q0")
    _check_restrict(restrict, intervals, freeze)
    if policy is None and not (kicks or intervals or freeze or restrict):
        return follow(robot, targets, q_prev, tol_pos, tol_rot, max_sweeps, rest_weight,
                      FRDMOptions(stall_window=stall_window, stall_rel=stall_rel, **frdm_options))
    options = {"max_sweeps": max_sweeps, "kicks": kicks, "intervals": intervals, "freeze": freeze,
               "policy": tuple(s for s in (policy or ()) if s not in RESTRICTIONS),
               "stall_window": stall_window, "stall_rel": stall_rel, **frdm_options}
    path = _Path(robot, tol_pos, tol_rot, options, restrict, [s for s in (policy or ()) if s in RESTRICTIONS],
                 jump_limit, hold)
    for k, target in enumerate(targets):
        q_prev = path.sample(k, target, q_prev)
    return path.result()


RESTRICTIONS = ("intervals", "freeze")


def _check_restrict(restrict: tuple[str, ...], intervals: dict | None, freeze: dict | None) -> None:
    unknown = [s for s in restrict if s not in RESTRICTIONS]
    if unknown:
        raise KinelabError(f"restrict takes 'intervals' and 'freeze', not {unknown}")
    for name, table in (("intervals", intervals), ("freeze", freeze)):
        if name in restrict and not table:
            raise KinelabError(f"restrict names {name!r} but no {name} table was given")


class _Path:
    """The samples solved so far, the restrictions held and the monitor log of one tracked path."""

    def __init__(self, robot: Robot, tol_pos: float, tol_rot: float, options: dict[str, Any],
                 restrict: tuple[str, ...], restrictions: list[str], jump_limit: float | None, hold: int):
        self.robot, self.tol_pos, self.tol_rot, self.options = robot, tol_pos, tol_rot, options
        self.restrict, self.restrictions, self.jump_limit, self.hold = restrict, restrictions, jump_limit, hold
        self.held: dict[str, int] = {}
        self.rows: list[np.ndarray] = []
        self.figures: list[tuple[float, float, str, int, float]] = []
        self.events: list[SingularEvent] = []
        self.bypasses: list[BypassRecord] = [BypassRecord(s, sample=0, hold="path") for s in restrict]

    def _solve(self, target: pin.SE3, q_start: np.ndarray, active: tuple[str, ...]) -> Attempt:
        return solver.attempt(self.robot, target, q_start, self.tol_pos, self.tol_rot, np.inf, active=active,
                              **self.options)

    def sample(self, k: int, target: pin.SE3, q_prev: np.ndarray) -> np.ndarray:
        """Solve sample k warm-started from q_prev, switching a restriction on if a monitor fires."""
        t0 = time.perf_counter()
        active = (*self.restrict, *(s for s, left in self.held.items() if left > 0 and s not in self.restrict))
        att = self._solve(target, q_prev, active)
        step = float(np.max(np.abs(att.q - q_prev)))
        jumped = self.jump_limit is not None and step > self.jump_limit
        self.events += [ev.at_sample(k) for ev in att.events]
        if jumped:
            self.events.append(SingularEvent("jump", sample=k, max_joint_step=step))
        pending = [s for s in self.restrictions if s not in active]
        if (att.events or jumped) and (att.status != Status.CONVERGED or jumped) and pending:
            self.held[pending[0]] = self.hold
            self.bypasses.append(BypassRecord(pending[0], sample=k, hold=self.hold))
            att = self._solve(target, q_prev, (*active, pending[0]))
        self.bypasses += [b.at_sample(k) for b in att.bypasses if b.bypass not in RESTRICTIONS]
        self.held = {s: left - 1 for s, left in self.held.items() if left > 1}
        dp, dr = self.robot.tool_error(att.q, target)
        self.rows.append(att.q)
        self.figures.append((dp, dr, att.status.value, att.iterations, time.perf_counter() - t0))
        return att.q

    def result(self) -> TrackResult:
        """The path's TrackResult."""
        dp, dr, status, sweeps, times = zip(*self.figures, strict=True) if self.figures else ([],) * 5
        return TrackResult(np.array(self.rows), np.array(dp), np.array(dr), list(status), np.array(sweeps),
                           np.array(times), self.events, self.bypasses)
