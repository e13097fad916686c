"""#69: the delta robot (urdf/delta.urdf, Clavel's geometry) against its closed form. Its platform's position given
the three motor angles is the intersection of three spheres (each forearm's length about its elbow, moved in by the
platform's radius): the assembly puts the platform at one of the two intersections (1e-10) and never turns it; where
the spheres do not meet, no assembly is claimed. The step and the solve move the platform with the loops held."""

from pathlib import Path

import numpy as np
import pytest

import kinelab
from kinelab import AssemblyError, FrameTask

R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04  # base radius, upper arm, forearm, platform radius [m] (the file's header)
PHI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)
MOTORS = ("motor_1", "motor_2", "motor_3")


def platform_closed_form(theta: np.ndarray, forearm: float = LB) -> list[np.ndarray]:
    """The platform centre's two positions (or none) for motor angles theta [rad] (0: arm horizontal, positive:
    down): |P − c_i| = forearm with c_i = the elbow of leg i moved in by the platform's radius."""
    c = np.array([(R + LA * np.cos(t) - RP) * np.array([np.cos(p), np.sin(p), 0.0]) + np.array([0, 0, -LA * np.sin(t)])
                  for p, t in zip(PHI, theta, strict=True)])
    A, b = 2 * (c[1:] - c[0]), (c[1:] ** 2).sum(1) - (c[0] ** 2).sum()
    n = np.cross(A[0], A[1])
    base = np.linalg.lstsq(A, b, rcond=None)[0]  # a point of the line the two planes share
    d = base - c[0]
    qa, qb, qc = n @ n, 2 * d @ n, d @ d - forearm**2
    disc = qb * qb - 4 * qa * qc
    if disc < 0:
        return []
    return [base + s * n for s in ((-qb - np.sqrt(disc)) / (2 * qa), (-qb + np.sqrt(disc)) / (2 * qa))]


def with_motors(robot: kinelab.Robot, q: np.ndarray, theta: np.ndarray) -> np.ndarray:
    out = q.copy()
    for name, t in zip(MOTORS, theta, strict=True):
        out[robot.model.joints[robot.model.getJointId(name)].idx_q] = t
    return out


def test_the_assembly_is_the_closed_form() -> None:
    """200 seeded motor triples within the motors' limits, each assembled from the home pose: the loops closed to
    1e-10, the motors held, the platform where the closed form puts it (one of its two points, 1e-10) and parallel
    to the base (1e-10)."""
    robot = kinelab.load("delta")
    rng = np.random.default_rng(690)
    home = robot.neutral()
    for theta in rng.uniform(-0.6, 1.4, (200, 3)):
        q = robot.assemble(with_motors(robot, home, theta))
        assert np.abs(robot.closure_error(q)).max() <= 1e-10
        assert np.array_equal(with_motors(robot, q, theta), q)
        oMp = robot.frame_placement(q, "platform_centre")
        assert min(np.abs(oMp.translation - p).max() for p in platform_closed_form(theta)) <= 1e-10
        assert np.abs(oMp.rotation - np.eye(3)).max() <= 1e-10


def test_no_assembly_where_the_spheres_do_not_meet(tmp_path: Path) -> None:
    """A delta with 0.25 m forearms: motor triples whose spheres do not meet are refused (AssemblyError with the gap),
    the others assembled to the closed form; both kinds occur among the 80 seeded triples."""
    short = 0.25
    text = Path(kinelab.load("delta").source or "").read_text().replace(f'xyz="0 0 {-LB}"', f'xyz="0 0 {-short}"')
    path = tmp_path / "short_delta.urdf"
    path.write_text(text)
    robot = kinelab.load(path, closures=list(kinelab.load("delta").closures), actuated=list(MOTORS))
    rng = np.random.default_rng(692)
    refused = assembled = 0
    for theta in rng.uniform(-0.6, 1.4, (80, 3)):
        expected = platform_closed_form(theta, short)
        if expected:
            q = robot.assemble(with_motors(robot, robot.neutral(), theta))
            P = robot.frame_placement(q, "platform_centre").translation
            assert min(np.abs(P - p).max() for p in expected) <= 1e-10
            assembled += 1
        else:
            with pytest.raises(AssemblyError) as caught:
                robot.assemble(with_motors(robot, robot.neutral(), theta))
            assert caught.value.residual > 1e-6
            refused += 1
    assert refused >= 10 and assembled >= 10


def test_the_step_moves_the_platform_with_the_loops_held() -> None:
    """The platform driven around a 5 cm circle for 300 steps: every loop closed to 1e-9 after every step, the
    platform kept parallel to the base, on its target at the end (1e-6 m)."""
    robot = kinelab.load("delta")
    q = robot.assemble(robot.neutral())
    centre = robot.frame_placement(q, "platform_centre").translation
    problem = kinelab.WholeBody(robot, [FrameTask("platform_centre", centre, task="position")])
    worst = 0.0
    for k in range(400):
        angle = 2 * np.pi * min(k, 300) / 300
        target = centre + 0.05 * np.array([np.cos(angle) - 1, np.sin(angle), 0.0])
        problem.set_target(0, target)
        result = problem.step(q, 0.01)
        assert result.solved, result.status
        q = result.q
        worst = max(worst, float(np.abs(robot.closure_error(q)).max()))
    oMp = robot.frame_placement(q, "platform_centre")
    assert worst <= 1e-9 and np.abs(oMp.rotation - np.eye(3)).max() <= 1e-9
    assert np.linalg.norm(oMp.translation - centre) <= 1e-6


def test_the_solve_places_the_platform() -> None:
    """30 targets from the closed form (the platform below the base, the mode the home pose is in, for seeded motor
    triples): every solve converges with the platform within 1e-6 m by Pinocchio's FK and the loops closed to
    1e-10, the joints within their limits."""
    robot = kinelab.load("delta")
    home = robot.assemble(robot.neutral())
    rng = np.random.default_rng(693)
    for k, theta in enumerate(rng.uniform(-0.6, 1.4, (30, 3))):
        target = min(platform_closed_form(theta), key=lambda p: p[2])
        out = kinelab.solve(robot, FrameTask("platform_centre", target, task="position"), q0=home, seed=k,
                            time_budget=None, max_restarts=20)
        assert out.success, out.message
        assert np.linalg.norm(robot.frame_placement(out.q, "platform_centre").translation - target) <= 1e-6
        assert np.abs(robot.closure_error(out.q)).max() <= 1e-10 and robot.within_limits(out.q)
