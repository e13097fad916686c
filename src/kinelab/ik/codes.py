"""The compiled kernels' return codes, one table for FRDM's and the biquaternion preset's (the compiled core's
``Code`` enum, :mod:`kinelab.core._frdm`), and the :class:`~kinelab.ik.result.Status` each stands for."""

from __future__ import annotations

from kinelab.core._frdm import Code
from kinelab.ik.result import Status

CONVERGED, STALL_STEP, STALL_WINDOW, BUDGET = (int(c) for c in (Code.CONVERGED, Code.STALL_STEP, Code.STALL_WINDOW,
                                                                Code.BUDGET))
SINGULAR, MAX_STEPS, OUTSIDE_LIMITS = (int(c) for c in (Code.SINGULAR, Code.MAX_STEPS, Code.OUTSIDE_LIMITS))
NOT_STARTED, STOPPED = int(Code.NOT_STARTED), int(Code.STOPPED)  # a row the deadline cut before or while it ran

STATUS_OF: dict[int, Status] = {
    CONVERGED: Status.CONVERGED, STALL_STEP: Status.STALLED, STALL_WINDOW: Status.STALLED,
    BUDGET: Status.MAX_ITERATIONS, SINGULAR: Status.SINGULAR, MAX_STEPS: Status.MAX_ITERATIONS,
    OUTSIDE_LIMITS: Status.OUTSIDE_LIMITS, NOT_STARTED: Status.TIME_BUDGET, STOPPED: Status.TIME_BUDGET}


def status_of(code: int) -> Status:
    """The status a kernel's code stands for (any other code, such as a polish's −1: max_iterations). The caller
    decides what the code cannot tell: whether the judge confirms a convergence, whether the deadline passed."""
    return STATUS_OF.get(int(code), Status.MAX_ITERATIONS)

