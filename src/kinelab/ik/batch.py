"""``solve_batch``: IK for many targets in one call, every answer checked by Pinocchio.

Row b is the answer :func:`kinelab.solve` gives for ``targets[b]`` alone with ``seed = seed + b`` and
start ``q0[b]`` (or none), when neither runs out of time. FRDM with compiled options runs the rows in
parallel inside one kernel (every core, numba ``prange``; the answers do not depend on the thread
count); the other solvers and FRDM's monitored options run ``solve`` row by row on one core.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import pinocchio as pin

from kinelab.errors import ConfigurationError
from kinelab.geometry import stack_homogeneous
from kinelab.ik.frdm import batch as frdm_batch
from kinelab.ik.frdm.batch import Rows
from kinelab.ik.multistart import seed_states
from kinelab.ik.result import Status
from kinelab.ik.solve import check_arguments, for_task, solve, solver_module
from kinelab.ik.targets import as_target_arrays
from kinelab.ik.tasks import POSE, Task
from kinelab.ik.workspace import reach_bound
from kinelab.robot import Robot


@dataclass
class BatchIKResult:
    """The outcome of :func:`solve_batch`: one row per target.

    Attributes:
        q: (B, n) answers [rad or m] (NaN in rows the time budget left unsolved).
        success: (B,) Pinocchio confirms both tolerances within the joint limits.
        status: (B,) :class:`~kinelab.ik.result.Status` values as strings.
        position_error: (B,) [m]; rotation_error: (B,) [rad] (Pinocchio's FK against the target).
        iterations: (B,) sweeps (FRDM) or the solver's iterations; restarts: (B,).
        seed: the base seed (row b used seed + b); wall_time: [s] for the whole batch, checks included.
        solver, mode: the solver and how it ran ("frdm (compiled batch, T threads)" or "per target").
    """

    q: np.ndarray
    success: np.ndarray
    status: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    iterations: np.ndarray
    restarts: np.ndarray
    seed: int
    wall_time: float
    solver: str
    mode: str

    def __len__(self) -> int:
        return int(self.success.shape[0])

    def summary(self) -> dict[str, Any]:
        """Counts per status, the success rate and the throughput [solves/s]."""
        values, counts = np.unique(self.status, return_counts=True)
        return {"targets": len(self), "solved": int(self.success.sum()), "success_rate": float(self.success.mean()),
                "status": dict(zip(values.tolist(), counts.tolist(), strict=True)),
                "solves_per_second": len(self) / self.wall_time if self.wall_time > 0 else float("inf"),
                "mode": self.mode}


def solve_batch(robot: Robot, targets: Any, q0: Any = None, seed: int | None = None, solver: str = "frdm",
                tol_pos: float = 1e-6, tol_rot: float = 1e-6, max_restarts: int = 1000,
                time_budget: float | None = None, options: Any = None, task: str = "pose", axis: str = "z",
                **solver_options: Any) -> BatchIKResult:
    """Solve IK for every target of a batch (each a tool pose in the robot's base frame).

    Args:
        robot: the robot.
        targets: a sequence of ``pin.SE3`` or an (B, 4, 4) array of homogeneous matrices (oMtarget).
        q0: starts: None (each row draws its own from its seed), one configuration for every row, or (B, n)
            [rad or m]; within the joint limits.
        seed: base seed, an int ≥ 0 (row b uses seed + b); None draws one (reported in the result).
        solver: "frdm", "biquat" or "dls".
        tol_pos: [m].
        tol_rot: [rad].
        max_restarts: random restarts per row after its first attempt.
        time_budget: wall-clock budget [s] of the whole batch (None: none); rows not started when it runs
            out are left unsolved with status ``time_budget`` and NaN in q.
        options: the solver's options object, as for :func:`kinelab.solve`.
        task: the components to meet, as for :func:`kinelab.solve`; axis: the tool axis of task "axis".
        solver_options: or its fields as keyword arguments.

    Returns:
        The :class:`BatchIKResult`, every row judged by Pinocchio's FK.

    Raises:
        TargetError: a bad target (its index named).
        ConfigurationError: q0 of the wrong shape, NaN or outside the limits (row named).
        OptionError: a bad option or argument (SolverNotFoundError: an unknown solver).
    """
    module = solver_module(solver)
    opts = module.Options.of(options, **solver_options)
    tk = Task.of(task, axis)
    if tk is not POSE:
        opts = for_task(solver, opts, tk)
    check_arguments(tol_pos, tol_rot, 1.0 if time_budget is None else time_budget, max_restarts, seed, "refuse")
    points, rotations = as_target_arrays(targets)
    starts = _starts(robot, q0, points.shape[0])
    if seed is None:
        seed = int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(2))
    if solver == "frdm" and opts.compiled:
        frdm_batch.prepare(robot)
        t0 = time.perf_counter()
        attempts = np.where(_beyond(robot, points) > 0, 1, max_restarts + 1)
        deadline = np.inf if time_budget is None else t0 + time_budget
        rows = frdm_batch.run(robot, points, rotations, starts, seed_states(seed, points.shape[0]), attempts,
                              tol_pos, tol_rot, deadline, opts)
        mode = f"frdm (compiled batch, {numba.get_num_threads()} threads)"
    else:
        t0 = time.perf_counter()
        rows = _per_target(robot, points, rotations, starts, seed, solver, tol_pos, tol_rot, max_restarts,
                           time_budget, opts, tk)
        mode = f"{solver} (per target)"
    return _judged(robot, rows, points, rotations, tol_pos, tol_rot, seed, t0, solver, mode, tk)


def _starts(robot: Robot, q0: Any, count: int) -> np.ndarray | None:
    """The (count, n) starts, checked (None: every row draws its own)."""
    if q0 is None:
        return None
    arr = np.asarray(q0, dtype=float) if not isinstance(q0, np.ndarray) or q0.dtype.kind in "fiu" else q0
    if arr.dtype.kind not in "fiu":
        raise ConfigurationError(f"q0 must be numbers, got dtype {arr.dtype}")
    if arr.shape == (robot.n,):
        arr = np.broadcast_to(arr, (count, robot.n))
    if arr.shape != (count, robot.n):
        raise ConfigurationError(f"q0 must be None, {robot.n} numbers or ({count}, {robot.n}) for {count} targets "
                                 f"of {robot.name}, got shape {arr.shape}")
    for b in np.flatnonzero(~np.isfinite(arr).all(axis=1) | ~robot.within_limits_batch(arr)):
        robot.check_q(arr[b], limits=True, what=f"q0[{b}]")
    return np.array(arr, dtype=float)


def _beyond(robot: Robot, points: np.ndarray) -> np.ndarray:
    """Per target: how far [m] its position lies beyond the reach bound (≤ 0: maybe reachable)."""
    anchor, radius = reach_bound(robot)
    return np.linalg.norm(points - np.asarray(anchor), axis=1) - radius


def _per_target(robot: Robot, points: np.ndarray, rotations: np.ndarray, starts: np.ndarray | None, seed: int,
                solver: str, tol_pos: float, tol_rot: float, max_restarts: int, time_budget: float | None,
                opts: Any, task: Task) -> Rows:
    """solve() row by row (solvers without a compiled batch); rows after the budget are left unsolved."""
    count, n = points.shape[0], robot.n
    rows = Rows.unsolved(count, n)
    deadline = np.inf if time_budget is None else time.perf_counter() + time_budget
    for b in range(count):
        left = deadline - time.perf_counter()
        if left <= 0:
            break
        res = solve(robot, pin.SE3(rotations[b], points[b]), solver, None if starts is None else starts[b],
                    seed + b, tol_pos, tol_rot, min(left, 1e9), max_restarts, "refuse", opts, task.name,
                    "xyz"[task.axis] if task.axis >= 0 else "z")
        rows.Q[b], rows.iterations[b], rows.restarts[b] = res.q, res.iterations, res.restarts
        rows.status[b] = res.status.value
    return rows


def _judged(robot: Robot, rows: Rows, points: np.ndarray, rotations: np.ndarray, tol_pos: float, tol_rot: float,
            seed: int, t0: float, solver: str, mode: str, task: Task) -> BatchIKResult:
    """Pinocchio's verdict on every solved row; statuses as :func:`kinelab.solve` gives them."""
    count = points.shape[0]
    dp, dr, success = np.full(count, np.nan), np.full(count, np.nan), np.zeros(count, dtype=bool)
    solved = np.flatnonzero(rows.status != Status.TIME_BUDGET.value)
    if solved.size:
        H_target = stack_homogeneous(points[solved], rotations[solved])
        dp[solved], dr[solved] = task.errors_batch(H_target, robot.fk_batch(rows.Q[solved]))
        within = robot.within_limits_batch(rows.Q[solved])
        success[solved] = task.met_batch(dp[solved], dr[solved], tol_pos, tol_rot) & within
    status = rows.status
    status[success] = Status.CONVERGED.value
    failed = ~success & (status != Status.TIME_BUDGET.value)
    status[failed & (_beyond(robot, points) > 0)] = Status.UNREACHABLE.value
    status[failed & (status == Status.CONVERGED.value)] = Status.STALLED.value  # the solver's test passed only
    return BatchIKResult(rows.Q, success, rows.status, dp, dr, rows.iterations, rows.restarts, seed,
                         time.perf_counter() - t0, solver, mode)
