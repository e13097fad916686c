"""One biquaternion-control solve: the Python integrators, or the compiled preset with its restarts.

The error biquaternion M = N̄∘Λ is the tool's pose in the target frame; the control U = ω + s v (end
link axes) drives it to ±1 (docs/methods.md §2). q̇ = A⁻¹U is integrated with fixed-step Euler or RK4,
or adaptively; the default ``newton`` preset (Euler with h·k = 1, steps capped at 0.5 rad) runs
compiled (:mod:`kinelab.ik.biquat.kernel`) with its restarts when the options allow it
(``BiquatOptions.compiled``). n ≠ 6 uses a damped pseudo-inverse.
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.core._engine import BiquatEngine
from kinelab.core._frdm import pack_chain
from kinelab.core.spec import BiquatSpec
from kinelab.dq import kinematics as biquat_kinematics
from kinelab.dq.algebra import DualQuat, same_pose
from kinelab.errors import BiquaternionError, KinelabError
from kinelab.ik import multistart as restarts
from kinelab.ik.biquat import kernel, laws
from kinelab.ik.biquat.integrators import Stop, System, Trajectory, adaptive, fixed
from kinelab.ik.biquat.options import BiquatOptions
from kinelab.ik.chain import chain_model
from kinelab.ik.codes import status_of
from kinelab.ik.driver import engine_judge, engine_spec
from kinelab.ik.limits import wrap_q
from kinelab.ik.multistart import clock_chunk
from kinelab.ik.request import Request
from kinelab.ik.result import Attempt, BiquatDiagnostics, Status
from kinelab.robot import Chain

Options = BiquatOptions
# integration steps × joints before the first look at the clock (most solves end within them), then between
# two looks (≈ 0.05 ms of work); a cut attempt is resumed, so the answer does not depend on these
JOINT_STEPS_PER_LOOK = 192
JOINT_STEPS_PER_LATER_LOOK = 48


def error_biquaternion(N: DualQuat, Lam: DualQuat) -> DualQuat:
    """M = N̄∘Λ (the biquaternion product; :func:`relative_biquaternion` gives it from poses)."""
    return N.conj() * Lam


def canonical(M: DualQuat) -> DualQuat:
    """M with m^0 ≥ 0 (Λ and −Λ are the same pose)."""
    return -M if M.real_wxyz[0] < 0 else M


def relative_biquaternion(oMtarget: pin.SE3, oMtool: pin.SE3) -> np.ndarray:
    """M = N̄∘Λ as 8 numbers with m^0 ≥ 0: the biquaternion of the tool's pose in the target frame."""
    return laws.error_biquaternion(oMtool.translation, oMtool.rotation, oMtarget.translation, oMtarget.rotation)


def simple_law(M: DualQuat, k: float, k0: float = 0.0, k_v: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Law (9)/(16) (:func:`kinelab.ik.biquat.laws.simple_law`) on a DualQuat: (ω, v) [rad/s, m/s].

    Raises:
        KinelabError: m^0 = 0 (an error rotation of π), where the law is singular.
    """
    twist = np.empty(6)
    if not laws.simple_law(M.as_array(), float(k), float(k0), float(k if k_v is None else k_v), twist):
        raise KinelabError("law (9) is singular: the error rotation is π (m^0 = 0); use law='regular'")
    return twist[3:], twist[:3]


def regular_law(M: DualQuat, T: tuple[float, float], k: float, k0: float = 0.0) -> tuple:
    """Law (11)/(12) (:func:`kinelab.ik.biquat.laws.regular_law`) on a DualQuat: (ω, v, (τ̇, τ̇0))."""
    twist = np.empty(6)
    T_dot = laws.regular_law(M.as_array(), float(T[0]), float(T[1]), float(k), float(k0), twist)
    return twist[3:], twist[:3], T_dot


def attempt(robot: Chain, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float, deadline: float,
            options: BiquatOptions | None = None, **kwargs: object) -> Attempt:
    """Integrate q̇ = A⁻¹U from ``q0`` until M* is within tolerance of ±1 or a limit is reached.

    The stopping test is |m⃗| < tol_rot/2 and |m0⃗| < tol_pos/2: near ±1, m⃗ ≈ δθ/2 and m0⃗ ≈ ½R*ᵀΔp.

    Args:
        robot: the robot.
        oMtarget: the wanted tool pose in the base frame.
        q0: start, one number per joint [rad or m].
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        deadline: ``time.perf_counter()`` value after which the attempt stops.
        options: a :class:`BiquatOptions`.
        kwargs: or its fields as keyword arguments.

    Returns:
        The attempt, before kinelab's Pinocchio check.

    Raises:
        OptionError: an option outside what it accepts.
        BiquaternionError: a target biquaternion that is not unit or not the target's pose.
    """
    opts = BiquatOptions.of(options, **kwargs)
    N = _target_biquaternion(opts, oMtarget)
    system = System(robot, oMtarget, opts)
    stop = Stop(opts.h, opts.model_time, deadline, 0.5 * tol_rot, 0.5 * tol_pos, opts.step_cap, opts.steps_cap)
    traj = Trajectory() if opts.record else None
    try:
        if opts.integrator == "adaptive":
            q_pin, t, steps, status, _ = adaptive(system, robot.to_pin_q(q0), stop, traj)
        else:
            q_pin, t, steps, status, _ = fixed(system, robot.to_pin_q(q0), stop, opts.integrator, traj)
    except (KinelabError, np.linalg.LinAlgError, FloatingPointError) as exc:
        return Attempt(robot.neutral(), Status.SINGULAR, 0, diagnostics=BiquatDiagnostics(message=str(exc)),
                       mode=f"biquat ({opts.law})")
    q_end = robot.from_pin_q(q_pin)
    M0 = None
    if opts.target_biquaternion is not None or opts.record:
        # Λ by the chain product, continuous in q: the scalar of N̄∘Λ tells which of ±1 was reached
        M0 = float((N.conj() * biquat_kinematics.pose(robot, q_end)).real_wxyz[0])
    preset = "newton " if opts.newton and opts.integrator != "adaptive" else ""
    diag = BiquatDiagnostics(model_time=t, steps=steps, M0=M0, damping=system.damping, law=opts.law,
                       integrator=opts.integrator, trajectory=None if traj is None else traj.arrays())
    mode = f"biquat ({opts.law}, {preset}{opts.integrator}, h={opts.h:g}, k={opts.gain:g})"
    return Attempt(wrap_q(robot, robot.wrap_continuous(q_end)), status, steps, diagnostics=diag, mode=mode)


def _target_biquaternion(opts: BiquatOptions, oMtarget: pin.SE3) -> DualQuat:
    if opts.target_biquaternion is None:
        return DualQuat.from_se3(oMtarget)
    N = opts.target_biquaternion.require_unit("target_biquaternion")
    if not same_pose(N, DualQuat.from_se3(oMtarget), 1e-6):
        raise BiquaternionError("target_biquaternion is not the pose of the target")
    return N


def paper_unit_biquaternion(real_wxyz: ArrayLike, dual_wxyz: ArrayLike) -> DualQuat:
    """A target given as printed numbers, checked: finite and unit (|λ| = 1, λ·λ0 = 0) to 1e-5."""
    lam = DualQuat(np.asarray(real_wxyz, float), np.asarray(dual_wxyz, float))
    return lam.require_unit("the target biquaternion", tol=1e-5).normalized()


def multistart(robot: Chain, oMtarget: pin.SE3, q0: np.ndarray | None, tol_pos: float, tol_rot: float, deadline: float,
               seed: int | None, max_restarts: int, options: BiquatOptions | None = None) -> tuple[Attempt, int]:
    """The default preset (law (9), Euler, h = 1/k, steps capped at 0.5 rad, 30 steps per attempt) with
    its seeded restarts inside the compiled kernel; answers outside the joint limits are restarted."""
    opts = options or BiquatOptions()
    k = opts.gain
    damping = opts.damping_for(robot.n)
    cm = chain_model(robot)
    prob = kernel.Control(np.array(oMtarget.translation), np.ascontiguousarray(oMtarget.rotation), float(k), 1.0 / k,
                          0.5, _max_steps(opts), 0.5 * float(tol_rot), 0.5 * float(tol_pos), float(damping))
    rng_state = restarts.seed_state(seed)
    q = restarts.first_start(q0, cm.kind, cm.lower, cm.upper, rng_state)
    stats = np.zeros(kernel.STATS_SIZE)
    restart_lower, restart_upper = restarts.restart_windows(cm, q, oMtarget.translation)
    code = kernel.timed(q, cm.chain, cm.lower, cm.upper, prob, rng_state, max_restarts + 1,
                        clock_chunk(JOINT_STEPS_PER_LOOK, cm.n), clock_chunk(JOINT_STEPS_PER_LATER_LOOK, cm.n),
                        float(deadline), restart_lower, restart_upper, stats)
    return compiled_attempt(code, q, stats, deadline, damping, k), max(0, int(stats[kernel.T_ATTEMPTS]) - 1)


def compiled_attempt(code: int, q: np.ndarray, stats: np.ndarray, deadline: float, damping: float,
                     k: float) -> Attempt:
    """The attempt of the compiled preset's multistart: its code (the kernel's), last q and statistics (slots
    ``kernel.T_*``); TIME_BUDGET when the deadline has passed without a convergence."""
    if code == kernel.CONVERGED:
        status = Status.CONVERGED
    elif time.perf_counter() > deadline:
        status = Status.TIME_BUDGET
    else:
        status = status_of(code)  # singular, or max_iterations (its steps or its chunk spent)
    return Attempt(q, status, int(stats[kernel.T_STEPS]), diagnostics=compiled_diagnostics(stats, damping),
                   mode=compiled_mode(k))


def compiled_diagnostics(stats: np.ndarray, damping: float) -> BiquatDiagnostics:
    """The diagnostics of the compiled preset's multistart from its statistics (slots ``kernel.T_*``)."""
    return BiquatDiagnostics(model_time=float(stats[kernel.T_MODEL_TIME]), steps=int(stats[kernel.T_STEPS]),
                       damping=damping, law="simple", integrator="euler", attempts=int(stats[kernel.T_ATTEMPTS]),
                       outside_limits=int(stats[kernel.T_OUTSIDE]), path="compiled")


def compiled_mode(k: float) -> str:
    """The compiled preset's mode string at gain k [1/s]."""
    return f"biquat (simple, newton euler, h={1.0 / k:g}, k={k:g}, compiled)"


def engine(robot: Chain, req: Request) -> BiquatEngine | None:
    """The prepared solver's one-call engine (:class:`kinelab.core._engine.BiquatEngine`): the compiled preset with
    its restarts, judged by the robot's certified compiled FK, the result filled in C. None where the general route
    must serve: options the preset does not run, a robot judged by Pinocchio's FK.

    Args:
        robot: the robot.
        req: the prepared solver's request (solver "biquat").
    """
    opts, judge = req.options, engine_judge(robot, req.options)
    if judge is None:
        return None
    cm = chain_model(robot)
    k, damping = opts.gain, opts.damping_for(robot.n)
    tol_pos, tol_rot = float(req.tol_pos), float(req.tol_rot)
    spec = engine_spec(
        robot, req, cm, partial(compiled_attempt, damping=damping, k=k), compiled_mode(k),
        partial(compiled_diagnostics, damping=damping), BiquatSpec, wrap_continuous=False, pstar=np.zeros(3),
        Rstar=np.eye(3),
        k=float(k), max_step=0.5, max_steps=_max_steps(opts), eps_rot=0.5 * tol_rot, eps_dual=0.5 * tol_pos,
        damping=float(damping), first_chunk=clock_chunk(JOINT_STEPS_PER_LOOK, cm.n),
        later_chunk=clock_chunk(JOINT_STEPS_PER_LATER_LOOK, cm.n), wide=restarts.wide_base(cm).astype(np.uint8),
        length=float(cm.length))
    return BiquatEngine(pack_chain(cm.chain), judge, spec)


def _max_steps(opts: BiquatOptions) -> int:
    """Steps of one attempt of the compiled preset: 30, or ceil(max_time·k)."""
    return 30 if opts.max_time is None else max(1, int(np.ceil(float(opts.max_time) * opts.gain)))


def prepare(robot: Chain, options: BiquatOptions | None = None) -> None:
    """Build the chain model before a solve's clock starts (the kernels are compiled at install)."""
    chain_model(robot)
