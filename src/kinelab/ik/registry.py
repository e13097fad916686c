"""The solvers by name: the built-in ones imported on first use, and those a user registers; and what each can do
(:class:`Capabilities`), which the entry points read instead of comparing names."""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError, SolverNotFoundError
from kinelab.ik.result import Attempt
from kinelab.robot import Chain

if TYPE_CHECKING:
    from kinelab.ik.biquat.options import BiquatOptions
    from kinelab.ik.dls import DLSOptions
    from kinelab.ik.frdm.options import FRDMOptions

SolverOptions: TypeAlias = "FRDMOptions | BiquatOptions | DLSOptions | None"
"""A solver's options object, taken as it is (None: the solver's defaults under the keywords given)."""

BUILTIN = {"frdm": "kinelab.ik.frdm.solver", "biquat": "kinelab.ik.biquat.solver", "dls": "kinelab.ik.dls"}
SOLVERS: dict[str, Any] = {}


@dataclass(frozen=True)
class Capabilities:
    """What a solver can do, as the entry points (``solve``, ``solve_batch``, ``solve_all``, ``track``, ``IK``, the
    CLI) read it.

    Attributes:
        closed_form: its answers come from the chain's closed form (docs/analytic.md): every branch, no options and
            no restarts; a chain without one is refused by name.
        picks: the closed form where the chain has one and the task is "pose", else the multistart of ``runs``.
        runs: the solver whose request (tolerances, task, options) a closed-form or picking solver's call is
            built with; None: itself.
        stands_in: with no options, ``solve(prefer=)`` may take every branch from the closed form for it.
        compiled: options with ``compiled`` set run the threaded compiled batch of FRDM's kernel (a solve's one
            compiled call is the module's: its ``engine``).
        follows_paths: ``track`` follows a path with it (warm-started sweeps).
        monitored: its results carry the singularity monitor's events and bypasses.
    """

    closed_form: bool = False
    picks: bool = False
    runs: str | None = None
    stands_in: bool = False
    compiled: bool = False
    follows_paths: bool = False
    monitored: bool = False

    def request_solver(self, name: str) -> str:
        """The solver whose request a call with solver ``name`` is built with."""
        return self.runs or name


BUILTIN_CAPABILITIES = {
    "frdm": Capabilities(stands_in=True, compiled=True, follows_paths=True, monitored=True),
    "biquat": Capabilities(),
    "dls": Capabilities(),
    "analytic": Capabilities(closed_form=True, runs="frdm"),
    "auto": Capabilities(picks=True, runs="frdm"),
}
CAPABILITIES: dict[str, Capabilities] = {}


class SolverModule(Protocol):
    """What a solver provides: an options class with ``of(options, **kwargs)``, and ``attempt``; optionally
    ``prepare(robot, options)`` (compilation of what those options run, outside the timed region), a compiled
    ``multistart`` (the general route's restarts in one kernel call) and ``engine(robot, request)`` (the prepared
    solver's one-call engine, :class:`kinelab.core._engine.Engine`, or None where the general route must serve)."""

    Options: Any

    def attempt(self, robot: Chain, oMtarget: pin.SE3, q0: np.ndarray, tol_pos: float, tol_rot: float,
                deadline: float, options: SolverOptions = None) -> Attempt:
        """One run from ``q0`` towards ``oMtarget``, before kinelab's Pinocchio check."""


def register(name: str, module: SolverModule, capabilities: Capabilities | None = None) -> None:
    """Make a solver module (see :class:`SolverModule`) available as ``solve(..., solver=name)``.

    Args:
        name: the solver's name.
        module: a module or object with ``Options`` and ``attempt``.
        capabilities: what it can do beyond one answer at a time through kinelab's driver (default: nothing).
    """
    SOLVERS[name] = module
    CAPABILITIES[name] = capabilities or Capabilities()


def capabilities(name: str) -> Capabilities:
    """What solver ``name`` can do.

    Raises:
        SolverNotFoundError: an unknown name (the valid ones listed).
    """
    found = CAPABILITIES.get(name) if isinstance(name, str) else None
    if found is None:
        found = BUILTIN_CAPABILITIES.get(name) if isinstance(name, str) else None
    if found is None:
        raise SolverNotFoundError(str(name), [*names(), "analytic", "auto"])
    return found


def one_answer(name: str) -> Capabilities:
    """What solver ``name`` can do, for an entry point that answers one target at a time (``solve``,
    ``solve_batch``): a picking solver ("auto") chooses among every branch, which is ``solve_all``'s.

    Raises:
        SolverNotFoundError: an unknown or picking name (the valid ones listed).
    """
    kind = capabilities(name)
    if kind.picks:
        raise SolverNotFoundError(str(name), [*names(), "analytic"],
                                  "chooses among every branch of a pose, which is solve_all's work "
                                  "(kinelab.solve_all, kinelab branches); for one answer name the solver")
    return kind


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
            raise SolverNotFoundError(str(name), [*names(), "analytic", "auto"])  # routes the entry points take
        module = SOLVERS[name] = importlib.import_module(BUILTIN[name])
    return module


def refuse_options(options: SolverOptions | dict[str, object]) -> None:
    """The closed form has no settings: options given with solver="analytic" are refused by name.

    Raises:
        OptionError: ``options`` (an options object or option keywords) is not empty.
    """
    if options:
        raise OptionError("options", options, "none with solver='analytic' (the closed form has no settings)")
