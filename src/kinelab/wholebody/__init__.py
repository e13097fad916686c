"""Whole-body kinematics on a robot's whole tree: tasks on any frame (and the centre of mass, a posture, couplings),
limits held exactly, one differential step (a QP), and the converged solve.

- :mod:`~kinelab.wholebody.tasks`: the tasks, frozen values.
- :mod:`~kinelab.wholebody.limits`: what the step holds (positions, velocities, accelerations).
- :mod:`~kinelab.wholebody.evaluate`: each task's error and rate matrix from one Pinocchio pass.
- :mod:`~kinelab.wholebody.qp`: the QP (DAQP, or ProxQP).
- :mod:`~kinelab.wholebody.step`: :func:`step`.
"""

from kinelab.wholebody.limits import Limits
from kinelab.wholebody.step import StepOptions, StepResult, TaskError, step
from kinelab.wholebody.tasks import ComTask, CouplingTask, FrameTask, PostureTask, RelativeFrameTask

__all__ = ["ComTask", "CouplingTask", "FrameTask", "Limits", "PostureTask", "RelativeFrameTask", "StepOptions",
           "StepResult", "TaskError", "step"]
