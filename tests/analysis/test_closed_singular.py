"""#69: singularities of closed chains, by SVD, in Gosselin and Angeles' two types, against closed forms. The
four-bar's type I configurations are its rocker's dead points (crank and coupler in line: |AC| = a + b or b − a);
its type II (coupler and rocker in line) are where a non-Grashof four-bar stops assembling. The delta's motor-to-
platform map is the classical A⁻¹B of its closed form (A: the forearms, B: each leg's upper arm along its forearm)."""

from pathlib import Path

import numpy as np
import pytest
from helpers import planar_fourbar

import kinelab
from kinelab.analysis import closed_singular as cs

A, B, C, D = 0.10, 0.28, 0.22, 0.30  # the four-bar's crank, coupler, rocker, ground [m]
R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04  # the delta's base radius, upper arm, forearm, platform radius [m]
PHI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)


def dead_points() -> list[float]:
    """The crank angles [rad] where crank and coupler lie in line, C where |AC| = a ± b meets the rocker's circle
    (both mirror images)."""
    angles = []
    for length, flip in ((A + B, 0.0), (B - A, np.pi)):
        x = (length**2 - C**2 + D**2) / (2 * D)
        y = np.sqrt(length**2 - x**2)
        angles += [np.arctan2(y, x) + flip, np.arctan2(-y, x) + flip]
    return angles


def assembled_at(robot: kinelab.Robot, theta: float, point: np.ndarray | None = None) -> np.ndarray:
    """An assembly with the crank at theta; with ``point``, the one whose C is there (both modes tried)."""
    for start in (0.0, 1.0, -1.0, 2.0, -2.0, 3.0):
        q = robot.assemble(np.array([theta, start, start]))
        if point is None or np.abs(robot.frame_placement(q, "rocker_tip").translation[:2] - point).max() < 1e-9:
            return q
    raise AssertionError("no assembly with C there")


def test_the_fourbar_is_type_one_at_its_rocker_dead_points_only() -> None:
    robot = kinelab.load("fourbar")
    for theta in dead_points():
        length = np.hypot(*(A * np.array([np.cos(theta), np.sin(theta)])))
        assert length > 0
        q = robot.assemble(np.array([theta, 0.0, 0.0]))
        tip = robot.frame_placement(q, "rocker_tip").translation[:2]
        if abs(np.linalg.norm(tip) - (A + B)) > 1e-9 and abs(np.linalg.norm(tip) - (B - A)) > 1e-9:
            continue  # the other mode's assembly at this crank angle: not the dead point
        s = cs.analyze(robot, q, "rocker_tip")
        assert s.sigma_serial <= 1e-9 and s.kind == "type I"
    rng = np.random.default_rng(6)
    for theta in rng.uniform(-np.pi, np.pi, 30):
        if min(abs(np.angle(np.exp(1j * (theta - d)))) for d in dead_points()) < 0.1:
            continue
        s = cs.analyze(robot, robot.assemble(np.array([theta, 0.0, 0.0])), "rocker_tip")
        assert s.kind == "regular" and s.sigma_serial > 1e-3 and s.sigma_parallel > 1e-2  # a crank-rocker: no type II


def test_a_non_grashof_fourbar_is_type_two_where_it_stops_assembling() -> None:
    """Crank 0.2, coupler 0.12, rocker 0.1, ground 0.3: at the crank angle where |BD| = b + c the coupler and rocker
    lie in line: 1e-8 rad from it σ_II is 2e-5 (→ 0 as the square root of the distance) and the motion the crank
    gives the rocker unbounded; at a crank angle well inside, regular."""
    a, b, c, d = 0.2, 0.12, 0.1, 0.3
    robot = planar_fourbar(a, b, c, d)
    edge = np.arccos((a * a + d * d - (b + c) ** 2) / (2 * a * d))  # |BD| = b + c
    near = cs.analyze(robot, robot.assemble(np.array([edge - 1e-8, 0.0, 0.0])), "rocker_tip")
    inside = cs.analyze(robot, robot.assemble(np.array([edge - 0.3, 0.0, 0.0])), "rocker_tip")
    assert near.sigma_parallel <= 1e-3 and near.sigma_serial > 100  # the rocker's rate per crank rate blows up
    assert inside.sigma_parallel > 1e-2 and inside.kind == "regular"


def delta_maps(theta: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The delta's A (rows: the forearms s_i = P + p_i − E_i) and B (diagonal: s_i · ∂E_i/∂θ_i): A ẋ = B θ̇."""
    rows, diagonal = [], []
    for phi, t in zip(PHI, theta, strict=True):
        u = np.array([np.cos(phi), np.sin(phi), 0.0])
        elbow = (R + LA * np.cos(t)) * u + np.array([0.0, 0.0, -LA * np.sin(t)])
        s = P + RP * u - elbow
        rows.append(s)
        diagonal.append(s @ (-LA * np.sin(t) * u + np.array([0.0, 0.0, -LA * np.cos(t)])))
    return np.array(rows), np.diag(diagonal)


@pytest.mark.parametrize("seed", range(10))
def test_the_deltas_motor_map_is_its_closed_forms(seed: int) -> None:
    """At a seeded assembly, the type I measure is the smallest singular value of A⁻¹B (1e-9) and the type II
    measure is zero exactly where det A is (both clear of zero here)."""
    robot = kinelab.load("delta")
    home = robot.assemble(robot.neutral())
    theta = np.random.default_rng(seed).uniform(-0.4, 1.2, 3)
    q = home.copy()
    for name, t in zip(("motor_1", "motor_2", "motor_3"), theta, strict=True):
        q[robot.model.joints[robot.model.getJointId(name)].idx_q] = t
    q = robot.assemble(q)
    P = robot.frame_placement(q, "platform_centre").translation
    Am, Bm = delta_maps(theta, P)
    s = cs.analyze(robot, q, "platform_centre")
    assert abs(s.sigma_serial - np.linalg.svd(np.linalg.solve(Am, Bm), compute_uv=False)[-1]) <= 1e-9
    assert abs(np.linalg.det(Am)) > 1e-4 and s.sigma_parallel > 1e-3 and s.kind == "regular"


def test_a_delta_leg_at_a_type_one_singularity(tmp_path: Path) -> None:
    """The delta's motors' range keeps it clear of type I; with motor 1 allowed down to -2 rad (the other two at
    -0.8), its upper arm turns until it lies along its forearm (B₁₁ = 0 by the closed form, found by bisection along
    a path of assemblies): σ_I ≤ 1e-7 there."""
    text = Path(kinelab.load("delta").source or "").read_text().replace('lower="-0.6"', 'lower="-2.0"')
    path = tmp_path / "wide_delta.urdf"
    path.write_text(text)
    robot = kinelab.load(path, closures=list(kinelab.load("delta").closures),
                         actuated=["motor_1", "motor_2", "motor_3"])
    index = [robot.model.joints[robot.model.getJointId(m)].idx_q for m in ("motor_1", "motor_2", "motor_3")]
    q = robot.neutral()
    path_q = [robot.assemble(q)]
    for t in np.linspace(0.0, -0.8, 9)[1:]:  # motors 2 and 3 down the path, then motor 1 (one assembly mode)
        q = path_q[-1].copy()
        q[index[1]] = q[index[2]] = t
        path_q.append(robot.assemble(q))

    def b11(t: float) -> tuple[float, np.ndarray]:
        start = path_q[-1].copy()
        start[index[0]] = t
        found = robot.assemble(start)
        return delta_maps(found[index], robot.frame_placement(found, "platform_centre").translation)[1][0, 0], found

    lo, hi = -1.0, -1.6
    for t in np.linspace(0.0, lo, 11)[1:]:  # motor 1 brought to the bracket along assemblies
        path_q.append(b11(t)[1])
    assert b11(lo)[0] > 0 > b11(hi)[0]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if b11(mid)[0] > 0 else (lo, mid)
    s = cs.analyze(robot, b11(0.5 * (lo + hi))[1], "platform_centre")
    assert s.sigma_serial <= 1e-7 and s.kind in ("type I", "both")


def test_the_command_reads_both_types(capsys: pytest.CaptureFixture[str]) -> None:
    """``kinelab singular fourbar THETA`` at a dead point says type I; a sweep counts and locates each type's
    smallest σ; a wrong count of motors exits 2 naming the motors."""
    from kinelab.cli.main import main

    theta = dead_points()[0]
    assert main(["singular", "fourbar", str(float(theta)), "--output", "rocker_tip", "--json"]) == 0
    import json

    reading = json.loads(capsys.readouterr().out)
    assert reading["kind"] == "type I" and reading["sigma_serial"] <= 1e-9
    assert main(["singular", "delta", "--sweep", "20", "--seed", "3", "--json"]) == 0
    sweep = json.loads(capsys.readouterr().out)
    assert sweep["samples"] == 20 and sweep["no_assembly"] == 0 and sweep["smallest_parallel"]["sigma"] > 1e-3
    assert main(["singular", "fourbar", "1", "2"]) == 2
    assert "one value per motor, 1 in all (crank_joint)" in capsys.readouterr().err


def test_the_singularity_map_of_a_robot_with_loops_finds_the_dead_points(capsys: pytest.CaptureFixture[str]) -> None:
    """``kinelab map singular fourbar`` maps a robot with loops by both types over random motor configurations (the
    sweep's engine): 400 draws find the four-bar's type I near a closed-form dead point (the smallest σ_I's crank
    angle within 0.02 rad of one) and no type II; ``--grid`` is refused in one line, exit 2."""
    import json

    from kinelab.cli.main import main

    assert main(["map", "singular", "fourbar", "--samples", "400", "--seed", "5", "--json"]) == 0
    mapped = json.loads(capsys.readouterr().out)
    assert mapped["samples"] == 400 and mapped["no_assembly"] == 0 and mapped["near_parallel"] == 0
    crank = mapped["smallest_serial"]["motors"][0]
    assert min(abs(np.angle(np.exp(1j * (crank - d)))) for d in dead_points()) <= 0.02
    assert main(["map", "singular", "fourbar", "--grid"]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
