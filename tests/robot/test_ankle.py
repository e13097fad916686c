"""#69: the two-rod parallel ankle (urdf/ankle.urdf) against its closed form. For a foot pitch β and roll γ, each
motor's angle has a closed form: the heel point a = Ry(β) Rx(γ) p is a rod's length from the crank's end
m + Ry(θ)(−r, 0, 0), so dx cos θ − dz sin θ = (L² − |d|² − r²) / 2r with d = a − m (two roots; the one nearer zero).
Assembling with the motors at those angles gives back the foot's pitch and roll (1e-10); the step tilts the foot with
the loops held; the solve places the sole."""

import numpy as np
import pinocchio as pin

import kinelab
from kinelab import FrameTask

MOTOR, CRANK, HEEL = np.array([-0.03, 0.04, 0.25]), 0.05, np.array([-0.05, 0.04, 0.0])  # the file's header
ROD = float(np.linalg.norm(MOTOR + [-CRANK, 0.0, 0.0] - HEEL))


def motor_angles(pitch: float, roll: float) -> np.ndarray:
    """The two motors' angles [rad] that put the foot at this pitch and roll (the closed form above)."""
    R = pin.rpy.rpyToMatrix(0.0, pitch, 0.0) @ pin.rpy.rpyToMatrix(roll, 0.0, 0.0)
    out = []
    for side in (1.0, -1.0):
        flip = np.array([1.0, side, 1.0])
        d = R @ (HEEL * flip) - MOTOR * flip
        k = (ROD**2 - d @ d - CRANK**2) / (2 * CRANK)
        base, spread = np.arctan2(-d[2], d[0]), np.arccos(np.clip(k / np.hypot(d[0], d[2]), -1.0, 1.0))
        roots = [np.angle(np.exp(1j * (base + s * spread))) for s in (1.0, -1.0)]
        out.append(min(roots, key=abs))
    return np.array(out)


def index(robot: kinelab.Robot, name: str) -> int:
    return robot.model.joints[robot.model.getJointId(name)].idx_q


def test_the_assembly_gives_back_the_pitch_and_roll_of_the_closed_form() -> None:
    """200 seeded (pitch, roll) within the ankle's limits: the motors set by the closed form, the assembly (from the
    home pose, moved there in four steps) has the foot at that pitch and roll (1e-10) with both loops closed."""
    robot = kinelab.load("ankle")
    motors = [index(robot, "motor_1"), index(robot, "motor_2")]
    home = robot.assemble(robot.neutral())
    rng = np.random.default_rng(694)
    for pitch, roll in zip(rng.uniform(-0.5, 0.5, 200), rng.uniform(-0.3, 0.3, 200), strict=True):
        theta = motor_angles(pitch, roll)
        q = home.copy()
        for w in (0.25, 0.5, 0.75, 1.0):
            q[motors] = w * theta
            q = robot.assemble(q)
        assert abs(q[index(robot, "ankle_pitch")] - pitch) <= 1e-10
        assert abs(q[index(robot, "ankle_roll")] - roll) <= 1e-10
        assert np.abs(robot.closure_error(q)).max() <= 1e-10


def test_both_motors_together_pitch_and_against_each_other_roll() -> None:
    """The closed form's own reading of the mechanism: equal angles for a pure pitch, opposite ones (to a few
    percent: the rods' geometry is not linear) for a pure roll."""
    pitch_only, roll_only = motor_angles(0.3, 0.0), motor_angles(0.0, 0.2)
    assert abs(pitch_only[0] - pitch_only[1]) <= 1e-12 and abs(pitch_only[0]) > 0.1
    assert roll_only[0] * roll_only[1] < 0 and abs(roll_only[0] + roll_only[1]) <= 0.05 * abs(roll_only[0])


def test_the_step_tilts_the_foot_with_its_loops_held() -> None:
    """The sole's orientation driven to a pitch of 0.3 and a roll of -0.2 rad (a 'orientation' task) over 200 steps:
    the loops closed to 1e-9 after each, the foot there at the end (1e-6 rad), the motors where the closed form
    puts them (1e-6)."""
    robot = kinelab.load("ankle")
    q = robot.assemble(robot.neutral())
    goal = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.3, 0.0) @ pin.rpy.rpyToMatrix(-0.2, 0.0, 0.0), np.zeros(3))
    problem = kinelab.WholeBody(robot, [FrameTask("sole", goal, task="orientation")])
    for _ in range(200):
        result = problem.step(q, 0.01)
        assert result.solved
        q = result.q
        assert np.abs(robot.closure_error(q)).max() <= 1e-9
    assert abs(q[index(robot, "ankle_pitch")] - 0.3) <= 1e-6 and abs(q[index(robot, "ankle_roll")] + 0.2) <= 1e-6
    assert np.abs(q[[index(robot, "motor_1"), index(robot, "motor_2")]] - motor_angles(0.3, -0.2)).max() <= 1e-6
