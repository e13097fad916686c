"""FRDM's options: every default written once, every value checked once (docs/methods.md §1.5–1.6)."""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinelab.errors import OptionError
from kinelab.ik import options as opt
from kinelab.ik.frdm import kernel
from kinelab.ik.tasks import Task

ORDERS = {"tip2base": kernel.TIP_TO_BASE, "base2tip": kernel.BASE_TO_TIP, "alternate": kernel.ALTERNATE,
          "mixed": kernel.MIXED}
MODES = ("pose", "position", "axis", "orientation")
ACCELERATIONS = ("anderson", "none")
FINISHES = ("newton", "none")
BYPASSES = ("kicks", "intervals", "freeze", "auto_kick")
# Defaults measured on panda, ur5, stanford and era (docs/bench): w_p = 3/L², a 10-sweep stall window.
W_P_FACTOR = 3.0
STALL_WINDOW = 10
PLAIN_STALL_WINDOW = 50
MAX_ACCEL_MEMORY = 50  # sweeps Anderson acceleration may remember (each costs a column in its least squares)


@dataclass(frozen=True)
class FRDMOptions:
    """Options of one FRDM solve.

    Attributes:
        mode: "pose", "position" (tool point only), "axis" (tool point and the tool axis ``tool_axis``, the
            roll about it free) or "orientation" (tool axes only).
        tool_axis: the axis of mode "axis": "x", "y" or "z".
        w_p: position weight [1/m²]; None: ``w_p_factor``/L² with L the chain's characteristic length
            (scale-aware: the same factor serves a 0.3 m arm and the 11 m ERA), a third of it in mode "axis"
            (one tool axis weighed against the point instead of three).
        w_p_factor: the dimensionless factor of the default w_p.
        w_axes: weights of the tool x, y, z axes (≥ 0, three numbers).
        order: "tip2base", "base2tip", "alternate" (each way in turn) or "mixed" (base → tip here; in the
            compiled multistart, base → tip and tip → base on alternate restarts: the two directions fall
            into different local minima).
        relax: step = relax × the exact optimum, 0 < relax < 2 (still never increases the objective).
        accel: "anderson" (safeguarded extrapolation of the sweep map) or "none" (plain FRDM).
        accel_memory: Anderson memory (sweeps), ≥ 1.
        max_sweeps: sweep cap of one attempt; None: 100 accelerated, 3000 plain.
        eps_q: Σ|Δq| over a sweep below this is a stall [rad or m].
        stall_window: sweeps over which the objective must fall by ``stall_rel``; None: 10 accelerated,
            50 plain.
        stall_rel: relative fall required over the window; None: 0.1 accelerated, 1e-3 plain.
        use_limits: keep every step within the joint limits.
        kicks: joint → signed δ [rad or m] added when the monitor fires.
        intervals: joint → (lower, upper), a tighter window held while active.
        freeze: joint → value (None: where the joint is) held while active.
        policy: the order in which monitor events switch bypasses on (None: those configured, in the
            order kicks, intervals, freeze; "auto_kick" when none is).
        active: bypasses switched on before the first sweep.
        max_bypass_events: how many monitor events the policy answers before the attempt gives up.
        polish: follow FRDM with damped-least-squares steps (reported as mode "frdm+polish").
        stall_polish: Gauss–Newton steps the compiled multistart tries on a stalled attempt before its
            restart (:mod:`~kinelab.ik.frdm.attempts`; 0: the paper's FRDM alone).
        finish: "newton" (the default): once FRDM's objective falls below ``finish_below``, damped
            Gauss–Newton steps with the analytic Jacobian finish the attempt (quadratic convergence where
            FRDM's is linear; tried once per attempt, and if they fall short the sweeps go on from where they
            were); "none": the paper's FRDM, sweeps only (``kinelab validate`` checks this one).
        finish_below: the objective E below which the finish starts (dimensionless; with the default weights
            1e-3 is about 2 % of the arm's length and 0.02 rad away).
        finish_steps: Gauss–Newton steps of the finish, ≥ 1.
        trace: keep the objective after every sweep in ``diagnostics.trace``.
    """

    mode: str = "pose"
    tool_axis: str = "z"
    w_p: float | None = None
    w_p_factor: float = W_P_FACTOR
    w_axes: tuple[float, float, float] = (1.0, 1.0, 1.0)
    order: str = "mixed"
    relax: float = 1.0
    accel: str = "anderson"
    accel_memory: int = 5
    max_sweeps: int | None = None
    eps_q: float = 1e-10
    stall_window: int | None = None
    stall_rel: float | None = None
    use_limits: bool = True
    kicks: dict[str, float] | None = None
    intervals: dict[str, tuple[float, float]] | None = None
    freeze: dict[str, float | None] | None = None
    policy: tuple[str, ...] | None = None
    active: tuple[str, ...] | None = None
    max_bypass_events: int = 3
    polish: bool = False
    stall_polish: int = 10
    finish: str = "newton"
    finish_below: float = 1e-3
    finish_steps: int = 8
    trace: bool = False

    def __hash__(self) -> int:  # computed once: solve() looks its compiled context up by these options
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = hash(tuple(_hashable(getattr(self, f.name)) for f in dataclasses.fields(self)))
            object.__setattr__(self, "_hash", cached)
        return cached

    def __post_init__(self) -> None:
        opt.choice("mode", self.mode, MODES, what="FRDM mode")
        opt.choice("order", self.order, tuple(ORDERS), what="sweep order")
        opt.choice("tool_axis", self.tool_axis, ("x", "y", "z"), what="tool axis")
        opt.choice("accel", self.accel, ACCELERATIONS, what="acceleration")
        opt.choice("finish", self.finish, FINISHES, what="finish")
        opt.positive("finish_below", self.finish_below)
        opt.positive("finish_steps", self.finish_steps, integer=True)
        opt.positive("w_p", self.w_p, allow_none=True)
        opt.positive("w_p_factor", self.w_p_factor)
        opt.positive("eps_q", self.eps_q)
        opt.positive("accel_memory", self.accel_memory, integer=True)
        if self.accel_memory > MAX_ACCEL_MEMORY:  # a longer memory only costs: every solve then ran out of sweeps
            raise OptionError("accel_memory", self.accel_memory, f"an integer from 1 to {MAX_ACCEL_MEMORY} (sweeps "
                              "Anderson acceleration remembers; 5 is the default)")
        opt.positive("max_sweeps", self.max_sweeps, allow_none=True, integer=True)
        opt.positive("stall_window", self.stall_window, allow_none=True, integer=True)
        opt.positive("stall_rel", self.stall_rel, allow_none=True)
        opt.positive("max_bypass_events", self.max_bypass_events, integer=True, zero=True)
        opt.positive("stall_polish", self.stall_polish, integer=True, zero=True)
        for name in ("use_limits", "polish", "trace"):
            opt.flag(name, getattr(self, name))
        opt.positive("relax", self.relax)
        if not float(self.relax) < 2.0:
            raise OptionError("relax", self.relax, "a number in (0, 2)")
        self._check_weights()
        self._check_bypass_tables()

    def _check_weights(self) -> None:
        try:
            w = np.asarray(self.w_axes, dtype=float)
        except (TypeError, ValueError):
            w = np.full(1, np.nan)
        if w.shape != (3,) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise OptionError("w_axes", self.w_axes, "three finite weights ≥ 0 (tool x, y, z axes)")
        object.__setattr__(self, "w_axes", tuple(float(x) for x in w))

    def _check_bypass_tables(self) -> None:
        for name in ("kicks", "intervals", "freeze"):
            table = getattr(self, name)
            if table is not None and not isinstance(table, dict):
                raise OptionError(name, table, "a dict joint name → value")
        _check_entries("kicks", self.kicks, _nonzero_finite, "a finite non-zero δ per joint [rad or m]")
        _check_entries("intervals", self.intervals, _interval, "a non-empty (lower, upper) per joint",
                       "bypass interval for {name!r} is empty or malformed: {value!r}")
        _check_entries("freeze", self.freeze, _held_value,
                       "a finite value per joint [rad or m], or None (where the joint is)")
        for name in ("policy", "active"):
            steps = getattr(self, name)
            if steps is not None:
                object.__setattr__(self, name, _bypass_steps(name, steps))

    @classmethod
    def of(cls, options: FRDMOptions | None = None, **kwargs: object) -> FRDMOptions:
        """``options`` as given, or built from keyword arguments (cached for hashable ones)."""
        return opt.resolve(cls, "frdm", options, kwargs)

    # -- resolved values --------------------------------------------------------------------
    @property
    def plain(self) -> bool:
        """No acceleration: every change is an exact FRDM step."""
        return self.accel == "none"

    @property
    def label(self) -> str:
        """The solver's mode as results report it: "frdm", "frdm+newton", with " (plain)" without acceleration."""
        return "frdm" + ("+newton" if self.finish == "newton" else "") + (" (plain)" if self.plain else "")

    @property
    def sweep_cap(self) -> int:
        """Sweeps allowed in one attempt."""
        return int(self.max_sweeps or (3000 if self.plain else 100))

    @property
    def window(self) -> int:
        """The monitor's stall window [sweeps]."""
        return int(self.stall_window or (PLAIN_STALL_WINDOW if self.plain else STALL_WINDOW))

    @property
    def window_rel(self) -> float:
        """Relative fall of the objective required over the window."""
        return (1e-3 if self.plain else 0.1) if self.stall_rel is None else float(self.stall_rel)

    @property
    def accel_m(self) -> int:
        """Anderson memory used by the kernel (0: plain)."""
        return 0 if self.plain else int(self.accel_memory)

    @functools.cached_property
    def compiled(self) -> bool:
        """True when the compiled multistart can serve these options: no bypass, policy, polish or trace
        named (naming one, even empty, asks for the monitor's diagnosis and log, kept by the Python loop)."""
        return (self.kicks is None and self.intervals is None and self.freeze is None and self.policy is None
                and self.active is None and not self.polish and not self.trace)

    @functools.cached_property
    def _settings(self) -> kernel.Settings:
        return kernel.Settings(float(self.relax), float(self.eps_q), int(self.window), float(self.window_rel),
                               int(self.accel_m), int(self.stall_polish),
                               float(self.finish_below) if self.finish == "newton" else 0.0, int(self.finish_steps))

    def settings(self) -> kernel.Settings:
        """The kernel's sweep and monitor settings (an immutable tuple, built once)."""
        return self._settings

    def position_weight(self, length: float) -> float:
        """w_p [1/m²] for a chain of characteristic length ``length`` [m]; 0 in orientation mode."""
        if self.mode == "orientation":
            return 0.0
        if self.w_p is not None:
            return float(self.w_p)
        # mode "axis" weighs one tool axis against the point where "pose" weighs three: the same balance
        share = 1.0 / 3.0 if self.mode == "axis" else 1.0
        return share * float(self.w_p_factor) / float(length) ** 2

    @property
    def rot_axis(self) -> int:
        """The kernel's rotation check: the tool axis index in mode "axis", −1 (the whole rotation) otherwise."""
        return "xyz".index(self.tool_axis) if self.mode == "axis" else -1

    def for_task(self, task: Task) -> FRDMOptions:
        """These options for a :class:`~kinelab.ik.tasks.Task` (FRDM's modes are its tasks), cached."""
        if task.name == "pose":
            return self
        cached = self._task_options.get(task)  # a loop asks every call: hashing these options costs µs
        if cached is None:
            cached = self._task_options[task] = _for_task(self, task)
        return cached

    @functools.cached_property
    def _task_options(self) -> dict:
        return {}

    def axis_weights(self) -> np.ndarray:
        """Weights of the tool x, y, z axes; 0 in position mode (a shared read-only array)."""
        return self._axis_weights

    @functools.cached_property
    def _axis_weights(self) -> np.ndarray:
        w = np.zeros(3) if self.mode == "position" else np.array(self.w_axes, dtype=float)
        if self.mode == "axis":  # one tool axis pulled onto the target's: the roll about it is free
            w = np.where(np.arange(3) == self.rot_axis, w, 0.0)
        w.flags.writeable = False
        return w


@functools.lru_cache(maxsize=64)
def _for_task(opts: FRDMOptions, task: Task) -> FRDMOptions:
    return dataclasses.replace(opts, mode=task.name, tool_axis="xyz"[task.axis] if task.axis >= 0 else opts.tool_axis)


def _hashable(value: object) -> object:
    """A bypass table (a dict joint → value) as a sorted tuple of items; anything else as it is."""
    if isinstance(value, dict):
        return tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in value.items()))
    return value


def _check_entries(option: str, table: dict[str, Any] | None, ok: Any, valid: str, message: str | None = None) -> None:
    """Refuse the first entry of a bypass table that ``ok`` rejects (``message`` formatted with its name and value,
    or the usual one naming the option)."""
    for name, value in (table or {}).items():
        if not ok(value):
            raise OptionError(option, {name: value}, valid,
                              None if message is None else message.format(name=name, value=value))


def _held_value(value: object) -> bool:
    """A frozen joint's value: a finite real [rad or m], or None (where the joint is)."""
    return value is None or (isinstance(value, numbers.Real) and not isinstance(value, bool)
                             and math.isfinite(value))


def _nonzero_finite(value: object) -> bool:
    return (not isinstance(value, bool) and isinstance(value, numbers.Real) and math.isfinite(value)
            and value != 0)


def _interval(window: object) -> bool:
    if not (isinstance(window, (tuple, list)) and len(window) == 2):
        return False
    lo, hi = window
    return isinstance(lo, numbers.Real) and isinstance(hi, numbers.Real) and float(lo) < float(hi)


def _bypass_steps(name: str, steps: object) -> tuple[str, ...]:
    """``steps`` as a tuple of known bypass names, or OptionError naming the first unknown one."""
    bad = [steps] if isinstance(steps, str) or not isinstance(steps, (tuple, list)) else [
        s for s in steps if s not in BYPASSES]
    if bad:
        raise OptionError(name, steps, ", ".join(BYPASSES),
                          f"unknown bypass {bad[0]!r} in {name}; bypasses are: {', '.join(BYPASSES)}")
    return tuple(steps)  # type: ignore[arg-type]
