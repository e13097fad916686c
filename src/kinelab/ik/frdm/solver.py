"""One FRDM solve: sweeps (compiled), the singularity monitor, and the bypass policy.

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

import functools
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.ik import restarts
from kinelab.ik.frdm import kernel
from kinelab.ik.frdm.model import VectorModel, build
from kinelab.ik.result import Attempt, Status
from kinelab.robot import Robot

ORDERS = {"tip2base": 0, "base2tip": 1, "alternate": 2, "mixed": 3}
MODES = ("pose", "position", "orientation")
BYPASSES = ("kicks", "intervals", "freeze", "auto_kick")
# Defaults measured on panda, ur5, stanford and era (200 seeded targets each, kernel time to 1e-6 m/rad):
# w_p = 3/L² against 10/L² cut the median time by 10–50 % (era, panda most) at equal or better success,
# and a 10-sweep stall window (accelerated) against 15 gave up on hopeless attempts sooner at no loss.
W_P_FACTOR = 3.0
STALL_WINDOW = 10
PLAIN_STALL_WINDOW = 50
SINGULAR_SIGMA = 1e-4  # σ_min of the scaled Jacobian below this: a kinematic singularity
CHUNK = 64  # sweeps between two looks at the clock

_MODELS: dict[int, tuple[Robot, VectorModel]] = {}


def vector_model(robot: Robot) -> VectorModel:
    """The robot's vector model, built once per Robot object."""
    cached = _MODELS.get(id(robot))
    if cached is None or cached[0] is not robot:
        cached = (robot, build(robot))
        _MODELS[id(robot)] = cached
    return cached[1]


_COMPILED = False


def prepare(robot: Robot) -> None:
    """Build the vector model and compile (or load) the kernel: done before a solve's clock starts."""
    global _COMPILED
    vm = vector_model(robot)
    if not _COMPILED:
        target = pin.SE3.Identity()
        prob = _Problem(vm, target, "pose", None, (1.0, 1.0, 1.0), True)
        _Runner(robot, vm, prob, "base2tip", 1.0, 5, 1e-10, 15, 0.1, False, 2)._kernel(robot.neutral(), 2, 1e-6, 1e-6)
        multistart(robot, target, robot.neutral(), 1e-6, 1e-6, np.inf, 0, 0)  # the fast path's own signature
        _COMPILED = True


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
        if self.policy is not None:
            return tuple(self.policy)
        configured = tuple(k for k in ("kicks", "intervals", "freeze") if getattr(self, k))
        return configured or ("auto_kick",)

    def validate(self, robot: Robot) -> None:
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


class _Problem:
    """Arrays of one solve, handed to the kernel, plus what the bypasses change."""

    def __init__(self, vm: VectorModel, oMtarget: pin.SE3, mode: str, w_p: float | None, w_axes, use_limits: bool,
                 w_p_factor: float = 1.0):
        self.vm = vm
        self.pstar = oMtarget.translation  # pinocchio hands out a fresh array on every access
        self.Rstar = oMtarget.rotation
        self.w_p = _position_weight(vm, mode, w_p, w_p_factor)
        self.w_ax = _axis_weights(mode, w_axes)
        self.check_pos, self.check_rot = mode != "orientation", mode != "position"
        self.lower = vm.lower.copy() if use_limits else np.full(vm.n, -np.inf)
        self.upper = vm.upper.copy() if use_limits else np.full(vm.n, np.inf)
        self.base_lower, self.base_upper = self.lower.copy(), self.upper.copy()
        self.free = np.ones(vm.n, dtype=np.bool_)


def _position_weight(vm: VectorModel, mode: str, w_p: float | None, w_p_factor: float) -> float:
    """w_p [1/m²]: given, or w_p_factor/L² (L the chain's characteristic length); 0 in orientation mode."""
    if mode == "orientation":
        return 0.0
    return w_p_factor / vm.length**2 if w_p is None else float(w_p)


def _axis_weights(mode: str, w_axes) -> np.ndarray:
    """Weights of the tool x, y, z axes; 0 in position mode."""
    return np.zeros(3) if mode == "position" else np.array(w_axes, dtype=float)


def _monitor_defaults(plain: bool, max_sweeps, stall_window, stall_rel) -> tuple[int, int, float]:
    """Sweep cap and stall window of an attempt: 100 sweeps, 10 % over 10 accelerated; 3000, 1e-3 over 50 plain."""
    return (max_sweeps or (3000 if plain else 100), stall_window or (PLAIN_STALL_WINDOW if plain else STALL_WINDOW),
            (1e-3 if plain else 0.1) if stall_rel is None else float(stall_rel))


@functools.cache
def _all_free(n: int) -> np.ndarray:
    """Shared by every compiled solve; the kernel never writes it (left writeable: a read-only array is
    a second numba signature, 5 s more compiling on a cold cache)."""
    return np.ones(n, dtype=np.bool_)


def _scaled_sigma_min(robot: Robot, q: np.ndarray, length: float) -> float:
    J = robot.jacobian_local(q)
    J[:3] /= length
    return float(np.linalg.svd(J, compute_uv=False)[-1])


def _validate(mode: str, order: str, accel: str, relax: float) -> None:
    if mode not in MODES:
        raise KinelabError(f"unknown FRDM mode {mode!r}; modes are: {', '.join(MODES)}")
    if order not in ORDERS:
        raise KinelabError(f"unknown sweep order {order!r}; orders are: {', '.join(ORDERS)}")
    if accel not in ("anderson", "none"):
        raise KinelabError(f"unknown acceleration {accel!r}; use 'anderson' or 'none'")
    if not 0.0 < relax < 2.0:
        raise KinelabError(f"relax must lie in (0, 2), got {relax}")


def attempt(
    robot: Robot,
    oMtarget: pin.SE3,
    q0: np.ndarray,
    tol_pos: float,
    tol_rot: float,
    deadline: float,
    *,
    mode: str = "pose",
    w_p: float | None = None,
    w_p_factor: float = W_P_FACTOR,
    w_axes=(1.0, 1.0, 1.0),
    order: str = "mixed",
    relax: float = 1.0,
    accel: str = "anderson",
    accel_memory: int = 5,
    max_sweeps: int | None = None,
    eps_q: float = 1e-10,
    stall_window: int | None = None,
    stall_rel: float | None = None,
    use_limits: bool = True,
    kicks: dict | None = None,
    intervals: dict | None = None,
    freeze: dict | None = None,
    policy: tuple[str, ...] | None = None,
    active: tuple[str, ...] = (),
    max_bypass_events: int = 3,
    polish: bool = False,
    trace: bool = False,
) -> Attempt:
    """One FRDM run from ``q0`` (see the module docstring for the monitor and the bypasses).

    Args:
        mode: "pose", "position" (tool point only) or "orientation" (tool axes only).
        w_p: position weight [1/m²]; default ``w_p_factor``/L² with L the chain's characteristic length
            (methods.md §1.3): scale-aware, so the same factor serves a 0.3 m arm and the 11 m ERA.
        w_p_factor: the dimensionless factor of the default w_p (``W_P_FACTOR``).
        w_axes: weights of the tool x, y, z axes.
        order: "tip2base", "base2tip", "alternate" (one sweep each way, in turn) or "mixed" (base → tip
            here; in the compiled multistart, base → tip on the first attempt and every other restart,
            tip → base between: the two directions fall into different local minima, measured on 1000
            stanford targets as 99.5 → 99.6 % and on 200 as 99.0 → 99.5 %).
        relax: step = relax × the exact optimum, 0 < relax < 2 (still never increases the objective).
        accel: "anderson" (safeguarded extrapolation of the sweep map) or "none" (plain FRDM).
        max_sweeps: sweep cap of this attempt (default 100 accelerated, 3000 plain: restarts are cheaper
            than a long crawl).
        eps_q, stall_window, stall_rel: monitor thresholds: Σ|Δq| below eps_q in a sweep, or a relative
            drop of the objective below stall_rel over stall_window sweeps (default 10 % over 10 sweeps
            accelerated, 1e-3 over 50 sweeps plain).
        kicks: joint → signed δ (rad or m) added when the monitor fires.
        intervals: joint → (lower, upper), a tighter window held while active.
        freeze: joint → value (None: where the joint is) held while active.
        policy: the order in which monitor events switch bypasses on (default: those configured, in
            the order kicks, intervals, freeze; "auto_kick" when none is).
        active: bypasses switched on before the first sweep (tracking holds them while passing).
        max_bypass_events: how many monitor events the policy answers before the attempt gives up.
        polish: follow FRDM with damped-least-squares steps (reported as mode "frdm+polish").
        trace: keep the objective after every sweep in ``info["trace"]``.
    """
    _validate(mode, order, accel, relax)
    plain = accel == "none"
    max_sweeps, stall_window, stall_rel = _monitor_defaults(plain, max_sweeps, stall_window, stall_rel)
    bypass = Bypass(kicks or {}, intervals or {}, freeze or {}, policy, tuple(active))
    if kicks or intervals or freeze or policy or active:
        bypass.validate(robot)
    vm = vector_model(robot)
    prob = _Problem(vm, oMtarget, mode, w_p, w_axes, use_limits, w_p_factor)
    run = _Runner(robot, vm, prob, order, relax, accel_memory if accel == "anderson" else 0,
                  eps_q, stall_window, stall_rel, trace, max_sweeps)
    q = np.array(q0, dtype=float)
    for step in bypass.active:
        q = run.apply(bypass, step, q)
    status = run.solve(q, tol_pos, tol_rot, deadline, bypass, max_bypass_events)
    info = {"mode": "frdm" + ("" if accel == "anderson" else " (plain)"), "sweeps": run.sweeps,
            "accelerated_sweeps": run.accepted, "order": order, "w_p": prob.w_p, "relax": relax,
            "objective": run.E}
    if trace:
        info["trace"] = run.trace_values()
    att = Attempt(robot.wrap_continuous(run.q), status, run.sweeps, run.events, run.bypass_log, info)
    if polish and status != Status.CONVERGED:
        from kinelab.ik import dls

        pol = dls.attempt(robot, oMtarget, run.q, tol_pos, tol_rot, deadline, max_iterations=20)
        att = Attempt(pol.q, pol.status, run.sweeps + pol.iterations, run.events, run.bypass_log,
                      {**info, "mode": "frdm+polish", "polish_iterations": pol.iterations})
    return att


class _Runner:
    """Runs the kernel in chunks, fires the monitor, applies bypasses and logs everything."""

    def __init__(self, robot, vm, prob, order, relax, accel_m, eps_q, window, window_rel, trace, max_sweeps):
        self.robot, self.vm, self.prob = robot, vm, prob
        self.order, self.relax, self.accel_m = min(ORDERS[order], 2) if order != "mixed" else 1, relax, accel_m
        self.eps_q, self.window, self.window_rel = eps_q, window, window_rel
        self.max_sweeps = max_sweeps
        n = vm.n
        self.X = np.zeros((accel_m + 1, n))
        self.G = np.zeros((accel_m + 1, n))
        self.state = np.zeros(7)
        self.trace = np.full(max_sweeps if trace else 0, -1.0)
        self.events: list[dict] = []
        self.bypass_log: list[dict] = []
        self.q = np.zeros(n)
        self.next_bypass = 0

    @property
    def sweeps(self) -> int:
        return int(self.state[1])

    @property
    def accepted(self) -> int:
        return int(self.state[4])

    @property
    def E(self) -> float:
        return float(self.state[5])

    def trace_values(self) -> list[float]:
        return [float(v) for v in self.trace[: self.sweeps]]

    def reset_history(self) -> None:
        self.state[0] = 0.0
        self.state[2] = np.inf if self.sweeps == 0 else self.state[5] * (1 + 1e-12) + 1e-300
        self.state[3] = self.state[1]

    def _kernel(self, q, budget, tol_pos, tol_rot):
        vm, pr = self.vm, self.prob
        return kernel.run(
            q, vm.placement_R, vm.placement_t, vm.axis_local, vm.kind, vm.tool_R, vm.tool_t,
            pr.lower, pr.upper, pr.free, pr.pstar, pr.Rstar, pr.w_p, pr.w_ax, self.relax, self.order,
            tol_pos, tol_rot, pr.check_pos, pr.check_rot, budget, self.eps_q, self.window, self.window_rel,
            self.accel_m, self.X, self.G, self.state, self.trace,
        )

    def solve(self, q, tol_pos, tol_rot, deadline, bypass: Bypass, max_events: int) -> Status:
        self.q = q
        policy = bypass.resolved_policy()
        while True:
            budget = min(CHUNK, self.max_sweeps - self.sweeps)
            if budget <= 0:
                return Status.MAX_ITERATIONS
            code, _ = self._kernel(self.q, budget, tol_pos, tol_rot)
            if code == kernel.CONVERGED:
                return Status.CONVERGED
            if code == kernel.BUDGET:
                if time.perf_counter() > deadline:
                    return Status.TIME_BUDGET
                continue
            diagnosis = self._event(code)
            if len(self.bypass_log) >= max_events or self.next_bypass >= len(policy):
                return Status.SINGULAR if diagnosis == "singular" else Status.STALLED
            step = policy[self.next_bypass]
            if step == "auto_kick" and diagnosis != "singular":
                return Status.STALLED  # a kick does not leave a local minimum; a restart does
            self.next_bypass += 1
            self.q = self.apply(bypass, step, self.q)
            self.reset_history()
            # leaving a singularity starts slowly (the kick grows by a factor per sweep): judge it patiently
            self.window, self.window_rel = max(self.window, 100), min(self.window_rel, 1e-6)
            self.max_sweeps = max(self.max_sweeps, self.sweeps + 1000)

    def _event(self, code: int) -> str:
        sigma = _scaled_sigma_min(self.robot, self.q, self.vm.length)
        diagnosis = "singular" if sigma < SINGULAR_SIGMA else "stationary"
        oMtool = self.robot.fk(self.q)
        self.events.append({
            "sweep": self.sweeps,
            "trigger": "step" if code == kernel.STALL_STEP else "window",
            "diagnosis": diagnosis,
            "sigma_min": sigma,
            "position_error": float(np.linalg.norm(oMtool.translation - self.prob.pstar)),
            "rotation_error": float(np.linalg.norm(pin.log3(self.prob.Rstar.T @ oMtool.rotation))),
            "q": self.q.tolist(),
        })
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
            scale = np.where(self.vm.kind == kernel.PRISMATIC, self.vm.length, 1.0)
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
            self.state[6] = 1.0  # the joints nearest the base act first on the kicked chain
        self.bypass_log.append({"sweep": self.sweeps, "bypass": step, "q": q.tolist()})
        return q


FAST_PATH_BLOCKERS = ("kicks", "intervals", "freeze", "policy", "active", "polish", "trace")


def fast_path_allowed(options: dict) -> bool:
    """The compiled multistart serves a solve that names no bypass, policy, polish or trace (naming one,
    even empty, asks for the monitor's diagnosis and log, which the Python loop keeps)."""
    return not any(name in options for name in FAST_PATH_BLOCKERS)


class _Settings(NamedTuple):
    """A multistart's options, parsed and checked once per distinct set of options."""

    mode: str
    plain: bool
    order: str
    relax: float
    max_sweeps: int
    window: int
    window_rel: float
    accel_m: int
    eps_q: float
    w_p: float | None
    w_p_factor: float
    w_ax: np.ndarray
    check_pos: bool
    check_rot: bool
    use_limits: bool


@functools.lru_cache(maxsize=64)
def _settings(items: tuple) -> _Settings:
    options = dict(items)
    mode, accel = options.get("mode", "pose"), options.get("accel", "anderson")
    order, relax = options.get("order", "mixed"), float(options.get("relax", 1.0))
    _validate(mode, order, accel, relax)
    plain = accel == "none"
    max_sweeps, window, window_rel = _monitor_defaults(
        plain, options.get("max_sweeps"), options.get("stall_window"), options.get("stall_rel"))
    return _Settings(
        mode, plain, order, relax, max_sweeps, window, window_rel,
        0 if plain else int(options.get("accel_memory", 5)), float(options.get("eps_q", 1e-10)),
        options.get("w_p"), float(options.get("w_p_factor", W_P_FACTOR)),
        _axis_weights(mode, options.get("w_axes", (1.0, 1.0, 1.0))), mode != "orientation", mode != "position",
        bool(options.get("use_limits", True)),
    )


def _parsed(options: dict) -> _Settings:
    try:
        return _settings(tuple(sorted(options.items())))
    except TypeError:  # an unhashable option value (a list of weights): parse without the cache
        return _settings.__wrapped__(tuple(sorted(options.items())))


def multistart(
    robot: Robot, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float, deadline: float,
    seed: int | None, max_restarts: int, **options,
) -> tuple[Attempt, int]:
    """FRDM from q0 and then from seeded random starts, all inside the compiled kernel (a stall is answered
    by a restart: with no bypass configured that is what the monitor's policy does for a local minimum).
    Returns the attempt kept and the number of restarts. The caller checks the answer with Pinocchio."""
    st = _parsed(options)
    vm = vector_model(robot)
    w_p = _position_weight(vm, st.mode, st.w_p, st.w_p_factor)
    if st.use_limits:
        lower, upper = vm.lower, vm.upper
    else:
        lower, upper = np.full(vm.n, -np.inf), np.full(vm.n, np.inf)
    pstar, Rstar = oMtarget.translation, oMtarget.rotation  # fresh arrays from pinocchio
    rng_state = restarts.seed_state(seed)
    q = np.array(q0, dtype=float)
    best_q = q.copy()
    stats = np.zeros(5)
    order = ORDERS[st.order]
    free = _all_free(vm.n)

    def chunk(attempts_left: int) -> int:
        return kernel.multistart(
            q, vm.placement_R, vm.placement_t, vm.axis_local, vm.kind, vm.tool_R, vm.tool_t, lower, upper, free,
            pstar, Rstar, w_p, st.w_ax, st.relax, order, tol_pos, tol_rot, st.check_pos, st.check_rot,
            st.max_sweeps, st.eps_q, st.window, st.window_rel, st.accel_m, rng_state, attempts_left,
            stats[1] + CHUNK * 32, best_q, stats,
        )

    code = restarts.run_in_chunks(chunk, max_restarts + 1, stats, deadline, kernel.CONVERGED)
    if code == kernel.CONVERGED:
        status = Status.CONVERGED
    elif time.perf_counter() > deadline:
        status = Status.TIME_BUDGET
    else:
        status = Status.STALLED if stats[2] > 0 else Status.MAX_ITERATIONS
    info = {"mode": "frdm" + (" (plain)" if st.plain else ""), "sweeps": int(stats[1]),
            "accelerated_sweeps": int(stats[3]), "order": st.order, "w_p": w_p,
            "objective": float(stats[4]), "attempts": int(stats[0]), "stalls": int(stats[2]), "path": "compiled"}
    events = [{"trigger": "stall", "diagnosis": "not diagnosed (compiled multistart: restarted)",
               "count": int(stats[2])}] if stats[2] else []
    return Attempt(robot.wrap_continuous(best_q), status, int(stats[1]), events, [], info), max(0, int(stats[0]) - 1)
