"""The step's quadratic program: minimize ½ vᵀHv + fᵀv subject to lower ≤ v ≤ upper and A_eq v = b_eq.

DAQP (a dual active-set solver for small dense problems) by default: on the step's problems — tens of variables,
box bounds and a few equalities — it answers in microseconds and exactly at the bounds it makes active, which the
limits need (docs/wholebody.md, the solver measured against ProxQP). ProxQP (proxsuite, Pinocchio's family) is the
other choice.
"""

from __future__ import annotations

import importlib
from ctypes import c_int
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinelab.errors import KinelabError

SOLVERS = ("daqp", "proxsuite")
BIG = 1e30  # DAQP's infinity: bounds beyond it are none
EQUALITY, FREE = 5, 0  # DAQP's constraint senses
DAQP_STATUS = {1: "solved", 2: "solved", -1: "infeasible", -2: "cycling", -3: "unbounded", -4: "iteration limit",
               -5: "not convex", -6: "initial active set infeasible"}


@dataclass(frozen=True)
class Solution:
    """The QP's answer: v (NaN when it failed), its status in words, and whether it is solved."""

    v: np.ndarray
    status: str
    solved: bool
    iterations: int


def solve(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
          b_eq: np.ndarray | None, solver: str = "daqp") -> Solution:
    """Solve the step's QP (see the module's docstring).

    Raises:
        KinelabError: the solver is not installed (with the install hint).
    """
    if solver == "proxsuite":
        return _proxsuite(H, f, lower, upper, A_eq, b_eq)
    return _daqp(H, f, lower, upper, A_eq, b_eq)


def _daqp(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
          b_eq: np.ndarray | None) -> Solution:
    daqp = _import("daqp")
    n = H.shape[0]
    m = 0 if A_eq is None else A_eq.shape[0]
    A = np.zeros((0, n)) if A_eq is None else A_eq
    up = np.concatenate([np.minimum(upper, BIG), [] if b_eq is None else b_eq])
    lo = np.concatenate([np.maximum(lower, -BIG), [] if b_eq is None else b_eq])
    sense = np.zeros(n + m, dtype=c_int)
    sense[n:] = EQUALITY
    x, _, flag, info = daqp.solve(H, f, A, up, lo, sense)
    solved = flag in (1, 2)
    x = np.clip(np.asarray(x, dtype=float), lower, upper)  # its bounds hold to its tolerance (1e-7): exactly here
    return Solution(x if solved else np.full(n, np.nan), DAQP_STATUS.get(flag, str(flag)), solved,
                    int(info.get("iterations", 0)) if isinstance(info, dict) else 0)


def _proxsuite(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
               b_eq: np.ndarray | None) -> Solution:
    proxsuite = _import("proxsuite")
    n = H.shape[0]
    m = 0 if A_eq is None else A_eq.shape[0]
    qp = proxsuite.proxqp.dense.QP(n, m, 0, True)
    qp.settings.eps_abs = 1e-10
    qp.settings.verbose = False
    qp.init(H, f, A_eq, b_eq, None, None, None, np.maximum(lower, -BIG), np.minimum(upper, BIG))
    qp.solve()
    status = str(qp.results.info.status).rsplit(".", 1)[-1].lower()
    solved = "solved" in status
    x = np.clip(np.asarray(qp.results.x, dtype=float), lower, upper)  # its bounds hold to its tolerance: exact here
    return Solution(x if solved else np.full(n, np.nan), status, solved, int(qp.results.info.iter))


def _import(name: str) -> Any:
    try:
        return importlib.import_module(name)
    except ImportError:
        raise KinelabError(f"the whole-body step's QP solver {name!r} is not installed: pip install {name}") from None
