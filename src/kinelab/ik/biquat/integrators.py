"""The Python integrators of the Cauchy problem q̇ = A(q)⁻¹U (docs/methods.md §2.6): fixed-step Euler or
RK4 (the paper's h = 0.01 s), or adaptive (scipy's RK45 with a terminal event), with the trajectory kept
for plots. The laws and A(q) are the compiled functions the preset kernel uses too.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.ik.biquat import laws
from kinelab.ik.biquat.options import BiquatOptions
from kinelab.ik.chain import chain_fk, chain_model, jacobian_local
from kinelab.ik.limits import PinLimits
from kinelab.ik.result import BiquatTrajectory, Status
from kinelab.robot import Chain

_ZERO2 = np.zeros(2)


@dataclass
class Trajectory:
    """The integration history for plots: t [s], q(t), M(t) (8 numbers each), U(t) = (ω, v)."""

    t: list[float] = field(default_factory=list)
    q: list[np.ndarray] = field(default_factory=list)
    M: list[np.ndarray] = field(default_factory=list)
    U: list[np.ndarray] = field(default_factory=list)

    def append(self, t, q, M, U):
        """Record one step: model time [s], Pinocchio q, M*, U."""
        self.t.append(float(t))
        self.q.append(np.array(q))
        self.M.append(np.array(M))
        self.U.append(np.concatenate(U))

    def arrays(self) -> BiquatTrajectory:
        """The recorded rows as arrays."""
        return BiquatTrajectory(np.array(self.t), np.array(self.q), np.array(self.M), np.array(self.U))


class System:
    """q̇ = A(q)⁻¹ U(M*(q)) (and Ṫ for the regular law) on Pinocchio's q.

    The chain's FK and A(q) come from :mod:`kinelab.ik.chain` (A(q) = the LOCAL tool Jacobian, rows
    [v; ω]: the paper's eq. (8) with its two row blocks swapped, tested equal to the biquaternion product
    of :func:`kinelab.dq.kinematics.a_matrix`); M* and U from :mod:`kinelab.ik.biquat.laws`, the same
    functions the compiled preset calls.
    """

    def __init__(self, robot: Chain, oMtarget: pin.SE3, options: BiquatOptions):
        self.robot, self.model = robot, robot.model
        self.cm = chain_model(robot)
        self.pstar, self.Rstar = np.array(oMtarget.translation), np.array(oMtarget.rotation)
        self.law, self.k, self.k0 = options.law, options.gain, float(options.k0)
        self.k_v = self.k if options.k_v is None else float(options.k_v)
        self.damping = options.damping_for(robot.n)
        self.limits: PinLimits | None = PinLimits(robot) if options.clamp else None
        n = robot.n
        self._e, self._o, self._p, self._R = np.empty((n, 3)), np.empty((n, 3)), np.empty(3), np.empty((3, 3))
        self._twist = np.empty(6)

    def _fk(self, q_pin: np.ndarray) -> np.ndarray:
        chain_fk(self.cm.chain, self.robot.from_pin_q(q_pin), self._e, self._o, self._p, self._R)
        return laws.error_biquaternion(self._p, self._R, self.pstar, self.Rstar)

    def error(self, q_pin: np.ndarray) -> np.ndarray:
        """M* = N̄∘Λ(q), 8 numbers, m^0 ≥ 0."""
        return self._fk(q_pin)

    def rates(self, q_pin: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
        """(q̇, Ṫ, M*, U = (ω, v)) at q.

        Raises:
            KinelabError: law (9) at m^0 = 0 (an error rotation of π).
        """
        M = self._fk(q_pin)
        twist = self._twist
        if self.law == "simple":
            if not laws.simple_law(M, self.k, self.k0, self.k_v, twist):
                raise KinelabError("law (9) is singular: the error rotation is π (m^0 = 0); use law='regular'")
            T_dot = _ZERO2
        else:
            T_dot = np.array(laws.regular_law(M, T[0], T[1], self.k, self.k0, twist))
        J = jacobian_local(self._e, self._o, self.cm.kind, self._p, self._R)
        qd = laws.joint_rates(J, twist, self.damping)
        return qd, T_dot, M, (twist[3:].copy(), twist[:3].copy())


def done(M: np.ndarray, eps_rot: float, eps_dual: float) -> bool:
    """The stopping test: |m⃗| < eps_rot and |m0⃗| < eps_dual."""
    return bool(laws.converged(M, eps_rot, eps_dual))


class Stop(NamedTuple):
    """When an integration stops, and its step."""

    h: float  # fixed step (first step of the adaptive integrator) [s]
    max_time: float  # model-time limit [s]
    deadline: float  # time.perf_counter() value
    eps_rot: float  # |m⃗| below this ...
    eps_dual: float  # ... and |m0⃗| below this [m]: converged
    max_step: float | None  # largest joint change per fixed step [rad or m]
    max_steps: int  # fixed steps per attempt


def fixed(system: System, q_pin: np.ndarray, stop: Stop, integrator: str, traj: Trajectory | None) -> tuple:
    """Fixed-step Euler or RK4; with ``stop.max_step`` [rad or m] a step that would move a joint further is
    shortened (the same law, integrated with a smaller h there).

    Returns:
        (q_pin, model time, steps, status, M* at the end).
    """
    T = np.array([1.0, 0.0])
    t, steps = 0.0, 0
    while True:
        qd, Td, M, U = system.rates(q_pin, T)
        if traj is not None:
            traj.append(t, system.robot.from_pin_q(q_pin), M, U)
        if done(M, stop.eps_rot, stop.eps_dual):
            return q_pin, t, steps, Status.CONVERGED, M
        if not np.all(np.isfinite(qd)):
            return q_pin, t, steps, Status.SINGULAR, M
        if t >= stop.max_time or steps >= stop.max_steps:
            return q_pin, t, steps, Status.MAX_ITERATIONS, M
        if time.perf_counter() > stop.deadline:
            return q_pin, t, steps, Status.TIME_BUDGET, M
        dt = stop.h
        if stop.max_step is not None:
            dt = min(stop.h, stop.max_step / max(float(np.max(np.abs(qd))), 1e-300))
        q_pin, T = _step(system, q_pin, T, qd, Td, dt, integrator)
        t += dt
        steps += 1


def _step(system: System, q_pin: np.ndarray, T: np.ndarray, qd: np.ndarray, Td: np.ndarray, dt: float,
          integrator: str) -> tuple[np.ndarray, np.ndarray]:
    """One Euler or RK4 step of (q, T), configuration arithmetic through ``pin.integrate``."""
    model = system.model
    if integrator == "euler":
        q_pin, T = pin.integrate(model, q_pin, dt * qd), T + dt * Td
        if system.limits is not None:
            system.limits.project(q_pin)
        return q_pin, T
    k1, l1 = qd, Td
    k2, l2, _, _ = system.rates(pin.integrate(model, q_pin, 0.5 * dt * k1), T + 0.5 * dt * l1)
    k3, l3, _, _ = system.rates(pin.integrate(model, q_pin, 0.5 * dt * k2), T + 0.5 * dt * l2)
    k4, l4, _, _ = system.rates(pin.integrate(model, q_pin, dt * k3), T + dt * l3)
    q_pin = pin.integrate(model, q_pin, dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))
    return q_pin, T + dt / 6.0 * (l1 + 2 * l2 + 2 * l3 + l4)


def adaptive(system: System, q_pin: np.ndarray, stop: Stop, traj: Trajectory | None) -> tuple:
    """scipy's RK45 on tangent coordinates δ (q = q0 ⊕ δ), stopped by an event when M* is within tolerance."""
    from scipy.integrate import solve_ivp  # 30-300 ms to import: only where the adaptive integrator is asked for

    model, nv = system.model, system.robot.nv
    eps_rot, eps_dual = stop.eps_rot, stop.eps_dual
    q_base = q_pin.copy()

    def unpack(y):
        return pin.integrate(model, q_base, y[:nv]), y[nv:]

    last: dict[str, Any] = {"q": q_pin, "t": 0.0, "nfev": 0}  # where a run stopped by the clock ends

    def rhs(t, y):
        if time.perf_counter() > stop.deadline:
            raise _OutOfTimeError
        q, T = unpack(y)
        last.update(q=q, t=t, nfev=last["nfev"] + 1)
        qd, Td, M, U = system.rates(q, T)
        if traj is not None:
            traj.append(t, system.robot.from_pin_q(q), M, U)
        # d/dt of δ: the right Jacobian inverse of integrate maps q̇ to δ̇ (identity for scalar joints)
        Jd = pin.dIntegrate(model, q_base, y[:nv], pin.ArgumentPosition.ARG1)
        return np.r_[np.linalg.solve(Jd, qd), Td]

    def converged(t, y):
        q, _ = unpack(y)
        M = system.error(q)
        return max(np.linalg.norm(M[1:4]) / eps_rot, np.linalg.norm(M[5:8]) / eps_dual) - 1.0

    converged.terminal = True  # type: ignore[attr-defined]
    try:
        sol = solve_ivp(rhs, (0.0, stop.max_time), np.r_[np.zeros(nv), 1.0, 0.0], events=converged, rtol=1e-8,
                        atol=1e-10, first_step=min(stop.h, 0.1))
    except _OutOfTimeError:
        return last["q"], float(last["t"]), int(last["nfev"]), Status.TIME_BUDGET, system.error(last["q"])
    q_end, _ = unpack(sol.y[:, -1])
    M = system.error(q_end)
    status = Status.CONVERGED if done(M, eps_rot * 1.0001, eps_dual * 1.0001) else (
        Status.MAX_ITERATIONS if sol.status == 0 else Status.SINGULAR)
    return q_end, float(sol.t[-1]), int(sol.nfev), status, M


class _OutOfTimeError(Exception):
    """Raised inside scipy's integrator when the solve's deadline has passed (scipy has no deadline)."""
