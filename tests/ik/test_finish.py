"""FRDM's Newton finish: the default mode converges quadratically near the answer; the paper's FRDM
(``finish="none"``) stays one option away and computes what it computed before the finish existed."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import kinelab

DATA = Path(__file__).with_name("data")


def test_the_pure_option_reproduces_the_answers_pinned_before_the_finish_bit_for_bit():
    sys.path.insert(0, str(DATA))
    try:
        import make_frdm_pure
    finally:
        sys.path.remove(str(DATA))
    pinned = np.load(DATA / "frdm_pure.npz")
    now = make_frdm_pure.answers({"finish": "none"})
    assert sorted(now) == sorted(pinned.files)
    for key in pinned.files:
        assert np.array_equal(now[key], pinned[key]), key


@pytest.mark.parametrize("name", ["ur5", "panda", "era"])
def test_the_finish_converges_from_warm_starts_in_fewer_iterations_and_reports_itself(name):
    robot = kinelab.load(name)
    rng = np.random.default_rng(11)
    newton_sweeps, pure_sweeps = [], []
    for _ in range(20):
        q = robot.random_q(rng)
        target = robot.fk(q)
        q0 = np.clip(q + rng.normal(0, 0.02, q.size), robot.lower, robot.upper)
        fast = kinelab.solve(robot, target, q0=q0, seed=0, max_restarts=0, time_budget=None)
        pure = kinelab.solve(robot, target, q0=q0, seed=0, max_restarts=0, time_budget=None, finish="none")
        dp, dr = robot.tool_error(fast.q, target)  # the oracle's own check, beside the result's
        assert fast.success and dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(fast.q)
        assert fast.mode == "frdm+newton" and pure.mode == "frdm" and pure.diagnostics.newton_steps == 0
        newton_sweeps.append(fast.diagnostics.sweeps + fast.diagnostics.newton_steps)
        pure_sweeps.append(pure.diagnostics.sweeps)
    # a Gauss–Newton step costs about one sweep; quadratic convergence needs fewer of them than linear
    assert np.median(newton_sweeps) < np.median(pure_sweeps)


def test_finish_options_are_checked():
    ur5 = kinelab.load("ur5")
    target = ur5.fk(ur5.random_q(0))
    for bad in ({"finish": "lm"}, {"finish_below": -1.0}, {"finish_steps": 0}, {"finish_steps": 2.5}):
        with pytest.raises(kinelab.OptionError, match=next(iter(bad))):
            kinelab.solve(ur5, target, **bad)
