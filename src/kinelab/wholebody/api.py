"""``kinelab.solve``: one entry point for a target and for tasks.

``solve(chain, oMtarget, ...)`` places a chain's tool (:func:`kinelab.ik.api.solve`, every option of it);
``solve(robot, [tasks...], ...)`` meets several tasks on the whole tree (:func:`kinelab.wholebody.solve.solve`).
A whole robot with a single target, or a chain with tasks, is answered by name with the way to ask.
"""

from __future__ import annotations

from typing import Any

from kinelab.errors import ChainError
from kinelab.ik import api as chain_api
from kinelab.robot.chain import Chain
from kinelab.robot.tree import Robot
from kinelab.wholebody import solve as wholebody
from kinelab.wholebody.tasks import TASK_TYPES


def is_tasks(target: Any) -> bool:
    """True for a task or a non-empty list or tuple of tasks."""
    if isinstance(target, TASK_TYPES):
        return True
    return isinstance(target, list | tuple) and bool(target) and all(isinstance(t, TASK_TYPES) for t in target)


def solve(robot: Chain | Robot, target: Any, *positional: Any, **settings: Any) -> Any:
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
        ChainError: a whole robot with a pose (name the frame: ``FrameTask``), or a chain with tasks. Otherwise as
            the solve taken.
    """
    if is_tasks(target):
        if positional:
            chain_api.refuse_positional("solve", positional)
        if isinstance(robot, Chain):
            raise ChainError(f"tasks are solved on a whole robot: {robot.name}'s is robot.robot (kinelab.solve("
                             "robot.robot, tasks))")
        return wholebody.solve(robot, target, **settings)
    if isinstance(robot, Robot):
        raise ChainError(f"{robot.name} is a whole robot: ask for a frame with a task (kinelab.solve(robot, "
                         "[FrameTask(frame, oMtarget)])), or take a chain of it (robot.chain(base, tool))")
    return chain_api.solve(robot, target, *positional, **settings)
