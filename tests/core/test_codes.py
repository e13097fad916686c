"""One table of kernel codes (#58): FRDM's kernels and the biquaternion preset return the same codes for the same
outcomes (BUDGET had been 3 in one and 4 in the other), and each code stands for one status."""

import kinelab
from kinelab.ik import codes
from kinelab.ik.biquat import kernel as biquat
from kinelab.ik.frdm import kernel as frdm


def test_both_kernels_read_one_table():
    assert (frdm.CONVERGED, frdm.BUDGET) == (biquat.CONVERGED, biquat.BUDGET) == (codes.CONVERGED, codes.BUDGET)
    assert (biquat.SINGULAR, biquat.MAX_STEPS, biquat.OUTSIDE_LIMITS) == \
        (codes.SINGULAR, codes.MAX_STEPS, codes.OUTSIDE_LIMITS)
    values = [codes.CONVERGED, codes.STALL_STEP, codes.STALL_WINDOW, codes.BUDGET, codes.SINGULAR, codes.MAX_STEPS,
              codes.OUTSIDE_LIMITS, codes.NOT_STARTED, codes.STOPPED]
    assert len(set(values)) == len(values) and set(codes.STATUS_OF) == set(values)


def test_each_code_stands_for_its_status():
    S = kinelab.Status
    assert codes.status_of(codes.CONVERGED) is S.CONVERGED
    assert codes.status_of(codes.STALL_STEP) is codes.status_of(codes.STALL_WINDOW) is S.STALLED
    assert codes.status_of(codes.BUDGET) is codes.status_of(codes.MAX_STEPS) is S.MAX_ITERATIONS
    assert codes.status_of(codes.SINGULAR) is S.SINGULAR and codes.status_of(codes.OUTSIDE_LIMITS) is S.OUTSIDE_LIMITS
    assert codes.status_of(codes.NOT_STARTED) is codes.status_of(codes.STOPPED) is S.TIME_BUDGET
    assert codes.status_of(-1) is S.MAX_ITERATIONS  # a polish's own code: not a kernel's
