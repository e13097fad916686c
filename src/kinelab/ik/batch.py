"""``solve_batch``: IK for many targets in one call, every answer checked by Pinocchio.

Row b is the answer :func:`kinelab.solve` gives for ``targets[b]`` alone with ``seed = seed + b`` and
start ``q0[b]`` (or none), when neither runs out of time. FRDM with compiled options runs the rows in
parallel inside one kernel (every core, OpenMP threads; the answers do not depend on the thread
count); the other solvers and FRDM's monitored options run ``solve`` row by row on one core.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab import lazy
from kinelab.core import _blas, threads
from kinelab.errors import ConfigurationError, count_of
from kinelab.geometry import stack_homogeneous
from kinelab.ik.driver import prepare_solver, solve_one
from kinelab.ik.frdm import batch as frdm_batch
from kinelab.ik.frdm.batch import Rows
from kinelab.ik.limits import wrap_q
from kinelab.ik.multistart import seed_states
from kinelab.ik.registry import capabilities
from kinelab.ik.request import Request
from kinelab.ik.result import Status, status_counts
from kinelab.ik.targets import as_target_arrays, reach_bound
from kinelab.robot import Chain
from kinelab.typing import Configuration, Targets

if TYPE_CHECKING:
    from kinelab.ik import starts as starts_module
else:
    starts_module = lazy.module("kinelab.ik.starts", globals())

# [s] kept out of the solvers' share of a budget: Pinocchio's FK and error per row (about 7 µs on a busy 2-core
# machine), and the fixed cost of a call's arrays and thread start
VERDICT_SECONDS_PER_ROW = 1e-5
CALL_SECONDS = 3e-4


@dataclass
class BatchIKResult:
    """The outcome of :func:`solve_batch`: one row per target.

    Attributes:
        q: (B, n) answers [rad or m] (NaN in rows the time budget left unsolved).
        success: (B,) Pinocchio confirms both tolerances within the joint limits.
        status_code: (B,) int8 codes of :class:`~kinelab.ik.result.Status` (``status`` gives the members).
        position_error: (B,) [m]; rotation_error: (B,) [rad] (Pinocchio's FK against the target).
        iterations: (B,) sweeps (FRDM) or the solver's iterations; restarts: (B,).
        seed: the base seed (row b used seed + b); wall_time: [s] for the whole batch, checks included.
        solver, mode: the solver and how it ran ("frdm (compiled batch, T threads)" or "per target").
        judge: whose FK judged the rows: "compiled FK (certified)" or "Pinocchio FK" (``robot.fk_certificate``).
    """

    q: np.ndarray
    success: np.ndarray
    status_code: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    iterations: np.ndarray
    restarts: np.ndarray
    seed: int
    wall_time: float
    solver: str
    mode: str
    judge: str = "Pinocchio FK"

    def __len__(self) -> int:
        return int(self.success.shape[0])

    @property
    def status(self) -> np.ndarray:
        """(B,) the rows' :class:`~kinelab.ik.result.Status` members (an object array; ``== "converged"`` works)."""
        return Status.of_codes(self.status_code)

    def summary(self) -> dict[str, Any]:
        """Counts per status, the success rate and the throughput [solves/s]."""
        return {"targets": len(self), "solved": int(self.success.sum()), "success_rate": float(self.success.mean()),
                "status": status_counts(self.status_code),
                "solves_per_second": len(self) / self.wall_time if self.wall_time > 0 else float("inf"),
                "mode": self.mode}


def run_batch(robot: Chain, targets: Targets, q0: Configuration | None, req: Request) -> BatchIKResult:
    """Solve IK for every target of a batch (each a tool pose in the robot's base frame).

    Args:
        robot: the robot.
        targets: a sequence of ``pin.SE3`` or an (B, 4, 4) array of homogeneous matrices (oMtarget).
        q0: starts: None or "random" (each row draws its own from its seed), "table" (each row's first start
            the start table's configuration whose tool pose is nearest its target, :mod:`kinelab.ik.starts`), one
            configuration for every row, or (B, n) [rad or m]; within the joint limits.
        req: the validated request; its seed is the base seed (row b uses seed + b; None: one is drawn and
            reported), its time budget bounds the whole batch (rows not started when it runs out are left
            unsolved with status ``time_budget`` and NaN in q).

    Returns:
        The :class:`BatchIKResult`, every row judged by the FK ``robot.fk_certificate`` names (``judge``).

    Raises:
        TargetError: a bad target (its index named).
        ConfigurationError: q0 of the wrong shape, NaN or outside the limits (row named).
    """
    compiled = prepare(robot, req)
    t0 = time.perf_counter()
    points, rotations = as_target_arrays(targets)
    tabled = isinstance(q0, str) and _from_table(robot, req, q0)
    starts = _table_starts(robot, points, rotations) if tabled else \
        _starts(robot, None if isinstance(q0, str) else q0, points.shape[0])
    seed = fresh_seed() if req.seed is None else req.seed
    # the budget covers the whole call: the solvers stop early enough to leave time for Pinocchio's verdict
    deadline = np.inf if req.time_budget is None else \
        t0 + req.time_budget - min(CALL_SECONDS + VERDICT_SECONDS_PER_ROW * points.shape[0], 0.5 * req.time_budget)
    if compiled:
        attempts = np.where(_beyond(robot, points, req) > 0, 1, req.max_restarts + 1)
        rows = frdm_batch.run(robot, points, rotations, starts, seed_states(seed, points.shape[0]), attempts,
                              req.tol_pos, req.tol_rot, deadline, req.options)
        table = ", first starts from the start table" if tabled else ""
        mode = f"{req.options.label} (compiled batch, {threads.count()} threads{table})"
    else:
        rows = _per_target(robot, points, rotations, starts, replace(req, seed=seed), deadline)
        mode = f"{req.solver} (per target)"
    return judged_rows(robot, rows, points, rotations, req, seed, t0, mode)


def prepare(robot: Chain, req: Request) -> bool:
    """Build what a batch of this request needs once per robot, before any clock starts: the solver's model and
    what :func:`prepare_robot` builds. No budget pays for this: a first call with a 50 ms budget once spent it all
    on the certificate and returned nothing.

    Returns:
        True when the rows run in FRDM's compiled batch (else one by one through the driver).
    """
    compiled = bool(capabilities(req.solver).compiled and req.options.compiled)
    prepare_solver(req.module, robot, req.options)  # FRDM's: the chain model its batch runs on
    prepare_robot(robot)
    return compiled


def prepare_robot(robot: Chain) -> None:
    """What the compiled kernels and the judge need once per robot, before any clock starts: the certified judge, the
    reach bound and the BLAS routines (the kernels themselves are compiled at install; a solver's own model is its
    ``prepare``'s)."""
    _blas.ready()
    robot.fk_certificate  # noqa: B018 - certified once per robot
    reach_bound(robot)


def fresh_seed() -> int:
    """A base seed drawn from fresh entropy (an int ≥ 0 that leaves room for seed + row)."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(2))


def _from_table(robot: Chain, req: Request, q0: str | None) -> bool:
    """True when the batch's first starts come from the robot's start table (:mod:`kinelab.ik.starts`): ``q0``
    "table" for a pose task. Not the default: measured on 2,000 random targets it saves FRDM a fifth of its sweeps
    on the Panda and a tenth on the UR5, less than the look-up costs on the UR5 (docs/bench/throughput-2026-12-04.md).

    Raises:
        ConfigurationError: ``q0`` a string other than "table" or "random", or "table" for a task that is not
            "pose".
    """
    if isinstance(q0, str) and (q0 not in ("table", "random") or (q0 == "table" and req.task.name != "pose")):
        raise ConfigurationError(f"q0 must be None, 'random', 'table' (task 'pose'), {robot.n} numbers or "
                                 f"(B, {robot.n}), got {q0!r} for task {req.task.name!r}")
    return q0 == "table"


def _table_starts(robot: Chain, points: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Each row's first start from the robot's start table (built, with SciPy's k-d tree, on first use)."""
    return starts_module.start_table(robot).nearest(stack_homogeneous(points, rotations))


def _starts(robot: Chain, q0: Any, count: int) -> np.ndarray | None:
    """The (count, n) starts, checked (None: every row draws its own)."""
    if q0 is None:
        return None
    arr = np.asarray(q0)
    if arr.dtype.kind not in "fiu":
        raise ConfigurationError(f"q0 must be numbers, got dtype {arr.dtype}")
    if arr.shape == (robot.n,):
        arr = np.broadcast_to(arr, (count, robot.n))
    if arr.shape != (count, robot.n):
        raise ConfigurationError(f"q0 must be None, {robot.n} numbers or ({count}, {robot.n}) for {count} targets "
                                 f"of {robot.name}, got {count_of(arr.shape)}")
    for b in np.flatnonzero(~np.isfinite(arr).all(axis=1) | ~robot.within_limits_batch(arr)):
        robot.check_q(arr[b], limits=True, what=f"q0[{b}]")
    return np.array(arr, dtype=float)


def _beyond(robot: Chain, points: np.ndarray, req: Request) -> np.ndarray:
    """Per target: how far [m] its position lies beyond the reach bound (≤ 0: maybe reachable; always 0 for a
    task that ignores the point)."""
    if not req.task.position:
        return np.zeros(points.shape[0])
    anchor, radius = reach_bound(robot)
    beyond: np.ndarray = np.linalg.norm(points - np.asarray(anchor), axis=1) - radius
    return beyond


def _per_target(robot: Chain, points: np.ndarray, rotations: np.ndarray, starts: np.ndarray | None,
                req: Request, deadline: float) -> Rows:
    """The driver row by row (solvers without a compiled batch); rows after the deadline are left unsolved."""
    count, n = points.shape[0], robot.n
    rows = Rows.unsolved(count, n)
    seed = int(req.seed or 0)
    for b in range(count):
        left = deadline - time.perf_counter()
        if left <= 0:
            break
        row = replace(req, seed=seed + b, time_budget=min(left, 1e9), start_outside_limits="refuse")
        res = solve_one(robot, pin.SE3(rotations[b], points[b]), None if starts is None else starts[b], row)
        rows.Q[b], rows.iterations[b], rows.restarts[b] = res.q, res.iterations, res.restarts
        rows.code[b] = res.status.code
    return rows


def judged_rows(robot: Chain, rows: Rows, points: np.ndarray, rotations: np.ndarray, req: Request, seed: int,
            t0: float, mode: str) -> BatchIKResult:
    """Pinocchio's verdict on every solved row; statuses as :func:`kinelab.solve` gives them."""
    count, task = points.shape[0], req.task
    dp, dr, success = np.full(count, np.nan), np.full(count, np.nan), np.zeros(count, dtype=bool)
    met = np.zeros(count, dtype=bool)
    solved = np.flatnonzero(rows.code != Status.TIME_BUDGET.code)
    if solved.size:
        rows.Q[solved] = wrap_q(robot, rows.Q[solved])  # a whole turn into the limits: the same pose
        H_target = stack_homogeneous(points[solved], rotations[solved])
        with np.errstate(over="ignore"):  # a target 1e200 m away is far, not an error
            dp[solved], dr[solved] = task.errors_batch(H_target, robot.fk_batch(rows.Q[solved]))
        within = robot.within_limits_batch(rows.Q[solved])
        met[solved] = task.met_batch(dp[solved], dr[solved], req.tol_pos, req.tol_rot)
        success[solved] = met[solved] & within
    code = rows.code
    code[success] = Status.CONVERGED.code
    code[met & ~success] = Status.OUTSIDE_LIMITS.code  # use_limits=False: met beyond a limit, as solve says
    failed = ~met & (code != Status.TIME_BUDGET.code)
    code[failed & (_beyond(robot, points, req) > 0)] = Status.UNREACHABLE.code
    code[failed & (code == Status.CONVERGED.code)] = Status.STALLED.code  # the solver's test passed only
    return BatchIKResult(rows.Q, success, code, dp, dr, rows.iterations, rows.restarts, seed,
                         time.perf_counter() - t0, req.solver, mode, robot.fk_certificate.judge)
