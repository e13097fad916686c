"""#69: a robot's loops held by the step and the converged solve. The four-bar (urdf/fourbar.urdf, crank driven)
follows a coupler point along its coupler curve with every loop closed after every step (1e-9), at its velocity
limit; dropping the closure rows from the step (a negative control here) breaks the velocity limit, so the test can
fail for that reason; starts off the loop are brought back; the converged solve meets its targets with the loop
closed to 1e-10, judged by Pinocchio's FK."""

import numpy as np
import pytest

import kinelab
from kinelab import FrameTask, Limits, WholeBody
from kinelab.wholebody import constraints
from kinelab.wholebody.tasks import TaskError

DT = 0.01
VMAX = 1.0  # [rad/s] every joint's, for this test: the crank's sweep reaches it


def crank_path(robot: kinelab.Robot, steps: int) -> list[np.ndarray]:
    """The coupler tip's positions with the crank swept 0.5 + 1.5 sin(0.006 k) rad (at up to 0.9 rad/s), each
    assembled from the one before (one branch of the loop: on the coupler curve the step follows), then held at the
    last for 100 steps."""
    q, path = robot.assemble(np.array([0.5, 0.0, 0.0])), []
    for k in range(steps):
        q = robot.assemble(np.array([0.5 + 1.5 * np.sin(0.006 * k), q[1], q[2]]))
        path.append(robot.frame_placement(q, "coupler_tip").translation)
    return path + path[-1:] * 100


def follow(robot: kinelab.Robot, targets: list[np.ndarray]) -> tuple[float, float, float]:
    """(largest loop error after a step [m], largest |v| [rad/s], last tip error [m]) along the targets."""
    q = robot.assemble(np.array([0.5, 0.0, 0.0]))
    loop, speed = 0.0, 0.0
    for target in targets:
        result = kinelab.step(robot, q, [FrameTask("coupler_tip", target, task="position")], DT,
                              limits=Limits(velocity=VMAX))
        assert result.solved, result.status
        q = result.q
        loop, speed = max(loop, float(np.abs(robot.closure_error(q)).max())), max(speed, float(np.abs(result.v).max()))
    return loop, speed, float(np.linalg.norm(robot.frame_placement(q, "coupler_tip").translation - targets[-1]))


def test_the_step_holds_the_loop_and_the_velocity_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    """600 steps: the loop closed to 1e-9 after each; |v| within the limit but for the drift's O(|v|² dt) that the
    settle removes (1 %); the tip on its target at the end (1e-6 m). Without the closure rows the QP moves the
    chain as if open and the settle drags the passive joints past the limit (> 1.3 × VMAX)."""
    robot = kinelab.load("fourbar")
    targets = crank_path(robot, 600)
    loop, speed, tip = follow(robot, targets)
    assert loop <= 1e-9 and speed <= VMAX * 1.01 and tip <= 1e-6
    monkeypatch.setattr(constraints.ClosureTask, "add_to",
                        lambda self, rows, robot, q, dt: TaskError(self.label, 0.0, 0.0))
    _, open_speed, _ = follow(robot, targets)
    assert open_speed > 1.3 * VMAX


def test_a_start_off_the_loop_is_brought_back() -> None:
    """A start with the loop open by 0.05 rad at the coupler closes in one step (1e-9), the crank moved no faster
    than the step lets it."""
    robot = kinelab.load("fourbar")
    q = robot.assemble(np.array([0.8, 0.0, 0.0]))
    q[1] += 0.05
    assert np.abs(robot.closure_error(q)).max() > 1e-3
    result = WholeBody(robot, [kinelab.PostureTask(q)]).step(q, DT)
    assert result.solved and np.abs(robot.closure_error(result.q)).max() <= 1e-9


@pytest.mark.parametrize("solver", ["step", "frdm"])
def test_the_converged_solve_closes_the_loop(solver: str) -> None:
    """40 seeded targets from assembled configurations: every solve converges, the tip within 1e-6 m of its target
    by Pinocchio's FK, the loop closed to 1e-10, the joints within their limits."""
    robot = kinelab.load("fourbar")
    start = robot.assemble(np.array([0.5, 0.0, 0.0]))
    rng = np.random.default_rng(691)
    for k, theta in enumerate(rng.uniform(-np.pi, np.pi, 40)):
        target = robot.frame_placement(robot.assemble(np.array([theta, 0.0, 0.0])), "coupler_tip").translation
        out = kinelab.solve(robot, FrameTask("coupler_tip", target, task="position"), q0=start, solver=solver, seed=k)
        assert out.success, (theta, out.status)
        assert np.linalg.norm(robot.frame_placement(out.q, "coupler_tip").translation - target) <= 1e-6
        assert np.abs(robot.closure_error(out.q)).max() <= 1e-10
        assert robot.within_limits(out.q)
        assert out.tasks[-1].label.startswith("loop coupler_tip = rocker_tip")


def test_a_problem_says_why_the_readable_step_answers() -> None:
    problem = WholeBody(kinelab.load("fourbar"), [FrameTask("coupler_tip", np.zeros(3), task="position")])
    assert not problem.compiled and "closes loops" in problem.route
    assert [t.label for t in problem.loops] == ["loop coupler_tip = rocker_tip (xy)"]
