"""Biquaternion kinematic-control IK (Chelnokov; Lomovtseva & Chelnokov): the Cauchy problem q̇ = A(q)⁻¹U.

The error biquaternion M = N̄∘Λ is the tool's pose in the target frame; the control U = ω + s v (end
link axes) drives it to ±1 (methods.md §2):

- the simple law (9)/(16): U = −2K vect(M)/scal(M), dual gain K = k + s k0, singular at m^0 = 0
  (error rotation π). Optional separate real gains (k_ω, k_v) for the rotation and moment parts;
- the regular law (11)/(12): U = K T⁻¹ vect(Λ̄∘N), 2Ṫ = K(scal(Λ̄∘N) − T), T(t0) = 1, bounded everywhere.

q̇ = A⁻¹U is integrated with fixed-step Euler or RK4 (the paper's h = 0.01 s), or adaptively (scipy's
RK45 with a terminal event). The ``newton`` preset is Euler with h·k = 1: locally one Gauss–Newton step
per step, still the paper's law. A(q) is Pinocchio's LOCAL Jacobian with its row blocks swapped, which
the tests hold equal to the biquaternion A(q) of :mod:`kinelab.biquat_kinematics`; n ≠ 6 uses a damped
pseudo-inverse.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from kinelab import biquat_kinematics
from kinelab.dualquat import DualQuat, same_pose
from kinelab.errors import KinelabError
from kinelab.ik.limits import PinLimits, wrap_q
from kinelab.ik.result import Attempt, Status
from kinelab.robot import Robot

LAWS = ("simple", "regular")
MAX_STEPS = 20000
_ZERO2 = np.zeros(2)  # fixed steps per attempt, whatever the model time
INTEGRATORS = ("euler", "rk4", "adaptive")


def error_biquaternion(N: DualQuat, Lam: DualQuat) -> DualQuat:
    """M = N̄∘Λ."""
    return N.conj() * Lam


def canonical(M: DualQuat) -> DualQuat:
    """M with m^0 ≥ 0 (Λ and −Λ are the same pose)."""
    return -M if M.real_wxyz[0] < 0 else M


def _parts(M) -> tuple[float, np.ndarray, float, np.ndarray]:
    """(m^0, m⃗, m0^0, m0⃗) of a DualQuat or of 8 numbers (real w, x, y, z, dual w, x, y, z)."""
    arr = M.as_array() if isinstance(M, DualQuat) else M
    return arr[0], arr[1:4], arr[4], arr[5:8]


def relative_biquaternion(oMtarget: pin.SE3, oMtool: pin.SE3) -> np.ndarray:
    """M = N̄∘Λ as 8 numbers with m^0 ≥ 0: the biquaternion of the tool's pose in the target frame."""
    rel = oMtarget.actInv(oMtool)
    quat = pin.Quaternion(rel.rotation)
    w, x, y, z = quat.w, quat.x, quat.y, quat.z
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    tx, ty, tz = 0.5 * rel.translation
    # ½ (0, t)∘λ
    return np.array([w, x, y, z,
                     -tx * x - ty * y - tz * z,
                     tx * w + ty * z - tz * y,
                     ty * w + tz * x - tx * z,
                     tz * w + tx * y - ty * x])


def simple_law(M: DualQuat, k: float, k0: float = 0.0, k_v: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Law (9)/(16): (ω, v) [rad/s, m/s], end-link axes. ``k_v`` set: separate gains k (rotation), k_v (moment).

    ω = −2k m⃗/m^0, v = −2[k m^0 m0⃗ + (k0 m^0 − k m0^0) m⃗]/(m^0)²; with k_v: v = −2k_v(m^0 m0⃗ − m0^0 m⃗)/(m^0)².
    """
    m0s, m, d0s, d = _parts(M)
    if m0s == 0.0:
        raise KinelabError("law (9) is singular: the error rotation is π (m^0 = 0); use law='regular'")
    omega = -2.0 * k * m / m0s
    if k_v is None:
        v = -2.0 * (k * m0s * d + (k0 * m0s - k * d0s) * m) / m0s**2
    else:
        v = -2.0 * k_v * (m0s * d - d0s * m) / m0s**2
    return omega, v


def regular_law(M: DualQuat, T: tuple[float, float], k: float, k0: float = 0.0):
    """Law (11)/(12): (ω, v) and (τ̇, τ̇0). U = −K T⁻¹ vect(M), 2Ṫ = K(scal(M) − T)."""
    tau, tau0 = T
    c, c0 = k / tau, (k0 * tau - k * tau0) / tau**2  # K T⁻¹ as a dual number
    m0s, m, d0s, d = _parts(M)
    omega = -c * m
    v = -(c * d + c0 * m)
    tau_dot = 0.5 * k * (m0s - tau)
    tau0_dot = 0.5 * (k * (d0s - tau0) + k0 * (m0s - tau))
    return omega, v, (tau_dot, tau0_dot)


@dataclass
class Trajectory:
    """The integration history for plots: t [s], q(t), M(t) (8 numbers each), U(t) = (ω, v)."""

    t: list[float] = field(default_factory=list)
    q: list[np.ndarray] = field(default_factory=list)
    M: list[np.ndarray] = field(default_factory=list)
    U: list[np.ndarray] = field(default_factory=list)

    def append(self, t, q, M, U):
        self.t.append(float(t))
        self.q.append(np.array(q))
        self.M.append(np.array(M))
        self.U.append(np.concatenate(U))

    def arrays(self) -> dict[str, np.ndarray]:
        return {"t": np.array(self.t), "q": np.array(self.q), "M": np.array(self.M), "U": np.array(self.U)}


class _System:
    """q̇ = A(q)⁻¹ U(M(q)) (and Ṫ for the regular law), evaluated with Pinocchio's FK and Jacobian."""

    def __init__(self, robot: Robot, oMtarget: pin.SE3, law: str, k: float, k0: float, k_v: float | None,
                 damping: float):
        self.robot, self.model, self.data, self.fid = robot, robot.model, robot.data, robot.tool_frame_id
        self.oMtarget = oMtarget
        self.law, self.k, self.k0, self.k_v, self.damping = law, k, k0, k_v, damping
        self.square = robot.n == 6
        self.limits = None  # PinLimits when the integration keeps q inside the joint limits

    def error(self, q_pin: np.ndarray) -> np.ndarray:
        """M* = N̄∘Λ(q), 8 numbers, m^0 ≥ 0."""
        pin.forwardKinematics(self.model, self.data, q_pin)
        return relative_biquaternion(self.oMtarget, pin.updateFramePlacement(self.model, self.data, self.fid))

    def solve_rates(self, J: np.ndarray, omega: np.ndarray, v: np.ndarray) -> np.ndarray:
        """q̇ = A⁻¹(ω; v) = J_L⁻¹(v; ω); damped pseudo-inverse (SVD) when n ≠ 6 or damping > 0."""
        twist = np.concatenate((v, omega))
        if self.square and self.damping == 0.0:
            return np.linalg.solve(J, twist)  # a singular A raises LinAlgError: reported as singular
        U, s, Vt = np.linalg.svd(J, full_matrices=False)
        gain = s / (s**2 + self.damping**2)
        return Vt.T @ (gain * (U.T @ twist))

    def rates(self, q_pin, T):
        """(q̇, Ṫ, M*, U) at q: one pass of Pinocchio gives the tool pose and the Jacobian."""
        pin.computeJointJacobians(self.model, self.data, q_pin)
        oMtool = pin.updateFramePlacement(self.model, self.data, self.fid)
        M = relative_biquaternion(self.oMtarget, oMtool)
        if self.law == "simple":
            omega, v = simple_law(M, self.k, self.k0, self.k_v)
            T_dot = _ZERO2
        else:
            omega, v, T_dot = regular_law(M, T, self.k, self.k0)
            T_dot = np.array(T_dot)
        J = pin.getFrameJacobian(self.model, self.data, self.fid, pin.LOCAL)
        return self.solve_rates(J, omega, v), T_dot, M, (omega, v)


def _done(M: np.ndarray, eps_rot: float, eps_dual: float) -> bool:
    m, d = M[1:4], M[5:8]
    return bool(m @ m < eps_rot**2 and d @ d < eps_dual**2)


def attempt(
    robot: Robot,
    oMtarget: pin.SE3,
    q0: np.ndarray,
    tol_pos: float,
    tol_rot: float,
    deadline: float,
    *,
    law: str = "simple",
    k: float | None = None,
    k0: float = 0.0,
    k_v: float | None = None,
    integrator: str = "euler",
    step: float | None = None,
    max_time: float | None = None,
    damping: float | None = None,
    max_step: float | None = None,
    max_steps: int | None = None,
    clamp: bool | None = None,
    target_biquaternion: DualQuat | None = None,
    record: bool = False,
) -> Attempt:
    """Integrate q̇ = A⁻¹U from ``q0`` until M* is within tolerance of ±1 or a limit is reached.

    Args:
        law: "simple" (9)/(16) or "regular" (11)/(12).
        k, k0: the dual gain K = k + s k0 [1/s] (default k = 1; with the newton preset h = 1/k).
        k_v: a separate real gain for the moment part (simple law), as the paper advises.
        integrator: "euler", "rk4" or "adaptive" (scipy RK45 with a terminal event).
        step: the fixed step h [s] (default: 1/k, the Newton-like preset; the paper uses 0.01).
        max_time: model-time limit [s] (default 100/k).
        damping: λ of the damped pseudo-inverse (default 0 for n = 6, 1e-4 otherwise); it is reported.
        max_step: largest joint change per fixed step [rad or m]; longer steps are shortened (default
            0.5 with the newton preset, none when ``step`` is given, as in the paper).
        max_steps: step cap of this attempt (default 30 with the newton preset, where a converging run
            takes 10–25 steps and a longer one is crawling past a singularity; 20000 otherwise).
        clamp: after each Euler step, wrap revolute joints by 2π and clip q into the joint limits (off by
            default: measured on the bench it breaks more runs than it saves).
        target_biquaternion: N itself, when the sign of the target matters (the paper's printed N, or
            the chain product at a target q); it must be the pose of ``oMtarget``. Default: from the SE3.
        record: keep the trajectory (t, q, M*, U) in ``info["trajectory"]``.

    The stopping test is |m⃗| < tol_rot/2 and |m0⃗| < tol_pos/2: near ±1, m⃗ ≈ δθ/2 and m0⃗ ≈ ½R*ᵀΔp.
    """
    if law not in LAWS:
        raise KinelabError(f"unknown law {law!r}; laws are: {', '.join(LAWS)}")
    if integrator not in INTEGRATORS:
        raise KinelabError(f"unknown integrator {integrator!r}; integrators are: {', '.join(INTEGRATORS)}")
    k = 1.0 if k is None else float(k)
    if not (k > 0 and np.isfinite(k)) or (k_v is not None and not k_v > 0):
        raise KinelabError(f"gains must be positive and finite, got k = {k}, k_v = {k_v}")
    if not np.isfinite(k0):
        raise KinelabError(f"k0 must be finite, got {k0}")
    newton = step is None
    h = 1.0 / k if newton else float(step)
    max_step = (0.5 if newton else None) if max_step is None else float(max_step)
    max_steps = (30 if newton else MAX_STEPS) if max_steps is None else int(max_steps)
    clamp = False if clamp is None else bool(clamp)
    if not h > 0:
        raise KinelabError(f"the integration step must be positive, got {h}")
    max_time = 100.0 / k if max_time is None else float(max_time)
    damping = (0.0 if robot.n == 6 else 1e-4) if damping is None else float(damping)
    if target_biquaternion is not None:
        N = target_biquaternion.require_unit("target_biquaternion")
        if not same_pose(N, DualQuat.from_se3(oMtarget), 1e-6):
            raise KinelabError("target_biquaternion is not the pose of the target")
    else:
        N = DualQuat.from_se3(oMtarget)
    q_pin = robot.to_pin_q(q0)
    # The regular law is not invariant under M → −M: its hemisphere is fixed at t0 (m^0(t0) ≥ 0), and
    # φ ≤ π stays invariant after that, so the canonical M* (m^0 ≥ 0) of each evaluation is consistent.
    system = _System(robot, oMtarget, law, k, k0, k_v, damping)
    if clamp:
        system.limits = PinLimits(robot)
    eps_rot, eps_dual = 0.5 * tol_rot, 0.5 * tol_pos
    traj = Trajectory() if record else None
    try:
        if integrator == "adaptive":
            q_pin, t, steps, status, M = _adaptive(system, q_pin, h, max_time, deadline, eps_rot, eps_dual, traj)
        else:
            q_pin, t, steps, status, M = _fixed(system, q_pin, h, max_time, deadline, eps_rot, eps_dual,
                                                integrator, traj, max_step, max_steps)
    except (KinelabError, np.linalg.LinAlgError, FloatingPointError) as exc:
        return Attempt(robot.neutral(), Status.SINGULAR, 0, info={"mode": f"biquat ({law})", "message": str(exc)})
    q_end = robot.from_pin_q(q_pin)
    M0 = None
    if target_biquaternion is not None or record:
        # Λ by the chain product, continuous in q: the scalar of N̄∘Λ tells which of ±1 was reached
        M0 = float((N.conj() * biquat_kinematics.pose(robot, q_end)).real_wxyz[0])
    q = wrap_q(robot, robot.wrap_continuous(q_end))
    preset = "newton " if newton and integrator != "adaptive" else ""
    info = {"mode": f"biquat ({law}, {preset}{integrator}, h={h:g}, k={k:g})", "model_time": t, "steps": steps,
            "M0": M0, "damping": damping, "law": law, "integrator": integrator}
    if traj is not None:
        info["trajectory"] = traj.arrays()
    return Attempt(q, status, steps, info=info)


def _fixed(system: _System, q_pin, h, max_time, deadline, eps_rot, eps_dual, integrator, traj, max_step, max_steps):
    """Fixed-step Euler or RK4; with ``max_step`` [rad or m] a step that would move a joint further is
    shortened (the same law, integrated with a smaller h there)."""
    model = system.model
    T = np.array([1.0, 0.0])
    t, steps = 0.0, 0
    while True:
        qd, Td, M, U = system.rates(q_pin, T)
        if traj is not None:
            traj.append(t, system.robot.from_pin_q(q_pin), M, U)
        if _done(M, eps_rot, eps_dual):
            return q_pin, t, steps, Status.CONVERGED, M
        if not np.all(np.isfinite(qd)):
            return q_pin, t, steps, Status.SINGULAR, M
        if t >= max_time or steps >= max_steps:
            return q_pin, t, steps, Status.MAX_ITERATIONS, M
        if time.perf_counter() > deadline:
            return q_pin, t, steps, Status.TIME_BUDGET, M
        dt = h
        if max_step is not None:
            dt = min(h, max_step / max(float(np.max(np.abs(qd))), 1e-300))
        if integrator == "euler":
            q_pin, T = pin.integrate(model, q_pin, dt * qd), T + dt * Td
            if system.limits is not None:
                system.limits.project(q_pin)
        else:
            k1, l1 = qd, Td
            k2, l2, _, _ = system.rates(pin.integrate(model, q_pin, 0.5 * dt * k1), T + 0.5 * dt * l1)
            k3, l3, _, _ = system.rates(pin.integrate(model, q_pin, 0.5 * dt * k2), T + 0.5 * dt * l2)
            k4, l4, _, _ = system.rates(pin.integrate(model, q_pin, dt * k3), T + dt * l3)
            q_pin = pin.integrate(model, q_pin, dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))
            T = T + dt / 6.0 * (l1 + 2 * l2 + 2 * l3 + l4)
        t += dt
        steps += 1


def _adaptive(system: _System, q_pin, h, max_time, deadline, eps_rot, eps_dual, traj):
    """scipy's RK45 on tangent coordinates δ (q = q0 ⊕ δ), stopped by an event when M* is within tolerance."""
    from scipy.integrate import solve_ivp

    model, nv = system.model, system.robot.nv
    q_base = q_pin.copy()

    def unpack(y):
        return pin.integrate(model, q_base, y[:nv]), y[nv:]

    def rhs(t, y):
        q, T = unpack(y)
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

    converged.terminal = True
    sol = solve_ivp(rhs, (0.0, max_time), np.r_[np.zeros(nv), 1.0, 0.0], events=converged, rtol=1e-8,
                    atol=1e-10, first_step=min(h, 0.1))
    q_end, _ = unpack(sol.y[:, -1])
    M = system.error(q_end)
    status = Status.CONVERGED if _done(M, eps_rot * 1.0001, eps_dual * 1.0001) else (
        Status.MAX_ITERATIONS if sol.status == 0 else Status.SINGULAR)
    return q_end, float(sol.t[-1]), int(sol.nfev), status, M


def paper_unit_biquaternion(real_wxyz, dual_wxyz) -> DualQuat:
    """A target given as printed numbers, checked: finite and unit (|λ| = 1, λ·λ0 = 0) to 1e-5."""
    lam = DualQuat(np.asarray(real_wxyz, float), np.asarray(dual_wxyz, float))
    return lam.require_unit("the target biquaternion", tol=1e-5).normalized()


FAST_OPTIONS = {"law": "simple", "integrator": "euler", "step": None, "k0": 0.0, "k_v": None, "max_step": None,
                "max_steps": None, "clamp": None, "target_biquaternion": None, "record": False}


def fast_path_allowed(options: dict) -> bool:
    """The compiled preset serves law (9), newton Euler, k0 = 0, no trajectory and no given N."""
    return all(options.get(key, default) == default for key, default in FAST_OPTIONS.items()
               if key in options)


def multistart(
    robot: Robot, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float, deadline: float,
    seed: int | None, max_restarts: int, **options,
) -> tuple[Attempt, int]:
    """The default preset (law (9), Euler, h = 1/k, steps capped at 0.5 rad, 30 steps per attempt) with
    its seeded restarts inside the compiled kernel; answers outside the joint limits are restarted."""
    from kinelab.ik import biquat_kernel, restarts
    from kinelab.ik.frdm.solver import CHUNK, vector_model

    k = 1.0 if options.get("k") is None else float(options["k"])
    if not (k > 0 and np.isfinite(k)):
        raise KinelabError(f"gains must be positive and finite, got k = {k}")
    damping = (0.0 if robot.n == 6 else 1e-4) if options.get("damping") is None else float(options["damping"])
    max_time = options.get("max_time")
    vm = vector_model(robot)
    rng_state = restarts.seed_state(seed)
    q = np.array(q0, dtype=float)
    stats = np.zeros(5)
    pstar, Rstar = np.array(oMtarget.translation), np.array(oMtarget.rotation)
    max_steps = 30 if max_time is None else max(1, int(np.ceil(float(max_time) * k)))

    def chunk(attempts_left: int) -> int:
        return biquat_kernel.multistart(
            q, vm.placement_R, vm.placement_t, vm.axis_local, vm.kind, vm.tool_R, vm.tool_t, vm.lower, vm.upper,
            pstar, Rstar, k, 1.0 / k, 0.5, max_steps, 0.5 * tol_rot, 0.5 * tol_pos, damping, rng_state,
            attempts_left, stats[1] + CHUNK * 4, stats)

    code = restarts.run_in_chunks(chunk, max_restarts + 1, stats, deadline, biquat_kernel.CONVERGED)
    if code == biquat_kernel.CONVERGED:
        status = Status.CONVERGED
    elif time.perf_counter() > deadline:
        status = Status.TIME_BUDGET
    else:
        status = Status.SINGULAR if code == biquat_kernel.SINGULAR else Status.MAX_ITERATIONS
    info = {"mode": f"biquat (simple, newton euler, h={1.0 / k:g}, k={k:g}, compiled)", "model_time": float(stats[2]),
            "steps": int(stats[1]), "M0": None, "damping": damping, "law": "simple", "integrator": "euler",
            "attempts": int(stats[0]), "outside_limits": int(stats[3]), "path": "compiled"}
    return Attempt(q, status, int(stats[1]), info=info), max(0, int(stats[0]) - 1)


_COMPILED = False


def prepare(robot: Robot) -> None:
    """Compile (or load) the kernels before a solve's clock starts (once per process)."""
    global _COMPILED
    from kinelab.ik.frdm.solver import prepare as frdm_prepare

    frdm_prepare(robot)
    if not _COMPILED:
        multistart(robot, pin.SE3.Identity(), robot.neutral(), 1e-6, 1e-6, np.inf, 0, 0)
        _COMPILED = True
