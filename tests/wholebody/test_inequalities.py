"""The step's inequalities as objects of one protocol: the joints' limits (bounds on v), collisions and a user's own
(rows, or bounds where they are single velocities), held by the step and judged by the solve."""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

import kinelab
from kinelab.wholebody import Held, Inequality, JointLimits, Limits
from kinelab.wholebody.limits import bounds, velocity_bounds
from kinelab.wholebody.subject import as_robot


@pytest.fixture(scope="module")
def panda():
    """Panda's chain as the step takes it (its own joints: a Robot)."""
    return as_robot(kinelab.load("panda"))


@dataclass(frozen=True)
class AtLeast(Inequality):
    """One 1-DoF joint at least ``value`` [rad]: a single velocity's bound, ``v ≥ (value − q) / dt``."""

    joint: str
    value: float
    bounded: ClassVar[bool] = True

    @property
    def label(self) -> str:
        return f"{self.joint} ≥ {self.value:g}"

    def _iq(self, robot):
        joint = robot.model.joints[robot.model.getJointId(self.joint)]
        return joint.idx_q, joint.idx_v

    def bounds(self, robot, q, dt, v_prev):
        iq, iv = self._iq(robot)
        lower, upper = np.full(robot.nv, -np.inf), np.full(robot.nv, np.inf)
        lower[iv] = (self.value - q[iq]) / dt
        back = np.zeros(robot.nv, dtype=bool)
        back[iv] = q[iq] < self.value
        return lower, upper, back

    def rows(self, robot, q, dt):
        lower, _, _ = self.bounds(robot, q, dt, None)
        a = np.zeros((1, robot.nv))
        a[0, self._iq(robot)[1]] = 1.0
        return Held(a, lower[self._iq(robot)[1]:self._iq(robot)[1] + 1])

    def slack(self, robot, q):
        return float(q[self._iq(robot)[0]] - self.value)


def test_the_joint_limits_rows_are_its_bounds(panda):
    """JointLimits' rows ``A v ≥ b`` hold exactly where its bounds do: at the bounds' corners, and not 1e-6 past."""
    rng = np.random.default_rng(3)
    limits = JointLimits(velocity=1.0)
    for _ in range(5):
        q = panda.random_q(rng)
        lower, upper, _ = limits.bounds(panda, q, 0.01, None)
        held = limits.rows(panda, q, 0.01)
        for v in (lower, upper):
            assert (held.A @ v >= held.b - 1e-12).all()
        assert not (held.A @ (upper + 1e-6) >= held.b).all()
        assert np.allclose(lower, bounds(panda.space, q, 0.01, velocity_bounds(limits, panda.space), True, None,
                                         None)[0])


def test_the_joint_limits_slack_says_what_within_limits_says(panda):
    rng = np.random.default_rng(4)
    limits = JointLimits()
    for k in range(40):
        q = panda.random_q(rng)
        if k % 2:
            q[k % panda.nq] = panda.upper[k % panda.nq] + rng.uniform(1e-6, 0.2)
        assert (limits.slack(panda, q) >= 0.0) == panda.within_limits(q)


def test_a_bounded_inequality_is_intersected_with_the_joint_limits(panda):
    """A joint pulled by a posture toward −2.5 rad, a user's bound holding it ≥ −1.0: by the joint's own value,
    never below −1.0 (1e-9) over 100 steps, it comes to rest at −1.0 (1e-4), every step within the joint limits;
    the readable step answered (the compiled one has no block for a user's inequality)."""
    name = panda.joint_names[3]
    idx = panda.joint_names.index(name)
    q = panda.neutral()
    q[idx] = -0.5
    target = q.copy()
    target[idx] = -2.5
    problem = kinelab.WholeBody(panda, [kinelab.PostureTask(target)],
                                limits=Limits(inequalities=(AtLeast(name, -1.0),)))
    assert not problem.compiled and "inequalities" in problem.route
    for _ in range(100):
        q = problem.step(q, 0.02).q
        assert q[idx] >= -1.0 - 1e-9 and panda.within_limits(q)
    assert abs(q[idx] + 1.0) <= 1e-4


def test_the_joint_limits_alone_keep_the_compiled_step(panda):
    problem = kinelab.WholeBody(panda, [kinelab.PostureTask(panda.neutral())], limits=Limits(velocity=2.0))
    assert problem.limits.joints == JointLimits(True, 2.0, None)
    assert problem.compiled == problem.limits.compiled  # only the joints' limits: nothing keeps it off


def test_an_inequality_that_is_not_bounded_has_no_bounds(panda):
    @dataclass(frozen=True)
    class Rowed(Inequality):
        @property
        def label(self):
            return "rowed"

        def rows(self, robot, q, dt):
            return Held(np.zeros((0, robot.nv)), np.zeros(0))

        def slack(self, robot, q):
            return 0.0

    with pytest.raises(kinelab.OptionError, match="bounded"):
        Rowed().bounds(panda, panda.neutral(), 0.01, None)


def test_joint_limits_check_their_fields():
    with pytest.raises(kinelab.OptionError, match="velocity"):
        JointLimits(velocity=-1.0)
    with pytest.raises(kinelab.OptionError, match="position"):
        Limits(position="yes")


def test_the_compiled_steps_outcomes_say_what_the_readable_step_says():
    """Every flag of the compiled step is an Outcome whose words are the readable step's status for it: DAQP's exit
    flags as its documentation names them, the overflow as the readable step's 'not finite'."""
    from kinelab.wholebody.compiled import Outcome
    from kinelab.wholebody.qp import DAQP_STATUS, NOT_FINITE

    daqp = {1: "solved", 2: "solved", -1: "infeasible", -2: "cycling", -3: "unbounded", -4: "iteration limit",
            -5: "not convex", -6: "initial active set infeasible"}
    for flag, words in daqp.items():
        assert Outcome(flag).words == words == DAQP_STATUS[flag] and Outcome(flag).solved == (flag > 0)
    assert Outcome(-101).words == NOT_FINITE == "not finite" and not Outcome(-100).solved
