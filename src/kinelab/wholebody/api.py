"""``kinelab.solve`` and ``kinelab.track``: one entry point for a target and for tasks, one for a path.

``solve(chain, oMtarget, ...)`` places a chain's tool (:func:`kinelab.ik.api.solve`, every option of it);
``solve(robot, [tasks...], ...)`` meets several tasks on the whole tree (:func:`kinelab.wholebody.solve.solve`).
A whole robot with a single target, or a chain with tasks, is answered by name with the way to ask.
``track(chain, targets, ...)`` follows a path with FRDM's compiled follower (:func:`kinelab.ik.api.track`), or
with ``follower="step"`` by the whole-body step (:func:`kinelab.wholebody.follow.track`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, TypeGuard, overload

import pinocchio as pin

from kinelab import lazy
from kinelab.errors import ChainError, OptionError
from kinelab.ik import api as chain_api
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot
from kinelab.typing import Target, Targets
from kinelab.wholebody.tasks import Task

if TYPE_CHECKING:
    from kinelab.ik.registry import SolverOptions
    from kinelab.ik.result import IKResult, TrackResult
    from kinelab.typing import CollisionSpec, Configuration
    from kinelab.wholebody import follow
    from kinelab.wholebody import solve as wholebody
    from kinelab.wholebody.limits import Limits
    from kinelab.wholebody.solve import WholeBodyResult
else:  # a chain's solve does not load the whole-body step (its QP, its compiled problem)
    follow = lazy.module("kinelab.wholebody.follow", globals())
    wholebody = lazy.module("kinelab.wholebody.solve", globals())


def is_tasks(target: object) -> TypeGuard[Task | Sequence[Task]]:
    """True for a task or a non-empty list or tuple of tasks."""
    if isinstance(target, Task):
        return True
    return isinstance(target, list | tuple) and bool(target) and all(isinstance(t, Task) for t in target)


@overload
def solve(robot: Chain, target: Target, *, solver: str = "auto", q0: Configuration | None = None,
          seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, time_budget: float = 1.0,
          max_restarts: int = 1000, start_outside_limits: str = "project", options: SolverOptions = None,
          task: str = "pose", axis: str = "z", prefer: Configuration | None = None, collisions: CollisionSpec = None,
          **solver_options: object) -> IKResult: ...


@overload
def solve(robot: Robot | Chain, target: Task | Sequence[Task], *, q0: Configuration | None = None, solver: str = "step",
          seed: int | None = None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, max_iterations: int = 100,
          max_restarts: int = 200, time_budget: float | None = 1.0, limits: Limits | None = None
          ) -> WholeBodyResult: ...


def solve(robot: Chain | Robot, target: Target | Task | Sequence[Task], *positional: object,
          **settings: Any) -> IKResult | WholeBodyResult:
    """Inverse kinematics: a chain's tool at ``target`` (an ``IKResult``), or a whole robot's tasks (a
    ``WholeBodyResult``).

    Args:
        robot: a chain (``kinelab.load("panda")``) or a whole robot (``kinelab.load("talos")``).
        target: oMtarget (a chain's tool pose), or a task or a list of tasks (:mod:`kinelab.wholebody.tasks`).
        positional: nothing: every setting is keyword-only.
        settings: the keywords of :func:`kinelab.ik.api.solve` (a target) or :func:`kinelab.wholebody.solve.solve`
            (tasks).

    Returns:
        An :class:`~kinelab.ik.result.IKResult` or a :class:`~kinelab.wholebody.solve.WholeBodyResult`.

    Raises:
        ChainError: a whole robot with a pose (name the frame: ``FrameTask``). Otherwise as
            the solve taken.
    """
    if type(target) is pin.SE3 and type(robot) is Chain:  # the usual call, told apart in two type checks
        return chain_api.solve(robot, target, *positional, **settings)
    if is_tasks(target):
        if positional:
            chain_api.refuse_positional("solve", positional)
        extra = [k for k in settings if k not in SOLVE_SETTINGS]
        if extra:
            raise OptionError(extra[0], settings[extra[0]], "a setting of a whole-body solve: "
                              f"{', '.join(SOLVE_SETTINGS)}")
        return wholebody.solve(robot, target, **settings)
    if isinstance(robot, Robot):
        raise ChainError(f"{robot.name} is a whole robot: ask for a frame with a task (kinelab.solve(robot, "
                         "[FrameTask(frame, oMtarget)])), or take a chain of it (robot.chain(base, tool))")
    return chain_api.solve(robot, target, *positional, **settings)


SOLVE_SETTINGS = ("q0", "solver", "seed", "tol_pos", "tol_rot", "max_iterations", "max_restarts", "time_budget",
                  "limits")  # kinelab.wholebody.solve.solve's keywords
FOLLOWERS = ("frdm", "step")
STEP_SETTINGS = ("q0", "seed", "tol_pos", "tol_rot", "time_budget", "task", "axis", "jump_limit", "collisions")


def track(robot: Chain, targets: Targets, *positional: object, follower: str = "frdm",
          **settings: Any) -> TrackResult:
    """Follow a path: each target in turn, from the answer before.

    Args:
        robot: the chain.
        targets: oMtarget per sample (a sequence of ``pin.SE3`` or an (N, 4, 4) array, base frame).
        positional: nothing: every setting is keyword-only.
        follower: "frdm" (FRDM's compiled follower and its monitored loop: every option of
            :func:`kinelab.ik.api.track`) or "step" (the whole-body step: a posture and a box about each sample,
            :func:`kinelab.wholebody.follow.track`, which takes the settings ``STEP_SETTINGS`` names).
        settings: the follower's keywords.

    Returns:
        A :class:`~kinelab.ik.result.TrackResult`.

    Raises:
        OptionError: an unknown follower, or a setting the step follower does not take (the valid ones named).
            Otherwise as the follower taken.
    """
    if follower not in FOLLOWERS:
        raise OptionError("follower", follower, "'frdm' or 'step'")
    if follower == "frdm":
        return chain_api.track(robot, targets, *positional, **settings)
    chain_api.check_entry(robot, "track", positional)
    extra = [k for k in settings if k not in STEP_SETTINGS]
    if extra:
        raise OptionError(extra[0], settings[extra[0]], f"a setting of follower='step': {', '.join(STEP_SETTINGS)}")
    return follow.track(robot, targets, **settings)
