"""Tracking: follow a Cartesian path in small steps, each FRDM solve warm-started from the last answer.

This is FRDM's direct-control use (Danilov 2019): no restarts, so every jump or stall is visible. Two
monitors watch each sample: FRDM's own (Σ|Δq| = 0 short of the target, see
:mod:`kinelab.ik.frdm.solver`), and a jump monitor (a joint moving more than ``jump_limit`` between
consecutive samples: the links spinning through a singularity). When a monitor fires and the policy
has a restriction (``intervals`` or ``freeze``), the sample is solved again with it switched on, and it
stays on for ``hold`` samples before it is released. A restriction named in ``restrict`` is on for the
whole path instead: the paper's constraints set as parameters for a path that stays near a singular
point (the ERA wrist and shoulder passages), where no monitor fires before the damage is done.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.ik.frdm import solver
from kinelab.ik.result import Status
from kinelab.robot import Robot


@dataclass
class TrackResult:
    """One q per path sample (rows, rad/m) with its Pinocchio-measured errors and the monitor log."""

    q: np.ndarray
    position_error: np.ndarray  # [m]
    rotation_error: np.ndarray  # [rad]
    status: list[str]
    sweeps: np.ndarray
    wall_time: np.ndarray  # [s] per sample
    events: list[dict] = field(default_factory=list)
    bypasses: list[dict] = field(default_factory=list)

    @property
    def joint_steps(self) -> np.ndarray:
        """|q_k − q_(k−1)| per sample and joint (first row zero) [rad or m]."""
        return np.vstack([np.zeros(self.q.shape[1]), np.abs(np.diff(self.q, axis=0))])

    @property
    def max_joint_step(self) -> float:
        """The largest joint change between two consecutive samples [rad or m]."""
        return float(self.joint_steps.max())

    @property
    def reached(self) -> np.ndarray:
        return np.array([s == Status.CONVERGED.value for s in self.status])

    def summary(self) -> dict:
        return {
            "samples": len(self.status),
            "reached": int(self.reached.sum()),
            "max_position_error_m": float(self.position_error.max()),
            "max_rotation_error_rad": float(self.rotation_error.max()),
            "max_joint_step": self.max_joint_step,
            "monitor_events": len(self.events),
            "bypasses": len(self.bypasses),
            "median_time_per_sample_s": float(np.median(self.wall_time)),
        }


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
    policy: tuple[str, ...] | None = (),
    restrict: tuple[str, ...] = (),
    hold: int = 10,
    stall_window: int = 100,
    stall_rel: float = 1e-6,
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
        jump_limit: largest joint change per sample [rad or m] before the jump monitor fires (None: off).
        kicks: the bypass kicks (see :class:`~kinelab.ik.frdm.options.FRDMOptions`).
        intervals: the bypass intervals.
        freeze: the joints to freeze.
        policy: the bypass policy; the default ``()`` is FRDM without bypass.
        restrict: restrictions ("intervals", "freeze") held on every sample of the path.
        hold: samples a restriction stays on after the monitor switched it on.
        stall_window: the monitor's window [sweeps]; a path sample starts close to its answer, so a slow
            start is an escape from a singularity, not a local minimum to abandon.
        stall_rel: the relative fall required over the window.
        **frdm_options: other :class:`~kinelab.ik.frdm.options.FRDMOptions` fields (order, w_p, accel, ...).

    Returns:
        One row of q per sample with its Pinocchio-measured errors, statuses and the monitor log.

    Raises:
        ConfigurationError: q0 of the wrong shape or outside the limits.
        KinelabError: a restriction named without its table.
    """
    q_prev = robot.check_q(q0, limits=True, what="q0")
    unknown = [s for s in restrict if s not in ("intervals", "freeze")]
    if unknown:
        raise KinelabError(f"restrict takes 'intervals' and 'freeze', not {unknown}")
    for name, table in (("intervals", intervals), ("freeze", freeze)):
        if name in restrict and not table:
            raise KinelabError(f"restrict names {name!r} but no {name} table was given")
    restrictions = [s for s in (policy or ()) if s in ("intervals", "freeze")]
    reactive = tuple(s for s in (policy or ()) if s not in ("intervals", "freeze"))
    frdm_options = {"stall_window": stall_window, "stall_rel": stall_rel, **frdm_options}
    held: dict[str, int] = {}
    rows, perr, rerr, status, sweeps, times, events = [], [], [], [], [], [], []
    bypasses: list[dict] = [{"sample": 0, "bypass": s, "hold": "path"} for s in restrict]
    for k, target in enumerate(targets):
        t0 = time.perf_counter()
        active = (*restrict, *(s for s, left in held.items() if left > 0 and s not in restrict))
        att = _solve(robot, target, q_prev, tol_pos, tol_rot, max_sweeps, kicks, intervals, freeze,
                     reactive, active, frdm_options)
        jumped = jump_limit is not None and np.max(np.abs(att.q - q_prev)) > jump_limit
        fired = att.events or jumped
        for ev in att.events:
            events.append({**ev, "sample": k})
        if jumped:
            events.append({"sample": k, "trigger": "jump", "max_joint_step": float(np.max(np.abs(att.q - q_prev)))})
        pending = [s for s in restrictions if s not in active]
        if fired and (att.status != Status.CONVERGED or jumped) and pending:
            step = pending[0]
            held[step] = hold
            bypasses.append({"sample": k, "bypass": step, "hold": hold})
            active = (*active, step)
            att = _solve(robot, target, q_prev, tol_pos, tol_rot, max_sweeps, kicks, intervals, freeze,
                         reactive, active, frdm_options)
        bypasses += [{**b, "sample": k} for b in att.bypasses if b["bypass"] not in ("intervals", "freeze")]
        held = {s: left - 1 for s, left in held.items() if left > 1}
        dp, dr = robot.tool_error(att.q, target)
        rows.append(att.q)
        perr.append(dp)
        rerr.append(dr)
        status.append(att.status.value)
        sweeps.append(att.iterations)
        times.append(time.perf_counter() - t0)
        q_prev = att.q
    return TrackResult(np.array(rows), np.array(perr), np.array(rerr), status, np.array(sweeps), np.array(times),
                       events, bypasses)


def _solve(robot, target, q_start, tol_pos, tol_rot, max_sweeps, kicks, intervals, freeze, reactive, active, options):
    return solver.attempt(
        robot, target, q_start, tol_pos, tol_rot, np.inf, max_sweeps=max_sweeps, kicks=kicks, intervals=intervals,
        freeze=freeze, policy=reactive, **{"active": active, **options},
    )
