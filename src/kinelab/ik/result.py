"""IKResult and Status: what every kinelab IK solver returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np


class Status(str, Enum):
    """Why a solve ended. Only ``converged`` goes with success, and only after Pinocchio's check."""

    CONVERGED = "converged"
    UNREACHABLE = "unreachable"  # the target is out of the workspace (proved, or every start agreed)
    SINGULAR = "singular"  # stopped at a kinematic singularity with the target not reached
    STALLED = "stalled"  # stopped at a stationary point (local minimum, joint limit) short of the target
    MAX_ITERATIONS = "max_iterations"
    TIME_BUDGET = "time_budget"


@dataclass
class IKResult:
    """The outcome of :func:`kinelab.solve`.

    ``position_error`` [m] and ``rotation_error`` [rad] are measured by Pinocchio's FK of the returned
    ``q`` against the target. ``success`` is true only when both are within tolerance and ``q`` is
    within the joint limits. ``q`` is one number per joint (rad, m) in the robot's joint order.
    """

    q: np.ndarray
    success: bool
    status: Status
    position_error: float
    rotation_error: float
    iterations: int
    restarts: int
    wall_time: float  # [s]
    solver: str
    mode: str = ""  # which variant produced the figures, e.g. "frdm (anderson)", "frdm+polish"
    singular_events: list[dict] = field(default_factory=list)
    bypasses: list[dict] = field(default_factory=list)
    message: str = ""
    info: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "q": np.asarray(self.q).tolist(),
            "success": self.success,
            "status": self.status.value,
            "position_error_m": self.position_error,
            "rotation_error_rad": self.rotation_error,
            "iterations": self.iterations,
            "restarts": self.restarts,
            "wall_time_s": self.wall_time,
            "solver": self.solver,
            "mode": self.mode,
            "singular_events": self.singular_events,
            "bypasses": self.bypasses,
            "message": self.message,
            "info": {k: v for k, v in self.info.items() if _jsonable(v)},
        }


def _jsonable(value) -> bool:
    return isinstance(value, (int, float, str, bool, list, dict)) or value is None


@dataclass
class Attempt:
    """One solver run from one start, before kinelab's Pinocchio check (internal to ``solve``)."""

    q: np.ndarray
    status: Status
    iterations: int
    events: list[dict] = field(default_factory=list)
    bypasses: list[dict] = field(default_factory=list)
    info: dict = field(default_factory=dict)
