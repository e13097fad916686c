"""FRDM's singularity monitor and bypass policy (docs/methods.md §1.6), around the compiled kernel.

Monitor (methods.md §1.6): the paper's rule Σ|Δq_i| = 0 while the target is not reached becomes
Σ|Δq_i| < ``eps_q`` over a sweep, or a relative drop of the objective below ``stall_rel`` over
``stall_window`` sweeps. Each firing is diagnosed (σ_min of the scaled Jacobian: a kinematic
singularity, or a stationary point such as a local minimum or a blocking limit), logged, and answered
by the next bypass of the policy:

- ``kicks``: add small signed δq to chosen joints (the ERA elbow: a minus sign folds it the wanted way);
- ``intervals``: hold joints inside tighter windows (the ERA wrist: q5, q6 below 80°);
- ``freeze``: hold joints at a value (q1 against the wrist gimbal lock, q1 or q7 at the shoulder);
- ``auto_kick``: a small deterministic kick of every free joint (the default when nothing is configured).

Every step of every sweep is an exact FRDM step, so the objective never increases. ``accel="anderson"``
extrapolates from the last sweeps and keeps the result only when it lowers the objective further;
``accel="none"`` is plain FRDM. ``polish=True`` adds damped-least-squares steps after FRDM: a separate
mode, reported as ``frdm+polish``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from kinelab.core import _frdm
from kinelab.errors import KinelabError
from kinelab.ik.chain import PRISMATIC, ChainModel
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm.kernel import no_rest
from kinelab.ik.frdm.options import BYPASSES, ORDERS, FRDMOptions
from kinelab.ik.result import BypassRecord, SingularEvent, Status
from kinelab.robot import Chain

SINGULAR_SIGMA = 1e-4  # σ_min of the scaled Jacobian below this: a kinematic singularity
CHUNK = 64  # sweeps between two looks at the clock


@dataclass
class Bypass:
    """The bypass configuration (all optional). Joint names are the robot's; values rad or m."""

    kicks: dict[str, float] = field(default_factory=dict)
    intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    freeze: dict[str, float | None] = field(default_factory=dict)  # None: hold the joint where it is
    policy: tuple[str, ...] | None = None
    active: tuple[str, ...] = ()  # bypasses applied before the first sweep
    auto_kick: float = 1e-2

    def resolved_policy(self) -> tuple[str, ...]:
        """The bypasses the monitor switches on, in order (the configured ones, or an automatic kick)."""
        if self.policy is not None:
            return tuple(self.policy)
        configured = tuple(k for k in ("kicks", "intervals", "freeze") if getattr(self, k))
        return configured or ("auto_kick",)

    def validate(self, robot: Chain) -> None:
        """Refuse a bypass that names a joint the robot does not have (JointNotFoundError)."""
        for table in (self.kicks, self.intervals, self.freeze):
            for name in table:
                robot.joint_index(name)
        for name, (lo, hi) in self.intervals.items():
            if not lo < hi:
                raise KinelabError(f"bypass interval for {name!r} is empty: [{lo}, {hi}]")
        for name, delta in self.kicks.items():
            if not np.isfinite(delta) or delta == 0:
                raise KinelabError(f"kick for {name!r} must be a finite non-zero δ, got {delta}")
        for step in (*self.resolved_policy(), *self.active):
            if step not in BYPASSES:
                raise KinelabError(f"unknown bypass {step!r} in policy; bypasses are: {', '.join(BYPASSES)}")


class Goal:
    """The arrays of one solve handed to the kernel, and the windows and free flags the bypasses change."""

    def __init__(self, cm: ChainModel, oMtarget: pin.SE3, options: FRDMOptions, tol_pos: float, tol_rot: float):
        self.pstar = oMtarget.translation  # pinocchio hands out a fresh array on every access
        self.Rstar = np.ascontiguousarray(oMtarget.rotation)  # one layout: one compiled signature
        self.w_p = options.position_weight(cm.length)
        self.w_ax = options.axis_weights()
        self.check_pos, self.check_rot = options.mode != "orientation", options.mode != "position"
        self.rot_axis = options.rot_axis
        self.tol_pos, self.tol_rot = float(tol_pos), float(tol_rot)
        self.lower = cm.lower.copy() if options.use_limits else np.full(cm.n, -np.inf)
        self.upper = cm.upper.copy() if options.use_limits else np.full(cm.n, np.inf)
        self.base_lower, self.base_upper = self.lower.copy(), self.upper.copy()
        self.free = np.ones(cm.n, dtype=np.bool_)

    def tuple(self) -> kernel.Objective:
        """The kernel's view of the problem (arrays shared, so bypasses show through)."""
        return kernel.Objective(self.lower, self.upper, self.free, self.pstar, self.Rstar, self.w_p, self.w_ax,
                              self.tol_pos, self.tol_rot, self.check_pos, self.check_rot, no_rest(len(self.free)), 0.0,
                              self.rot_axis)


def _scaled_sigma_min(robot: Chain, q: np.ndarray, length: float) -> float:
    J = robot.jacobian_local(q)
    J[:3] /= length
    return float(np.linalg.svd(J, compute_uv=False)[-1])


class Runner:
    """Runs the kernel in chunks, fires the monitor, applies bypasses and logs everything."""

    def __init__(self, robot: Chain, cm: ChainModel, prob: Goal, options: FRDMOptions):
        self.robot, self.vm, self.prob = robot, cm, prob
        self.order = ORDERS[options.order] if options.order != "mixed" else kernel.BASE_TO_TIP
        self.settings = options.settings()
        self.max_sweeps = options.sweep_cap
        self.mem = kernel.new_memory(cm.n, options.accel_m, self.max_sweeps if options.trace else 0)
        self.state = self.mem.state
        self.events: list[SingularEvent] = []
        self.bypass_log: list[BypassRecord] = []
        self.q = np.zeros(cm.n)
        self.next_bypass = 0

    @property
    def sweeps(self) -> int:
        """Sweeps run so far."""
        return int(self.state[kernel.S_SWEEPS])

    @property
    def accepted(self) -> int:
        """Accepted Anderson extrapolations."""
        return int(self.state[kernel.S_ACCEPTED])

    @property
    def newton_steps(self) -> int:
        """Gauss–Newton steps of the finish so far."""
        return int(self.state[kernel.S_NEWTON])

    @property
    def E(self) -> float:
        """The objective at the current q."""
        return float(self.state[kernel.S_E])

    def trace_values(self) -> list[float]:
        """The objective after every sweep so far."""
        return [float(v) for v in self.mem.trace[: self.sweeps]]

    def reset_history(self) -> None:
        """Forget the window of objective values (after a bypass moved q)."""
        self.state[kernel.S_HISTORY] = 0.0
        self.state[kernel.S_E_WINDOW] = np.inf if self.sweeps == 0 else self.state[kernel.S_E] * (1 + 1e-12) + 1e-300
        self.state[kernel.S_WINDOW_START] = self.state[kernel.S_SWEEPS]
        self.state[kernel.S_FINISH] = 0.0  # a bypass moved q: the Newton finish may be tried again

    def kernel_run(self, q: np.ndarray, budget: int) -> tuple[int, int]:
        """Up to ``budget`` sweeps of the compiled kernel from q (in place)."""
        self.state[kernel.S_HELD] = 0.0  # the monitor may have moved q since: the kernel recomputes the FK
        return _frdm.run_kernel(q, self.vm.chain, self.prob.tuple(), self.settings, self.order, int(budget), self.mem)

    def solve(self, q: np.ndarray, deadline: float, bypass: Bypass, max_events: int) -> Status:
        """Run until converged, out of sweeps or time, or the policy has no answer to a monitor event."""
        self.q = q
        policy = bypass.resolved_policy()
        while True:
            budget = min(CHUNK, self.max_sweeps - self.sweeps)
            if budget <= 0:
                return Status.MAX_ITERATIONS
            code, _ = self.kernel_run(self.q, budget)
            if code == kernel.CONVERGED:
                return Status.CONVERGED
            if code == kernel.BUDGET:
                if time.perf_counter() > deadline:
                    return Status.TIME_BUDGET
                continue
            ended = self._bypassed(self._event(code), bypass, policy, max_events)
            if ended is not None:
                return ended

    def _bypassed(self, diagnosis: str, bypass: Bypass, policy: tuple[str, ...], max_events: int) -> Status | None:
        """The policy's next bypass applied after a monitor event (None: the run goes on), or the status the run
        ends with when the policy has no answer to it."""
        if len(self.bypass_log) >= max_events or self.next_bypass >= len(policy):
            return Status.SINGULAR if diagnosis == "singular" else Status.STALLED
        step = policy[self.next_bypass]
        if step == "auto_kick" and diagnosis != "singular":
            return Status.STALLED  # a kick does not leave a local minimum; a restart does
        self.next_bypass += 1
        self.q = self.apply(bypass, step, self.q)
        self.reset_history()
        # leaving a singularity starts slowly (the kick grows by a factor per sweep): judge it patiently
        self.settings = self.settings._replace(window=max(self.settings.window, 100),
                                               window_rel=min(self.settings.window_rel, 1e-6))
        self.max_sweeps = max(self.max_sweeps, self.sweeps + 1000)
        return None

    def _event(self, code: int) -> str:
        sigma = _scaled_sigma_min(self.robot, self.q, self.vm.length)
        diagnosis = "singular" if sigma < SINGULAR_SIGMA else "stationary"
        dp, dr = self.robot.tool_error(self.q, pin.SE3(self.prob.Rstar, self.prob.pstar))
        self.events.append(SingularEvent(
            trigger="step" if code == kernel.STALL_STEP else "window",
            diagnosis=diagnosis,
            sweep=self.sweeps,
            sigma_min=sigma,
            position_error=dp,
            rotation_error=dr,
            q=tuple(self.q.tolist()),
        ))
        return diagnosis

    def apply(self, bypass: Bypass, step: str, q: np.ndarray) -> np.ndarray:
        """Apply one bypass to q and to the problem's windows; log it."""
        q = q.copy()
        idx = self.robot.joint_index
        if step == "kicks":
            for name, delta in bypass.kicks.items():
                q[idx(name)] += delta
        elif step == "auto_kick":
            # away from the nearer limit (a retracted slide extends, a joint at a stop backs off)
            lo, hi = self.prob.lower, self.prob.upper
            signs = np.where(np.isfinite(lo) & (q - lo < hi - q), 1.0, -1.0)
            scale = np.where(self.vm.kind == PRISMATIC, self.vm.length, 1.0)
            q[self.prob.free] += (bypass.auto_kick * signs * scale)[self.prob.free]
        elif step == "intervals":
            for name, (lo, hi) in bypass.intervals.items():
                i = idx(name)
                self.prob.lower[i] = max(lo, self.prob.base_lower[i])
                self.prob.upper[i] = min(hi, self.prob.base_upper[i])
        elif step == "freeze":
            for name, value in bypass.freeze.items():
                i = idx(name)
                q[i] = q[i] if value is None else value
                self.prob.free[i] = False
        q = np.clip(q, self.prob.lower, self.prob.upper)
        if step in ("kicks", "auto_kick"):
            self.state[kernel.S_KICKED] = 1.0  # the joints nearest the base act first on the kicked chain
        self.bypass_log.append(BypassRecord(step, sweep=self.sweeps, q=tuple(q.tolist())))
        return q


