"""The biquaternion solver's options: every default written once, every value checked once."""

from __future__ import annotations

import functools
from dataclasses import dataclass

from kinelab.dq.algebra import DualQuat
from kinelab.errors import OptionError
from kinelab.ik import options as opt

LAWS = ("simple", "regular")
INTEGRATORS = ("euler", "rk4", "adaptive")
MAX_STEPS = 20000  # step cap of the paper's fixed-step runs
NEWTON_MAX_STEPS = 30  # a converging newton-preset run takes 10–25 steps; a longer one crawls past a singularity
MAX_MODEL_TIME = 1e6  # [s] of model time; the paper's run takes about 14 s
MAX_GAIN = 1e6  # [1/s] larger gains only make the step h = 1/k vanish (and the law overflow)
NEWTON_MAX_STEP = 0.5  # [rad or m] joint-step cap of the newton preset


@dataclass(frozen=True)
class BiquatOptions:
    """Options of one biquaternion-control solve (docs/methods.md §2).

    Attributes:
        law: "simple" (9)/(16) or "regular" (11)/(12).
        k: real part of the dual gain K = k + s k0 [1/s]; None: 1.
        k0: dual part of the gain [1/s].
        k_v: a separate real gain for the moment part (simple law, the paper's (16)) [1/s].
        integrator: "euler", "rk4" or "adaptive" (scipy's RK45 with a terminal event).
        step: the fixed step h [s]; None: 1/k, the newton preset (locally one Gauss–Newton step per step);
            the paper uses 0.01.
        max_time: model-time limit [s]; None: 100/k (compiled preset: ceil(max_time·k) steps).
        damping: λ of the damped pseudo-inverse; None: 0 for n = 6, 1e-4 otherwise.
        max_step: largest joint change per fixed step [rad or m]; None: 0.5 with the newton preset, no cap
            when ``step`` is given (as in the paper).
        max_steps: step cap of one attempt; None: 30 with the newton preset, 20000 otherwise.
        clamp: after each Euler step, wrap revolute joints by 2π and clip q into the limits; None: off.
        target_biquaternion: N itself, when the sign of the target matters; it must be the target's pose.
        record: keep the trajectory (t, q, M*, U) in ``diagnostics.trajectory``.
    """

    law: str = "simple"
    k: float | None = None
    k0: float = 0.0
    k_v: float | None = None
    integrator: str = "euler"
    step: float | None = None
    max_time: float | None = None
    damping: float | None = None
    max_step: float | None = None
    max_steps: int | None = None
    clamp: bool | None = None
    target_biquaternion: DualQuat | None = None
    record: bool = False

    def __post_init__(self) -> None:
        opt.choice("law", self.law, LAWS, what="law")
        opt.choice("integrator", self.integrator, INTEGRATORS)
        opt.positive("k", self.k, allow_none=True)
        opt.finite("k0", self.k0)
        opt.positive("k_v", self.k_v, allow_none=True)
        for name in ("k", "k0", "k_v"):
            value = getattr(self, name)
            if value is not None and abs(float(value)) > MAX_GAIN:
                raise OptionError(name, value, f"a gain of at most {MAX_GAIN:g} 1/s in size")
        opt.positive("step", self.step, allow_none=True)
        opt.positive("max_time", self.max_time, allow_none=True)
        if self.max_time is not None and float(self.max_time) > MAX_MODEL_TIME:
            raise OptionError("max_time", self.max_time, f"a model time of at most {MAX_MODEL_TIME:g} s")
        opt.positive("damping", self.damping, allow_none=True, zero=True)
        opt.positive("max_step", self.max_step, allow_none=True)
        opt.positive("max_steps", self.max_steps, allow_none=True, integer=True)
        opt.flag("clamp", self.clamp, allow_none=True)
        opt.flag("record", self.record)
        if self.target_biquaternion is not None and not isinstance(self.target_biquaternion, DualQuat):
            raise OptionError("target_biquaternion", self.target_biquaternion, "a unit DualQuat or None")

    @classmethod
    def of(cls, options: BiquatOptions | None = None, **kwargs: object) -> BiquatOptions:
        """``options`` as given, or built from keyword arguments (cached for hashable ones)."""
        return opt.resolve(cls, "biquat", options, kwargs)

    # -- resolved values --------------------------------------------------------------------
    @property
    def gain(self) -> float:
        """k [1/s]."""
        return 1.0 if self.k is None else float(self.k)

    @property
    def newton(self) -> bool:
        """The newton preset: h = 1/k."""
        return self.step is None

    @property
    def h(self) -> float:
        """The fixed step [s]."""
        return 1.0 / self.gain if self.newton else float(self.step)  # type: ignore[arg-type]

    @property
    def step_cap(self) -> float | None:
        """Largest joint change per step [rad or m], or None."""
        if self.max_step is not None:
            return float(self.max_step)
        return NEWTON_MAX_STEP if self.newton else None

    @property
    def steps_cap(self) -> int:
        """Steps allowed in one attempt."""
        if self.max_steps is not None:
            return int(self.max_steps)
        return NEWTON_MAX_STEPS if self.newton else MAX_STEPS

    @property
    def model_time(self) -> float:
        """Model-time limit [s]."""
        return 100.0 / self.gain if self.max_time is None else float(self.max_time)

    def damping_for(self, n: int) -> float:
        """λ of the pseudo-inverse for an n-joint chain."""
        return (0.0 if n == 6 else 1e-4) if self.damping is None else float(self.damping)

    @functools.cached_property
    def compiled(self) -> bool:
        """True when the compiled preset serves these options: law (9), newton Euler, k0 = 0, no
        moment gain, step caps and clamp at their defaults, no trajectory and no given N."""
        return (self.law == "simple" and self.integrator == "euler" and self.step is None and self.k0 == 0.0
                and self.k_v is None and self.max_step is None and self.max_steps is None and not self.clamp
                and self.target_biquaternion is None and not self.record)
