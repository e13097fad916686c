"""Compile every compiled path ahead of use (``kinelab warmup``): after an install, or an update of kinelab or
numba, each path's first call compiles its numba kernels (about a minute each on a 2-core machine); warming up
pays that once, with progress, so that no later solve, batch, path or notebook waits silently."""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterator

from kinelab.ik.compiling import CompileNotice
from kinelab.robot import Robot


def paths(robot: Robot) -> list[tuple[str, Callable[[], object]]]:
    """(name, a call that runs the path once on ``robot``) for every compiled path."""
    from kinelab.ik.api import solve, solve_batch, track
    from kinelab.ik.prepared import IK

    q = robot.random_q(0)
    target = robot.fk(q)
    return [
        ("FRDM (single solves, the prepared solver)", lambda: IK(robot).solve(target, q0=q)),
        ("FRDM's monitored loop (bypasses, policies)", lambda: solve(robot, target, policy=("auto_kick",))),
        ("the FRDM batch", lambda: solve_batch(robot, [target] * 2, seed=0)),
        ("the path follower", lambda: track(robot, [target] * 2, q0=q)),
        ("the biquaternion solver", lambda: solve(robot, target, solver="biquat", seed=0)),
        ("the closed form (every branch, one pose and a batch)", lambda: _closed_form(robot)),
    ]


def _closed_form(robot: Robot) -> None:
    """Every branch of one pose and of a batch, on ``robot`` if its chain has a closed form, else on the UR5
    (the compiled code is the same for every arm)."""
    from kinelab.ik.analytic.branches import all_branches_batch
    from kinelab.ik.analytic.classify import classify
    from kinelab.ik.api import solve_all
    from kinelab.robot import load

    arm = robot if classify(robot).arm is not None else load("ur5")
    target = arm.fk(arm.random_q(0))
    solve_all(arm, target, solver="analytic")
    all_branches_batch(arm, [target])


def run(robot: Robot) -> Iterator[tuple[str, float]]:
    """Run every path once (compiling what is not cached), yielding (name, seconds) as each finishes."""
    for name, call in paths(robot):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CompileNotice)  # the caller reports progress itself
            call()
        yield name, time.perf_counter() - t0
