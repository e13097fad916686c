"""The step's quadratic program: minimize ½ vᵀHv + fᵀv subject to lower ≤ v ≤ upper, A_eq v = b_eq and
A_in v ≥ b_in (the collision rows, :mod:`kinelab.wholebody.clearance`).

DAQP (a dual active-set solver for small dense problems) by default: on the step's problems — tens of variables,
box bounds and a few equalities — it answers in microseconds and exactly at the bounds it makes active, which the
limits need (docs/wholebody.md, the solver measured against ProxQP). ProxQP (proxsuite, Pinocchio's family) is the
other choice, and answers where DAQP's active set cycles (many nearly equal rows) when it is installed.
"""

from __future__ import annotations

import importlib
import importlib.util
from ctypes import c_int
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

import numpy as np

from kinelab.errors import KinelabError

SOLVERS = ("daqp", "proxsuite")
BIG = 1e30  # DAQP's infinity: bounds beyond it are none
EQUALITY, FREE = 5, 0  # DAQP's constraint senses


class Outcome(IntEnum):
    """A QP's or a compiled step's outcome code: DAQP's exit flags, and the compiled step's own two."""

    SOLVED = 1
    SOLVED_SOFT = 2  # DAQP: optimal with soft constraints relaxed (none are: as solved)
    INFEASIBLE = -1
    CYCLING = -2
    UNBOUNDED = -3
    ITERATION_LIMIT = -4
    NOT_CONVEX = -5
    INITIAL_ACTIVE_SET_INFEASIBLE = -6
    NOT_A_CONFIGURATION = -100  # the compiled step: a q it does not take (the readable step names why)
    NOT_FINITE = -101  # the answer overflowed, nothing moved

    @property
    def solved(self) -> bool:
        """Whether v and q are the step's answer."""
        return self in (Outcome.SOLVED, Outcome.SOLVED_SOFT)

    @property
    def words(self) -> str:
        """The status in words, as results say it."""
        return "solved" if self.solved else self.name.lower().replace("_", " ")


DAQP_STATUS = {int(o): o.words for o in Outcome if o >= Outcome.INITIAL_ACTIVE_SET_INFEASIBLE}  # DAQP's own flags


@dataclass(frozen=True)
class Solution:
    """The QP's answer: v (NaN when it failed), its status in words, and whether it is solved."""

    v: np.ndarray
    status: str
    solved: bool
    iterations: int


CYCLING = Outcome.CYCLING.words  # DAQP's active set cycles on many degenerate rows (two grippers pressed together:
# 60 collision rows of rank 12): ProxQP, where installed, answers those
MAX_ITERATIONS = 10_000  # each solver's iteration bound: the step's QPs take tens, a call never runs unbounded
NOT_FINITE = Outcome.NOT_FINITE.words  # the status of an answer that overflowed (nothing moved)


@dataclass(frozen=True)
class Inequalities:
    """Rows A v ≥ b of the step's QP (A: (m, nv); b: (m,))."""

    A: np.ndarray
    b: np.ndarray


def solve(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
          b_eq: np.ndarray | None, solver: str = "daqp", dt: float = 1.0,
          inequalities: Inequalities | None = None) -> Solution:
    """Solve the step's QP (see the module's docstring) for v. ProxQP is given the problem in x = v·dt (the same
    minimiser, the objective times dt²): its absolute tolerances then meet numbers the size of the motion whatever
    dt (in v it ran to its iteration bound below dt ≈ 1e-8). DAQP takes v as it is: its active set is exact at the
    bounds it makes active, and its own absolute tolerances suit rates (in x they let it stop on a worse active set
    at a common dt of 10 ms, measured).

    Raises:
        KinelabError: the solver is not installed (with the install hint).
    """
    if solver != "proxsuite":
        found = _daqp(H, f, lower, upper, A_eq, b_eq, inequalities)
        v = found.v
        if found.status == CYCLING and importlib.util.find_spec("proxsuite") is not None:
            return solve(H, f, lower, upper, A_eq, b_eq, "proxsuite", dt, inequalities)  # degenerate rows
    else:
        scaled = None if inequalities is None else Inequalities(inequalities.A, inequalities.b * dt)
        found = _proxsuite(H, f * dt, lower * dt, upper * dt, A_eq, None if b_eq is None else b_eq * dt, scaled)
        v = found.v / dt
    if not found.solved:
        return found
    if not np.isfinite(v).all():
        return Solution(np.full(v.shape, np.nan), NOT_FINITE, False, found.iterations)
    return Solution(np.clip(v, lower, upper), found.status, True, found.iterations)


def _daqp(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
          b_eq: np.ndarray | None, inequalities: Inequalities | None = None) -> Solution:
    daqp = _import("daqp")
    n = H.shape[0]
    m = 0 if A_eq is None else A_eq.shape[0]
    A = np.zeros((0, n)) if A_eq is None else A_eq
    up = np.concatenate([np.minimum(upper, BIG), [] if b_eq is None else b_eq])
    lo = np.concatenate([np.maximum(lower, -BIG), [] if b_eq is None else b_eq])
    if inequalities is not None:
        A = np.vstack([A, inequalities.A])
        up = np.concatenate([up, np.full(inequalities.b.shape[0], BIG)])
        lo = np.concatenate([lo, inequalities.b])
    sense = np.zeros(A.shape[0] + n, dtype=c_int)
    sense[n:n + m] = EQUALITY
    x, _, flag, info = daqp.solve(H, f, A, up, lo, sense, iter_limit=MAX_ITERATIONS)
    solved = flag in (1, 2)
    x = np.clip(np.asarray(x, dtype=float), lower, upper)  # its bounds hold to its tolerance (1e-7): exactly here
    return Solution(x if solved else np.full(n, np.nan), DAQP_STATUS.get(flag, str(flag)), solved,
                    int(info.get("iterations", 0)) if isinstance(info, dict) else 0)


def _proxsuite(H: np.ndarray, f: np.ndarray, lower: np.ndarray, upper: np.ndarray, A_eq: np.ndarray | None,
               b_eq: np.ndarray | None, inequalities: Inequalities | None = None) -> Solution:
    proxsuite = _import("proxsuite")
    n = H.shape[0]
    m = 0 if A_eq is None else A_eq.shape[0]
    k = 0 if inequalities is None else inequalities.b.shape[0]
    qp = proxsuite.proxqp.dense.QP(n, m, k, True)
    qp.settings.eps_abs = 1e-10
    qp.settings.max_iter = MAX_ITERATIONS
    qp.settings.max_iter_in = MAX_ITERATIONS
    qp.settings.verbose = False
    C, low, high = (None, None, None) if inequalities is None else (
        inequalities.A, inequalities.b, np.full(k, BIG))
    qp.init(H, f, A_eq, b_eq, C, low, high, np.maximum(lower, -BIG), np.minimum(upper, BIG))
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
