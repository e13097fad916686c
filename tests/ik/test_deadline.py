"""#67 item 6: the closed-form loops stop before a step that would overrun their budget, and a root's finish gets
only what is left of it. Behaviour on fake clocks that move a set step per reading, never on the machine's clock
(the bench measures the overruns: ``kinelab bench --budgets``)."""

from types import SimpleNamespace

import numpy as np
import pytest

import kinelab
from kinelab.ik import request
from kinelab.ik.analytic import branches, redundancy


class Clock:
    """A clock whose readings are given in turn (the last one repeated)."""

    def __init__(self, *readings: float):
        self.readings = list(readings)

    def perf_counter(self) -> float:
        return self.readings.pop(0) if len(self.readings) > 1 else self.readings[0]


def test_a_deadline_stops_before_a_step_as_slow_as_the_slowest_would_pass_it(monkeypatch):
    """Steps of 1, 3 and 1 ms from 0 against an end of 10 ms less the verdict's reserve (0.2 ms): after the third
    step (t = 5 ms, the slowest 3 ms) another fits; after the fourth (t = 7.5 ms, 2.5 ms) 7.5 + 3 passes 9.8."""
    monkeypatch.setattr(request, "time", Clock(0.001, 0.004, 0.005, 0.0075))
    deadline = request.Deadline(0.0, 0.010)
    assert deadline.end == pytest.approx(0.010 - 0.0002)
    assert [deadline.near() for _ in range(4)] == [False, False, False, True]
    assert deadline.slowest == pytest.approx(0.003)


def test_no_budget_is_no_deadline(monkeypatch):
    monkeypatch.setattr(request, "time", Clock(1e9))
    assert not request.Deadline(0.0, None).near()


def test_a_root_short_of_the_tolerances_is_not_finished_once_the_budget_is_spent(monkeypatch, no_tolerance_floor):
    """judged() finished a near root with FRDM on a budget of its own (1 s) whatever the caller had left: a
    5 ms sweep ran 8.4 ms on baxter_left. Past ``end`` no finish is started; before it, the finish gets what is
    left."""
    ur5 = kinelab.load("ur5")
    q = ur5.random_q(2)
    target = ur5.fk(q)
    req = request.make_request("frdm", tol_pos=1e-300, tol_rot=1e-300)  # every root is short, and near
    given = []
    monkeypatch.setattr(branches, "solve_one", lambda robot, t, q0, r: given.append(r.time_budget)
                        or SimpleNamespace(success=False))
    monkeypatch.setattr(branches, "time", Clock(5.0))
    assert branches.judged(ur5, q, target, req, end=4.0) is None and given == []
    assert branches.judged(ur5, q, target, req, end=5.003) is None
    assert given == [pytest.approx(0.003)]  # the finish was started, with what was left


def test_the_sweep_hands_its_deadline_to_every_value(monkeypatch):
    panda = kinelab.load("panda")
    target = panda.fk(panda.random_q(4))
    ends = []
    real = redundancy.at_value

    def spy(robot, t, req, theta, q_ref=None, joint=None, end=np.inf):
        ends.append(end)
        return real(robot, t, req, theta, q_ref, joint, end)

    monkeypatch.setattr(redundancy, "at_value", spy)
    kinelab.solve_all(panda, target, redundancy=8, time_budget=1.0)
    assert len(ends) == 8 and all(np.isfinite(e) for e in ends) and len(set(ends)) == 1
