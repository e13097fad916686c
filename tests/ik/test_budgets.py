"""#57 item 5: every entry point with a budget reads its clock. No test here times anything: the searches read a
fake clock that moves 1 ms at every reading, and the compiled batches get a budget that has run out before their
first row (1 ns). What each keeps in wall time is measured by ``kinelab bench --budgets``."""

import itertools
import math
import types

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.ik.analytic import redundancy, sew
from kinelab.ik.analytic.branches import _empty_set
from kinelab.ik.result import Status


class FakeClock:
    """A ``time`` module whose perf_counter moves ``step`` seconds at every reading."""

    def __init__(self, step=1e-3):
        self.readings = 0
        self._t = itertools.count()
        self.step = step

    def perf_counter(self):
        self.readings += 1
        return next(self._t) * self.step


@pytest.fixture(scope="module")
def panda():
    return kinelab.load("panda")


def _pose(robot, seed):
    return robot.fk(robot.random_q(seed))


def test_the_sew_search_stops_at_its_budget(panda, monkeypatch):
    """On aadeea0 the SEW search never read its clock: 0.9 s at time_budget=0.001."""
    q = panda.random_q(3)
    target, psi = panda.fk(q), kinelab.SEW(kinelab.sew_angle(panda, q))
    panda_all = kinelab.solve_all(panda, target, redundancy=psi, time_budget=10.0)  # the whole search
    clock = FakeClock()
    monkeypatch.setattr(sew, "time", types.SimpleNamespace(perf_counter=clock.perf_counter))
    found = kinelab.solve_all(panda, target, redundancy=psi, time_budget=0.005)
    assert clock.readings <= 12  # a handful of samples, not the 64 and their refinements
    assert len(found) == 0 and found.status == Status.TIME_BUDGET and "time budget ran out" in found.message
    assert len(panda_all) >= 1  # the same target has branches when the budget allows


def test_the_swept_joint_s_values_stop_at_the_budget(panda, monkeypatch):
    target = _pose(panda, 4)
    clock = FakeClock()
    monkeypatch.setattr(redundancy, "time", types.SimpleNamespace(perf_counter=clock.perf_counter))
    found = kinelab.solve_all(panda, target, redundancy=4096, time_budget=0.01)
    assert clock.readings <= 15
    assert found.status in (Status.CONVERGED, Status.TIME_BUDGET)
    assert found.complete == "search" and "after" in found.complete_reason


def test_the_sew_angle_is_wrapped_and_1e308_is_one_angle(panda):
    assert kinelab.SEW(0.3 + 2 * math.pi).angle == pytest.approx(0.3, abs=1e-12)
    assert -math.pi < kinelab.SEW(1e308).angle <= math.pi
    assert -math.pi < kinelab.SEW(-7.0).angle <= math.pi
    q = panda.random_q(5)
    target, psi = panda.fk(q), kinelab.sew_angle(panda, q)
    one = kinelab.solve_all(panda, target, redundancy=kinelab.SEW(psi), time_budget=10.0)
    turned = kinelab.solve_all(panda, target, redundancy=kinelab.SEW(psi + 4 * math.pi), time_budget=10.0)
    assert len(one) >= 1 and len(one) == len(turned)
    assert np.allclose(np.sort(one.q, axis=0), np.sort(turned.q, axis=0), atol=1e-9)


def test_an_empty_sew_set_says_why_by_what_was_proved(panda):
    """On aadeea0 a target 1e10 m away got "time_budget" though no budget ran out."""
    far = pin.SE3(np.eye(3), np.array([1e10, 0.0, 0.0]))
    found = kinelab.solve_all(panda, far, redundancy=kinelab.SEW(0.3))
    assert len(found) == 0 and found.status == Status.UNREACHABLE and "beyond the robot's reach" in found.message
    found = kinelab.solve_all(panda, far, redundancy=64)
    assert found.status == Status.UNREACHABLE and "beyond the robot's reach" in found.message


def test_the_empty_set_rule():
    assert _empty_set(2, "", "", None, "x") == (None, "")
    assert _empty_set(0, "beyond reach", "late", "search", "x")[0] == Status.UNREACHABLE
    assert _empty_set(0, "", "after 3 of 64", "search", "x")[0] == Status.TIME_BUDGET
    assert _empty_set(0, "", "", "", "no branch") == (Status.UNREACHABLE, "no branch")
    assert _empty_set(0, "", "", None, "no branch") == (Status.UNREACHABLE, "no branch")
    status, message = _empty_set(0, "", "", "a search", "no branch")
    assert status == Status.NOT_FOUND and "not certified: a search" in message


def test_solve_all_batch_takes_a_budget_and_marks_the_rows_left():
    """On aadeea0 solve_all_batch had no budget at all (50,000 general6r rows: over a minute)."""
    for name in ("general6r", "ur5"):
        robot = kinelab.load(name)
        H = robot.fk_batch(robot.random_qs(300, 0))
        whole = kinelab.solve_all_batch(robot, H)
        assert whole.late is None and (whole.count > 0).all()
        cut = kinelab.solve_all_batch(robot, H, time_budget=1e-9)
        assert cut.late.all() and (cut.count == 0).all() and np.isnan(cut.q).all()
    with pytest.raises(kinelab.OptionError, match="time_budget"):
        kinelab.solve_all_batch(robot, H, time_budget=-1.0)


@pytest.mark.parametrize("name", ["baxter_left", "ur5"])
def test_the_analytic_batch_stops_at_its_budget(name):
    """On aadeea0 baxter_left's analytic batch ran 78-101x over a 5 ms budget: the held joint's values and FRDM
    ran whatever the clock said."""
    robot = kinelab.load(name)
    Q = robot.random_qs(100, 1)
    H = robot.fk_batch(Q)
    whole = kinelab.solve_batch(robot, H, solver="analytic", q0=Q)
    assert whole.success.all()
    cut = kinelab.solve_batch(robot, H, solver="analytic", q0=Q, time_budget=1e-9)
    assert not cut.success.any() and (Status.of_codes(cut.status_code) == Status.TIME_BUDGET).all()
    assert np.isnan(cut.q).all()
