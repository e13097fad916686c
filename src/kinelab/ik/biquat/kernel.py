"""The biquaternion solver's default preset (compiled: :mod:`kinelab.core._biquat`): law (9), Euler with h·k = 1
and a joint-step cap, the Cauchy problem q̇ = A⁻¹U integrated on the shared chain FK, with seeded restarts.

The Python integrators (:mod:`kinelab.ik.biquat.integrators`) are the reference and call the same laws
(:mod:`kinelab.ik.biquat.laws`); tests hold the two paths equal.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from kinelab.core._biquat import run_integrate as integrate
from kinelab.core._biquat import run_timed as timed
from kinelab.core._frdm import Code

# the preset's return codes: the compiled kernels' one table, as ints
CONVERGED, SINGULAR, MAX_STEPS = int(Code.CONVERGED), int(Code.SINGULAR), int(Code.MAX_STEPS)
OUTSIDE_LIMITS, BUDGET = int(Code.OUTSIDE_LIMITS), int(Code.BUDGET)
# slots of a multistart's statistics array
T_ATTEMPTS, T_STEPS, T_MODEL_TIME, T_OUTSIDE, T_SINGULAR, T_CUT, T_ATTEMPT_STEPS, T_ATTEMPT_TIME = range(8)
STATS_SIZE = 8

__all__ = ["Control", "integrate", "timed"]


class Control(NamedTuple):
    """The target and the preset's settings."""

    pstar: np.ndarray  # (3,) target point [m], base frame
    Rstar: np.ndarray  # (3, 3) target rotation
    k: float  # gain [1/s]
    h: float  # step [s]
    max_step: float  # largest joint change per step [rad or m]
    max_steps: int  # steps per attempt
    eps_rot: float  # stop when |m⃗| < eps_rot (half the rotation tolerance)
    eps_dual: float  # and |m0⃗| < eps_dual (half the position tolerance) [m]
    damping: float  # λ of the damped pseudo-inverse (0: exact solve when n = 6)
