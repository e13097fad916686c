"""Limits a whole-body step holds exactly: joint positions, velocities, accelerations — bounds on the step's
velocity v [nv], so that q ⊕ v·dt stays within every bounded joint's limits and |v| within the velocity limits —
and the inequalities it holds as rows (collisions, a user's own).

:class:`JointLimits` is the joints' limits as an inequality of the step's protocol
(:class:`~kinelab.wholebody.constraints.Inequality`) whose rows are single velocities: the QP holds them as its
bounds, and the compiled step packs them. :class:`Limits` gathers what one step holds.

A start outside its position limits is brought back at the velocity limit (at once where there is none): the
bounds of that joint are moved to ask for the return, never made infeasible; the step says which joints
(``StepResult.returning``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from kinelab.errors import OptionError
from kinelab.robot.space import LIMIT_SLACK, Space
from kinelab.values import is_real, mixes_non_reals
from kinelab.wholebody.constraints import Held, Inequality

if TYPE_CHECKING:
    from kinelab.robot.tree import Robot


@dataclass(frozen=True)
class JointLimits(Inequality):
    """The joints' limits as bounds on the step's v (:func:`bounds`): an inequality whose rows are single
    velocities, held by the QP as its bounds (both steps; the compiled step packs them).

    Attributes:
        position, velocity, acceleration: as :class:`Limits`' (checked the same way).
    """

    position: bool = True
    velocity: Any = True
    acceleration: Any = None
    bounded: ClassVar[bool] = True
    compiled: ClassVar[bool] = True

    def __post_init__(self) -> None:
        """Check every field.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        if not isinstance(self.position, bool):
            raise OptionError("position", self.position, "True or False")
        _check_rate("velocity", self.velocity)
        _check_rate("acceleration", self.acceleration)
        if self.acceleration is True:
            raise OptionError("acceleration", True, "None, a number > 0 or one per velocity (no file gives them)")

    @property
    def label(self) -> str:
        """The inequality in words."""
        held = [name for name, on in (("positions", self.position), ("velocities", self.velocity not in (None, False)),
                                      ("accelerations", self.acceleration is not None)) if on]
        return "joint limits (" + (", ".join(held) or "none") + ")"

    def bounds(self, robot: Robot, q: np.ndarray, dt: float, v_prev: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lower, upper) on v [nv] and the joints being brought back into their limits (:func:`bounds`)."""
        return bounds(robot.space, q, dt, velocity_bounds(self, robot.space), self.position,
                      acceleration_bounds(self, robot.space), v_prev)

    def rows(self, robot: Robot, q: np.ndarray, dt: float) -> Held:
        """Its bounds as rows, ``v_i ≥ lower_i`` and ``−v_i ≥ −upper_i`` for every finite bound (no velocity before
        the step: without the acceleration band)."""
        lower, upper, _ = self.bounds(robot, q, dt, None)
        eye = np.eye(robot.nv)
        low, high = np.isfinite(lower), np.isfinite(upper)
        return Held(np.vstack([eye[low], -eye[high]]), np.concatenate([lower[low], -upper[high]]))

    def breaks(self, robot: Robot, held: Held, q_next: np.ndarray) -> bool:
        """Never after a step that held its bounds (q ⊕ v·dt is linear in v on every bounded joint)."""
        return False

    def slack(self, robot: Robot, q: np.ndarray) -> float:
        """The least distance of a bounded joint inside its position limits [rad or m] (< 0: past one by that
        much, beyond LIMIT_SLACK; inf without position limits)."""
        space = robot.space
        if not self.position or not space.bounded_q.any():
            return float("inf")
        qb = q[space.bounded_q]
        inside = np.minimum(qb - space.lower[space.bounded_q], space.upper[space.bounded_q] - qb) + LIMIT_SLACK
        return float(np.min(inside))


@dataclass(frozen=True)
class Limits:
    """What the step holds (all exactly, at every step).

    Attributes:
        position: hold each bounded joint within its position limits.
        velocity: True: the file's velocity limits (where it gives them); False or None: none; a number: that
            limit [rad/s or m/s] on every joint but a free-flyer's; (nv,) numbers: one per velocity.
        acceleration: None (none), a number or (nv,) numbers [rad/s² or m/s²]: |v − v_prev| ≤ a·dt, where the
            step is given the velocity before it.
        collisions: None (none), or what :class:`kinelab.Collisions` takes — ``"self"``, an ``Environment`` or a
            ``Collisions(self_collisions=, environment=, margin=, detection=, gain=)``: every pair nearer than
            margin + detection held apart by one row of the QP (:mod:`kinelab.wholebody.clearance`).
        inequalities: more inequalities the step holds (as rows of its QP, or as bounds where they are
            ``bounded``) and the solve at its answer, any :class:`~kinelab.wholebody.constraints.Inequality` (a
            tuple; docs/extending.md).
        joints: (derived) the first three as a :class:`JointLimits`; compiled: (derived) whether the compiled step
            holds all of it (nothing beyond the joints' limits).
    """

    position: bool = True
    velocity: Any = True
    acceleration: Any = None
    collisions: Any = None
    inequalities: Any = ()
    joints: JointLimits = field(init=False, repr=False, compare=False)  # the joints' limits, an inequality of the step
    compiled: bool = field(init=False, repr=False, compare=False)  # the compiled step holds all of it (joints only)
    _boxes: tuple[Inequality, ...] = field(init=False, repr=False, compare=False)
    _rows: tuple[Inequality, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Check every field (the joints' three through :class:`JointLimits`), and sort the inequalities once into
        bounds and rows.

        Raises:
            OptionError: a field out of what it accepts (named).
        """
        object.__setattr__(self, "joints", JointLimits(self.position, self.velocity, self.acceleration))
        _check_inequalities(self.inequalities)
        given = tuple(self.inequalities)
        object.__setattr__(self, "inequalities", given)
        rows = tuple(i for i in given if not i.bounded)
        if self.collisions is not None:  # the collision module (coal's geometry) loaded only when asked for
            from kinelab.collision.model import as_collisions
            from kinelab.wholebody.clearance import Clearance

            object.__setattr__(self, "collisions", as_collisions(self.collisions))
            rows = (Clearance(self.collisions), *rows)
        object.__setattr__(self, "_boxes", (self.joints, *(i for i in given if i.bounded)))
        object.__setattr__(self, "_rows", rows)
        object.__setattr__(self, "compiled", self.collisions is None and all(i.compiled for i in given))

    def boxes(self) -> tuple[Inequality, ...]:
        """Every inequality held as bounds on v: the joints' limits first, then the bounded ones given."""
        return self._boxes

    def held(self) -> tuple[Inequality, ...]:
        """Every inequality held as rows (the collisions' first), beyond the bounds on v."""
        return self._rows


def _check_inequalities(value: Any) -> None:
    """A tuple or list of :class:`Inequality` values.

    Raises:
        OptionError: anything else.
    """
    if not isinstance(value, tuple | list) or not all(isinstance(i, Inequality) for i in value):
        raise OptionError("inequalities", value, "a tuple of kinelab.wholebody.Inequality values (or ())")


def _check_rate(name: str, value: Any) -> None:
    """A rate limit is True, False, None, a number > 0 or one per velocity (real numbers: no NaN, no booleans, no
    complex numbers)."""
    if value is None or isinstance(value, bool):
        return
    arr = _real(value)
    if arr is None or arr.ndim > 1 or not (np.all(arr > 0) and not np.any(np.isnan(arr))):
        raise OptionError(name, value, "True, False, None, a number > 0 or one per velocity (real numbers)")


def _real(value: Any) -> np.ndarray | None:
    """``value`` as a float array when it is real numbers (integers or floats), else None."""
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        return None
    return arr.astype(float) if arr.dtype.kind in "iuf" and not mixes_non_reals(value) else None


def velocity_bounds(limits: Limits | JointLimits, space: Space) -> np.ndarray:
    """(nv,) the velocity limit of each velocity [rad/s or m/s] (inf where none).

    Raises:
        OptionError: per-velocity limits of another length.
    """
    given = limits.velocity
    if given is True:
        return space.velocity
    if given is None or given is False:
        return np.full(space.nv, np.inf)
    arr = np.asarray(given, dtype=float)
    if arr.ndim == 0:
        out = np.full(space.nv, float(arr))
        if space.floating:
            out[:6] = np.inf
        return out
    if arr.shape != (space.nv,):
        raise OptionError("velocity", given, f"a number, or nv = {space.nv} numbers")
    return arr


def acceleration_bounds(limits: Limits | JointLimits, space: Space) -> np.ndarray | None:
    """(nv,) the acceleration limit of each velocity, or None.

    Raises:
        OptionError: per-velocity limits of another length.
    """
    given = limits.acceleration
    if given is None or given is False:
        return None
    arr = np.asarray(given, dtype=float)
    if arr.ndim == 0:
        return np.full(space.nv, float(arr))
    if arr.shape != (space.nv,):
        raise OptionError("acceleration", given, f"a number, or nv = {space.nv} numbers")
    return arr


def bounds(space: Space, q: np.ndarray, dt: float, vmax: np.ndarray, position: bool, amax: np.ndarray | None,
           v_prev: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lower, upper) on v [nv] and the joints brought back into their limits (a bool per velocity).

    Args:
        space: the robot's joint space.
        q: the configuration (Pinocchio's q).
        dt: the step [s].
        vmax: velocity limits (inf: none).
        position: hold position limits.
        amax: acceleration limits, or None.
        v_prev: the velocity before the step (needed with amax).
    """
    lo, hi = -vmax.copy(), vmax.copy()
    returning = np.zeros(space.nv, dtype=bool)
    if position:
        qb = q[space.bounded_q]
        pl = (space.lower[space.bounded_q] - qb) / dt
        pu = (space.upper[space.bounded_q] - qb) / dt
        idx = np.flatnonzero(space.bounded_v)
        vl, vu = lo[idx], hi[idx]
        slack = LIMIT_SLACK / dt  # a joint at its limit to rounding is not outside it
        below, above = pl > slack, pu < -slack  # outside its limits: only a return is allowed, at most at the limit
        new_lo = np.where(below, np.minimum(pl, vu), np.maximum(pl, vl))
        new_hi = np.where(above, np.maximum(pu, vl), np.minimum(pu, vu))
        if amax is not None:  # no faster than it can still stop before the limit, braking at amax
            a = amax[idx]
            inside = ~(below | above)
            new_hi = np.where(inside, np.minimum(new_hi, braking(pu * dt, a, dt)), new_hi)
            new_lo = np.where(inside, np.maximum(new_lo, -braking(-pl * dt, a, dt)), new_lo)
        lo[idx], hi[idx] = new_lo, new_hi
        returning[idx] = below | above
    if amax is not None and v_prev is not None:  # the acceleration yields where it cannot keep within the others
        a_lo, a_hi = v_prev - amax * dt, v_prev + amax * dt
        below, above = a_hi < lo, a_lo > hi  # its whole band beyond what the positions and velocities allow
        lo, hi = (np.where(below, lo, np.where(above, hi, np.maximum(lo, a_lo))),
                  np.where(below, lo, np.where(above, hi, np.minimum(hi, a_hi))))
    return lo, hi, returning


MIN_DT = 1e-9  # [s] a shorter step asks for rates (error / dt) past any joint's and toward what a double holds


def braking(distance: np.ndarray, amax: np.ndarray, dt: float) -> np.ndarray:
    """The largest speed [rad/s or m/s] toward a limit ``distance`` away [rad or m] from which steps of ``dt``
    braking at ``amax`` still stop before it: v·dt + v²/(2a) ≤ d (inf where there is no acceleration limit). At
    that speed the next step's bound, and the position's (d − v·dt)/dt, are both at least v − a·dt: the
    acceleration and position limits can hold together at every later step."""
    with np.errstate(invalid="ignore", over="ignore"):
        ad = amax * dt
        speed = -ad + np.sqrt(ad * ad + 2.0 * amax * np.maximum(distance, 0.0))
    return np.where(np.isfinite(amax), speed, np.inf)


def is_positive_time(dt: object) -> float:
    """``dt`` [s] as a float ≥ MIN_DT.

    Raises:
        OptionError: anything else.
    """
    if type(dt) is float and MIN_DT <= dt < math.inf:  # the usual call, checked at once
        return dt
    if not is_real(dt, MIN_DT):
        raise OptionError("dt", dt, f"a finite time ≥ {MIN_DT:g} s")
    return float(dt)


def checked_v_prev(v_prev: object, nv: int) -> np.ndarray:
    """The velocity before a step as nv finite floats [rad/s or m/s].

    Raises:
        OptionError: another shape, NaN/inf, or not real numbers (named).
    """
    arr = _real(v_prev)
    if arr is None or arr.shape != (nv,) or not np.isfinite(arr).all():
        raise OptionError("v_prev", v_prev, f"the velocity before the step: nv = {nv} finite numbers")
    return np.ascontiguousarray(arr)
