"""The configuration space of a whole Pinocchio model: q (nq numbers, Pinocchio's own: a free-flyer as position and
unit quaternion (x, y, z, w), a continuous joint as (cos, sin)), velocities (nv numbers), their limits, sampling,
and the arithmetic between them through ``pin.integrate`` and ``pin.difference``.

Limits. Position limits hold for the 1-DoF revolute and prismatic joints (one q entry, one velocity each); a
free-flyer, a continuous, spherical or planar joint has none. Velocity limits are the file's (``<limit
velocity=...>``) where it gives a positive finite one; none elsewhere (a free-flyer's six).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.errors import ConfigurationError, DescriptionError, JointLimitError, OptionError, count_of
from kinelab.values import mixes_non_reals

LIMIT_SLACK = 1e-9  # joint values this far past a limit still count as within it (rad or m)
MAX_COORDINATE = 1e6  # [m or rad] a coordinate beyond it is no configuration (a base 1000 km away, say)
SAMPLE_TURNS = 4  # random configurations keep unbounded revolute joints within ±4 turns
UNBOUNDED = 1e300  # a limit beyond this is no limit (Pinocchio writes ±DBL_MAX for a free-flyer's)
MAX_SAMPLE_BYTES = 8 * 2**30  # the most memory one random_qs call fills


@dataclass(frozen=True, eq=False)
class Space:
    """The joint space of a Pinocchio model, built once by :func:`space_of`.

    Attributes:
        nq, nv: sizes of q and of a velocity.
        lower, upper: (nq,) position limits [rad or m] where bounded (``bounded_q``), ±inf elsewhere.
        bounded_q: (nq,) the q entries with position limits; bounded_v: (nv,) the same joints' velocity entries
            (a bounded joint has one q entry and one velocity, in the same order).
        velocity: (nv,) velocity limits [rad/s or m/s], inf where the file gives none.
        names_q: (nq,) a name per q entry ("joint", or "root_joint.qw" for a multi-entry joint's parts).
        names_v: (nv,) a name per velocity entry.
        floating: the model's first joint is a free-flyer (its base moves with q[:7], v[:6]).
    """

    nq: int
    nv: int
    lower: np.ndarray
    upper: np.ndarray
    bounded_q: np.ndarray
    bounded_v: np.ndarray
    velocity: np.ndarray
    names_q: tuple[str, ...]
    names_v: tuple[str, ...]
    floating: bool


LOCKED = ("a robot's joint limits are read when it is built: edit a copy (model = pinocchio.Model(robot.model)) and "
          "build the robot from it (kinelab.Robot.from_model(model), or kinelab.Chain.from_model(model, tool=...))")


def _read_only(name: str) -> property:
    """A property of :class:`FixedLimitsModel` serving pin.Model's ``name`` read-only and refusing assignment."""
    vector = getattr(pin.Model, name)

    def get(self: pin.Model) -> np.ndarray:
        view = vector.fget(self)
        view.flags.writeable = False
        return view

    def refuse(self: pin.Model, value: object) -> None:
        raise DescriptionError(LOCKED)

    return property(get, refuse, doc=f"pin.Model's {name}, read-only (the robot's limits are fixed when it is built)")


class FixedLimitsModel(pin.Model):
    """The Pinocchio model a robot holds: a ``pin.Model`` (every Pinocchio function takes it) whose joint limits
    cannot change, so that no step or solve answers within limits other than the model's (an edit of them was
    silently ignored: kinelab reads them once, when the robot is built)."""

    __slots__ = ()
    lowerPositionLimit = _read_only("lowerPositionLimit")
    upperPositionLimit = _read_only("upperPositionLimit")
    velocityLimit = _read_only("velocityLimit")
    effortLimit = _read_only("effortLimit")


def fixed_limits(model: pin.Model) -> FixedLimitsModel:
    """A copy of ``model`` whose joint limits cannot change (the model itself if it is one already)."""
    return model if isinstance(model, FixedLimitsModel) else FixedLimitsModel(model)


def space_of(model: pin.Model) -> Space:
    """The :class:`Space` of ``model``."""
    bounded_q, bounded_v = np.zeros(model.nq, dtype=bool), np.zeros(model.nv, dtype=bool)
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        if joint.nq == 1 and joint.nv == 1 and joint.shortname() != "JointModelMimic":
            bounded_q[joint.idx_q], bounded_v[joint.idx_v] = True, True
    names_q, names_v = _coordinate_names(model)
    lower = np.where(bounded_q, model.lowerPositionLimit, -np.inf)
    upper = np.where(bounded_q, model.upperPositionLimit, np.inf)
    lower[bounded_q & (lower < -UNBOUNDED)], upper[bounded_q & (upper > UNBOUNDED)] = -np.inf, np.inf
    velocity = np.asarray(model.velocityLimit, dtype=float).copy()
    velocity[~np.isfinite(velocity) | (velocity <= 0) | (velocity > UNBOUNDED)] = np.inf
    floating = model.njoints > 1 and model.joints[1].shortname() == "JointModelFreeFlyer"
    if floating:
        velocity[:6] = np.inf
    for arr in (lower, upper, velocity, bounded_q, bounded_v):
        arr.flags.writeable = False
    return Space(model.nq, model.nv, lower, upper, bounded_q, bounded_v, velocity, tuple(names_q), tuple(names_v),
                 floating)


def _coordinate_names(model: pin.Model) -> tuple[list[str], list[str]]:
    """The names of q's and v's coordinates: a 1-coordinate joint's name, else ``name.k`` per coordinate."""
    names_q: list[str] = []
    names_v: list[str] = []
    for jid in range(1, model.njoints):
        joint, name = model.joints[jid], model.names[jid]
        names_q += [name] if joint.nq == 1 else [f"{name}.{k}" for k in range(joint.nq)]
        names_v += [name] if joint.nv == 1 else [f"{name}.{k}" for k in range(joint.nv)]
    return names_q, names_v


def check_q(space: Space, model: pin.Model, q: ArrayLike, *, limits: bool = False, what: str = "q") -> np.ndarray:
    """``q`` as nq finite floats (Pinocchio's q), its quaternions unit and, with ``limits``, its bounded joints
    within their limits.

    Raises:
        ConfigurationError: another shape, a non-real type, NaN/inf, a quaternion not of unit norm (1e-6).
        JointLimitError: with ``limits``, a bounded joint outside its limits (named).
    """
    arr = _q_numbers(space, q, what)
    bad = np.flatnonzero(~(np.abs(arr) <= MAX_COORDINATE))
    if bad.size:
        raise ConfigurationError(f"{what}[{bad[0]}] ({space.names_q[bad[0]]}) is {arr[bad[0]]}: values must be finite "
                                 f"and within ±{MAX_COORDINATE:g} (m or rad)")
    if not pin.isNormalized(model, arr, 1e-6):
        raise ConfigurationError(f"{what}: a quaternion (a free-flyer's or a spherical joint's) or a continuous "
                                 "joint's (cos, sin) is not of unit norm (within 1e-6)")
    if limits:
        outside = np.flatnonzero((arr < space.lower - LIMIT_SLACK) | (arr > space.upper + LIMIT_SLACK))
        if outside.size:
            i = int(outside[0])
            raise JointLimitError(space.names_q[i], float(arr[i]), float(space.lower[i]), float(space.upper[i]))
    return arr


def _q_numbers(space: Space, q: ArrayLike, what: str) -> np.ndarray:
    """``q`` as nq contiguous floats (real numbers only: no bool, complex or text, in arrays or lists).

    Raises:
        ConfigurationError: anything else, or another shape (named).
    """
    try:
        raw = np.asarray(q)
        if raw.dtype.kind not in "fiu" or mixes_non_reals(q):
            raise TypeError
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be {space.nq} numbers (Pinocchio's q), got {q!r}") from None
    if raw.shape != (space.nq,):
        raise ConfigurationError(f"{what} must have nq = {space.nq} numbers (Pinocchio's q: "
                                 f"{', '.join(space.names_q[:8])}{', ...' if space.nq > 8 else ''}), "
                                 f"got {raw.shape[0] if raw.ndim == 1 else 'shape ' + str(raw.shape)}")
    return np.ascontiguousarray(raw, dtype=float)


def check_v(space: Space, v: ArrayLike, what: str = "v") -> np.ndarray:
    """``v`` as nv finite floats (a velocity, or a displacement over 1 s).

    Raises:
        ConfigurationError: another shape, a non-real type, NaN or inf.
    """
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be {space.nv} numbers (velocities), got {v!r}") from None
    if arr.shape != (space.nv,) or not np.isfinite(arr).all():
        raise ConfigurationError(f"{what} must be nv = {space.nv} finite numbers, got {count_of(arr.shape)}")
    return np.ascontiguousarray(arr)


def within_limits(space: Space, q: np.ndarray, slack: float = LIMIT_SLACK) -> bool:
    """True when every bounded joint of Pinocchio's q lies within its limits (plus ``slack``)."""
    return bool(np.all(q >= space.lower - slack) and np.all(q <= space.upper + slack))


def random_q(space: Space, model: pin.Model, rng: np.random.Generator) -> np.ndarray:
    """A uniform random configuration: bounded joints within their limits, unbounded revolute ones within
    ±SAMPLE_TURNS turns, a free-flyer at the origin with a uniformly random orientation, other multi-entry joints
    (continuous, spherical) at uniformly random angles."""
    q = pin.neutral(model)
    lo = np.where(space.bounded_q, space.lower, -SAMPLE_TURNS * 2 * np.pi)
    hi = np.where(space.bounded_q, space.upper, SAMPLE_TURNS * 2 * np.pi)
    lo, hi = np.maximum(lo, -SAMPLE_TURNS * 2 * np.pi * 1e3), np.minimum(hi, SAMPLE_TURNS * 2 * np.pi * 1e3)
    drawn = rng.uniform(np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0))
    q[space.bounded_q] = drawn[space.bounded_q]
    v = rng.normal(size=space.nv)
    if space.floating:
        v[:3] = 0.0  # the base at the origin, turned at random
    moved = pin.integrate(model, q, np.where(space.bounded_v, 0.0, v))
    moved[space.bounded_q] = q[space.bounded_q]
    return np.asarray(moved, dtype=float)


def generator(rng: object) -> np.random.Generator:
    """A numpy Generator from what sampling accepts: None, a whole number ≥ 0, or a Generator.

    Raises:
        OptionError: anything else (named).
    """
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (isinstance(rng, int | np.integer) and not isinstance(rng, bool) and rng >= 0):
        return np.random.default_rng(rng)
    raise OptionError("rng", rng, "None, a whole number ≥ 0 (a seed) or a numpy Generator")


def spread_points(count: int, dims: int) -> np.ndarray:
    """``count`` points of [-1, 1)^dims spread evenly and deterministically (the additive recurrence of the
    generalised golden ratio, Roberts' R-sequence): the same every time, without importing ``numpy.random``
    (a few milliseconds of every command's start-up).

    Args:
        count: how many points (rows).
        dims: the dimension (columns), ≥ 1.

    Returns:
        A (count, dims) array.
    """
    phi = 2.0
    for _ in range(40):  # the real root of x^(dims+1) = x + 1, by fixed-point iteration
        phi = (1.0 + phi) ** (1.0 / (dims + 1))
    alpha = phi ** -np.arange(1.0, dims + 1.0)
    return 2.0 * np.mod(0.5 + np.outer(np.arange(1.0, count + 1.0), alpha), 1.0) - 1.0


def uniform(rng: np.random.Generator, lower: np.ndarray, upper: np.ndarray,
            size: int | tuple[int, ...] | None) -> np.ndarray:
    """Uniform draws between lower and upper, also where upper − lower overflows (a prismatic joint declared with
    ±1e308 m: numpy's uniform refuses that range)."""
    if (upper / 2 - lower / 2 < 0.5 * np.finfo(float).max).all():  # the width fits a float
        drawn: np.ndarray = rng.uniform(lower, upper, size)
        return drawn
    u = rng.random(size if size is not None else lower.shape)
    return np.asarray(lower * (1.0 - u) + upper * u)
