"""The public :func:`solve`: one answer (:func:`kinelab.ik.solve.solve`), or with ``prefer`` the branch nearest
a reference configuration among those :func:`~kinelab.ik.branches.solve_all` finds.

A solve from one start returns whichever branch its start falls towards; a user who wants the elbow-up
answer, or the one nearest the arm's current q, says so with ``prefer=q_ref`` and pays for the search of
all branches within the same ``time_budget``.
"""

from __future__ import annotations

from typing import Any

import pinocchio as pin

from kinelab.ik.branches import solve_all
from kinelab.ik.result import IKResult
from kinelab.ik.solve import solve as solve_one
from kinelab.robot import Robot


def solve(
    robot: Robot,
    target: pin.SE3,
    solver: str = "frdm",
    q0: Any = None,
    seed: int | None = None,
    tol_pos: float = 1e-6,
    tol_rot: float = 1e-6,
    time_budget: float = 1.0,
    max_restarts: int = 1000,
    start_outside_limits: str = "project",
    options: Any = None,
    task: str = "pose",
    axis: str = "z",
    prefer: Any = None,
    **solver_options: Any,
) -> IKResult:
    """Solve IK for the tool pose ``target`` (``pin.SE3`` in the robot's base frame).

    Args:
        robot: the robot (:func:`kinelab.load`).
        target: oMtarget, the wanted tool pose in the base frame.
        solver: "frdm", "biquat" or "dls" (the Pinocchio reference).
        q0: first start (one number per joint, rad or m); default a seeded random configuration.
        seed: seed of the random starts, an int ≥ 0 (None: fresh entropy).
        tol_pos: position tolerance [m].
        tol_rot: rotation tolerance [rad] (angle of R*ᵀR).
        time_budget: wall-clock budget [s] for all attempts together.
        max_restarts: random restarts after the first attempt (without ``prefer``).
        start_outside_limits: "project" (default: move q0 into the limits, with a warning) or "refuse".
        options: the solver's options object (``FRDMOptions``, ``BiquatOptions``, ``DLSOptions``).
        task: "pose", "position", "axis" or "orientation" (:mod:`kinelab.ik.tasks`).
        axis: the tool axis of task "axis": "x", "y" or "z".
        prefer: a reference configuration (rad or m): search every branch within ``time_budget`` and
            return the one nearest it (revolute joints compared modulo 2π); None (default): the first
            answer found. The search spends the whole ``time_budget`` (50 ms finds every branch of a UR5
            or Stanford target in 197 of 200 cases); solvers "frdm" and "dls"; ``q0`` and ``max_restarts``
            do not apply.
        solver_options: the solver's fields as keyword arguments.

    Returns:
        The result, checked by Pinocchio on the components the task constrains (``result.task``); with
        ``prefer``, ``info["branches"]`` is the number of distinct solutions found.

    Raises:
        SolverNotFoundError, OptionError, TargetError, ConfigurationError: bad input, named.
    """
    if prefer is None:
        return solve_one(robot, target, solver, q0, seed, tol_pos, tol_rot, time_budget, max_restarts,
                            start_outside_limits, options, task, axis, **solver_options)
    found = solve_all(robot, target, task=task, axis=axis, time_budget=time_budget, seed=seed, q_ref=prefer,
                      tol_pos=tol_pos, tol_rot=tol_rot, solver=solver, options=options, **solver_options)
    if found:
        best = found[0]
        best.info["branches"] = len(found)
        return best
    return solve_one(robot, target, solver, None, seed, tol_pos, tol_rot, time_budget, 0,
                        start_outside_limits, options, task, axis, **solver_options)
