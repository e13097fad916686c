"""Whole-body kinematics on a robot's whole tree: tasks on any frame (and the centre of mass, a posture, couplings),
limits held exactly, one differential step (a QP), and the converged solve.

- :mod:`~kinelab.wholebody.tasks`: the tasks, values that answer for themselves
  (:class:`~kinelab.wholebody.tasks.Task`).
- :mod:`~kinelab.wholebody.constraints`: what the step holds exactly (couplings, loops; the inequality protocol).
- :mod:`~kinelab.wholebody.limits`: what the step holds (the joints' limits as bounds, and what it holds as rows).
- :mod:`~kinelab.wholebody.evaluate`: each task's error and rate matrix from one Pinocchio pass.
- :mod:`~kinelab.wholebody.qp`: the QP (DAQP, or ProxQP).
- :mod:`~kinelab.wholebody.step`: the step's QP (the readable step, its options and result).
- :mod:`~kinelab.wholebody.problem`: :class:`WholeBody`, a problem prepared once, and :func:`step`.
- :mod:`~kinelab.wholebody.approach`: the converged solve's first move (the base and the limbs to the tasks).
- :mod:`~kinelab.wholebody.solve`: the converged solve.
"""

from kinelab.wholebody.constraints import CouplingTask, Held, Inequality
from kinelab.wholebody.limits import JointLimits, Limits
from kinelab.wholebody.problem import WholeBody, step
from kinelab.wholebody.step import StepOptions, StepResult
from kinelab.wholebody.tasks import (
    ComTask,
    DampingTask,
    FrameTask,
    Placement,
    PostureTask,
    RelativeFrameTask,
    Task,
    TaskError,
)

__all__ = ["ComTask", "CouplingTask", "DampingTask", "FrameTask", "Held", "Inequality", "JointLimits", "Limits",
           "Placement", "PostureTask", "RelativeFrameTask", "StepOptions", "StepResult", "Task", "TaskError",
           "WholeBody", "step"]
