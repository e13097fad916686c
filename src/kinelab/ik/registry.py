"""The solvers by name: the built-in ones imported on first use, and those a user registers."""

from __future__ import annotations

import importlib
from typing import Any, Protocol

import numpy as np
import pinocchio as pin

from kinelab.errors import SolverNotFoundError
from kinelab.ik.result import Attempt
from kinelab.robot import Robot

BUILTIN = {"frdm": "kinelab.ik.frdm.solver", "biquat": "kinelab.ik.biquat.solver", "dls": "kinelab.ik.dls"}
SOLVERS: dict[str, Any] = {}


class SolverModule(Protocol):
    """What a solver provides: an options class with ``of(options, **kwargs)``, and ``attempt``; optionally
    ``prepare(robot, options)`` (compilation of what those options run, outside the timed region) and a compiled
    ``multistart``."""

    Options: Any

    def attempt(self, robot: Robot, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float,
                deadline: float, options: Any = None) -> Attempt:
        """One run from ``q0`` towards ``oMtarget``, before kinelab's Pinocchio check."""


def register(name: str, module: Any) -> None:
    """Make a solver module (see :class:`SolverModule`) available as ``solve(..., solver=name)``.

    Args:
        name: the solver's name.
        module: a module or object with ``Options`` and ``attempt``.
    """
    SOLVERS[name] = module


def names() -> list[str]:
    """Every solver name, built-in first, each once."""
    return list(dict.fromkeys([*BUILTIN, *SOLVERS]))


def solver_module(name: str) -> Any:
    """The module of solver ``name``, imported on first use.

    Raises:
        SolverNotFoundError: an unknown name (the valid ones listed).
    """
    module = SOLVERS.get(name) if isinstance(name, str) else None
    if module is None:
        if not isinstance(name, str) or name not in BUILTIN:
            raise SolverNotFoundError(str(name), [*names(), "analytic"])  # the closed form: by the entry points
        module = SOLVERS[name] = importlib.import_module(BUILTIN[name])
    return module
