"""What a prepared solver hands its one-call engine (:mod:`kinelab.core._engine`), and why an engine declines a call.

:class:`EngineSpec` is the part every engine reads (the checks' bounds, the reach bound, the budget, the verdict's
tolerances, the converged result's shared fields, and ``unmet``, which builds any other outcome's result as the
general route does); :class:`FRDMSpec` and :class:`BiquatSpec` add their kernel's settings. Built once per prepared
solver by :func:`kinelab.ik.driver.engine_spec`. :class:`Decline` names the codes ``Engine.solve`` answers for a
call it leaves to the general route.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

import numpy as np

from kinelab.core import _engine


class Decline(IntEnum):
    """Why an engine leaves a call to the general route (which names what is wrong, or serves it)."""

    TARGET = _engine.DECLINE_TARGET  # not a pin.SE3, not a proper pose, or beyond the reach bound
    START = _engine.DECLINE_START  # q0 is not n real numbers
    OUTSIDE = _engine.DECLINE_OUTSIDE  # q0 lies outside the limits
    SEED = _engine.DECLINE_SEED  # not a whole number in [0, 2^64)
    EMPTY = _engine.DECLINE_EMPTY  # a chain without joints


@dataclass(frozen=True, eq=False)
class EngineSpec:
    """What every engine reads from its prepared solver.

    Attributes:
        kind: (n,) the joints' kinds (the kernel's codes).
        draw_lower, draw_upper: (n,) the window random starts are drawn in [rad or m].
        check_lower, check_upper: (n,) the limits a start and an answer must lie within [rad or m].
        turn_lower, turn_upper: (n,) the limits a whole turn brings a revolute answer into [rad].
        anchor: (3,) the reach bound's centre in the base frame [m].
        radius: the reach bound's radius [m] (inf: none).
        attempts: the first attempt and the restarts.
        budget: the kernel's share of the call's time budget [s] (inf: none).
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad].
        check_pos, check_rot: whether the verdict checks the position, the rotation.
        axis: -1, or the tool axis (0, 1, 2) of task "axis".
        pstar, Rstar: (3,) and (3, 3) the arrays a call's target is copied into (the kernel reads them).
        wrap_continuous: continuous joints of an answer wrapped into (−π, π] before the verdict.
        se3: the target type of a usual call (``pin.SE3``).
        result: the result type.
        fields: the values every converged result shares.
        diagnostics: statistics → the result's diagnostics (called when they are first read).
        unmet: the general result of any other outcome: ``unmet(target, code, q, stats, position error, rotation
            error, met, t_start, deadline, seed)``.
    """

    kind: np.ndarray
    draw_lower: np.ndarray
    draw_upper: np.ndarray
    check_lower: np.ndarray
    check_upper: np.ndarray
    turn_lower: np.ndarray
    turn_upper: np.ndarray
    anchor: np.ndarray
    radius: float
    attempts: int
    budget: float
    tol_pos: float
    tol_rot: float
    check_pos: bool
    check_rot: bool
    axis: int
    pstar: np.ndarray
    Rstar: np.ndarray
    wrap_continuous: bool
    se3: type
    result: type
    fields: dict[str, Any]
    diagnostics: Callable[[np.ndarray], Any]
    unmet: Callable[..., Any]


@dataclass(frozen=True, eq=False)
class FRDMSpec(EngineSpec):
    """:class:`EngineSpec` and compiled FRDM's timed multistart: ``order`` (the sweep order's code), ``cap`` (sweeps
    per attempt), ``first_chunk``, ``later_chunk`` (sweeps before the first look at the clock and between two),
    ``stall_events`` (stalls → the result's events)."""

    order: int
    cap: int
    first_chunk: float
    later_chunk: float
    stall_events: Callable[[int], list[Any]]


@dataclass(frozen=True, eq=False)
class BiquatSpec(EngineSpec):
    """:class:`EngineSpec` and the biquaternion preset's control: ``k`` [1/s], ``max_step`` [rad or m], ``max_steps``,
    ``eps_rot`` [rad], ``eps_dual`` [m], ``damping``; ``first_chunk``, ``later_chunk`` (steps before the first look
    at the clock and between two); ``wide`` (n,) the base joints whose restart window follows the target; ``length``
    [m] the chain's length."""

    k: float
    max_step: float
    max_steps: int
    eps_rot: float
    eps_dual: float
    damping: float
    first_chunk: int
    later_chunk: int
    wide: np.ndarray
    length: float
