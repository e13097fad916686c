"""All the branches: the distinct solutions of one target that seeded restarts find within a budget.

The FRDM paper calls its answer unique; it is unique from one start, not over the workspace (a 6R arm
has up to 16 inverse kinematic solutions, the UR arms 8). :func:`solve_all` solves the target from many
seeded random starts at once (:func:`~kinelab.ik.batch.solve_batch`), keeps every answer Pinocchio
confirms, and merges answers that are the same solution: equal joint by joint to SAME, revolute joints
compared modulo 2π (an arm whose joint can turn past ±π reaches the same solution at q and q ± 2π).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError
from kinelab.ik.batch import solve_batch
from kinelab.ik.result import IKResult, Status
from kinelab.ik.solve import check_arguments
from kinelab.ik.targets import as_target
from kinelab.robot import Robot

SAME = 1e-3  # [rad or m] two answers closer than this, joint by joint, are one solution (answers met to 1e-6 m
# near a singular point differ by up to ~2e-4 rad; distinct branches by far more)
ROUND = 64  # starts per round (one batch call)


def solve_all(robot: Robot, target: pin.SE3, task: str = "pose", axis: str = "z", time_budget: float = 0.05,
              seed: int | None = None, q_ref: Any = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6,
              solver: str = "frdm", max_solutions: int | None = None, **solver_options: Any) -> list[IKResult]:
    """The distinct solutions found for ``target`` within ``time_budget``, each checked by Pinocchio.

    Args:
        robot: the robot.
        target: oMtarget (base frame).
        task: the components to meet (as :func:`kinelab.solve`).
        axis: the tool axis of task "axis".
        time_budget: wall-clock budget [s]; rounds of ROUND seeded starts run until it is spent.
        seed: base seed (None: fresh entropy); the same seed finds the same solutions when the budget allows
            the same number of rounds.
        q_ref: sort the solutions by distance to this configuration (rad or m; revolute joints modulo 2π);
            default: by the order found.
        tol_pos: [m].
        tol_rot: [rad].
        solver: "frdm" (one compiled batch per round) or "dls".
        max_solutions: stop once this many distinct solutions are found (None: use the whole budget).
        solver_options: the solver's options as keyword arguments.

    Returns:
        One :class:`IKResult` per distinct solution (``info["found"]``: how many starts reached it).

    Raises:
        TargetError, ConfigurationError, OptionError: bad input, named.
    """
    target = as_target(target, task)
    check_arguments(tol_pos, tol_rot, time_budget, 0, seed, "refuse")
    if max_solutions is not None and (not isinstance(max_solutions, int) or max_solutions < 1):
        raise OptionError("max_solutions", max_solutions, "an integer ≥ 1, or None")
    ref = None if q_ref is None else robot.check_q(q_ref, what="q_ref")
    seed = int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(2)) if seed is None else seed
    found: list[tuple[np.ndarray, float, float, int]] = []
    t0 = time.perf_counter()
    rounds = 0
    while time.perf_counter() - t0 < time_budget and (max_solutions is None or len(found) < max_solutions):
        batch = solve_batch(robot, [target] * ROUND, seed=seed + rounds * ROUND, solver=solver, tol_pos=tol_pos,
                            tol_rot=tol_rot, max_restarts=0, task=task, axis=axis, **solver_options)
        for b in np.flatnonzero(batch.success):
            _merge(robot, found, batch.q[b], batch.position_error[b], batch.rotation_error[b])
        rounds += 1
    elapsed = time.perf_counter() - t0
    if ref is not None:
        found.sort(key=lambda f: distance(robot, f[0], ref))
    return [IKResult(q=q, success=True, status=Status.CONVERGED, position_error=dp, rotation_error=dr, iterations=0,
                     restarts=rounds * ROUND - 1, wall_time=elapsed, solver=solver, mode=f"{solver} (all branches)",
                     info={"found": count, "starts": rounds * ROUND}, task=task)
            for q, dp, dr, count in found[:max_solutions]]


def distance(robot: Robot, q: np.ndarray, ref: np.ndarray) -> float:
    """max |q_i − ref_i| over the joints [rad or m], revolute and continuous joints modulo 2π."""
    d = np.asarray(q, dtype=float) - np.asarray(ref, dtype=float)
    revolute = np.array([k != "prismatic" for k in robot.joint_kinds])
    d[revolute] = np.arctan2(np.sin(d[revolute]), np.cos(d[revolute]))
    return float(np.max(np.abs(d)))


def _merge(robot: Robot, found: list, q: np.ndarray, dp: float, dr: float) -> None:
    """Count q towards the solution it equals (joint by joint, revolute joints modulo 2π), or add it."""
    for k, (other, odp, odr, count) in enumerate(found):
        if distance(robot, q, other) <= SAME:
            found[k] = (other, odp, odr, count + 1)
            return
    found.append((np.array(q, dtype=float), float(dp), float(dr), 1))
