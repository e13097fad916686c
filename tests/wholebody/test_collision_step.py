"""#70: collisions held by the whole-body step. Each row's distance against coal's own (its shapes placed by
Pinocchio's FK and asked directly) and its rate against finite differences of that distance; Baxter's two grippers
commanded through each other stay apart by the margin at every step, and cross when the rows are dropped (the
negative control that makes the test able to fail for that reason); a Panda's hand commanded below a table top stops
at the margin; a start in collision is brought out; bad settings are named."""

import coal
import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import Collisions, Environment, FrameTask, Limits, Obstacle, WholeBody
from kinelab.collision.model import CollisionError
from kinelab.wholebody import clearance
from kinelab.wholebody.subject import as_robot

DT = 0.01
TABLE = Environment((Obstacle("box", (0.6, 0.6, 0.04), xyz=(0.5, 0.0, 0.2), name="table"),
                     Obstacle("capsule", (0.05, 0.4), xyz=(0.3, 0.4, 0.4), name="post")))


def coal_distance(found: clearance.StepCollisions, q: np.ndarray, k: int) -> float:
    """Pair k's distance by coal alone: each shape placed at its joint's placement (Pinocchio's FK) times its own."""
    model, data = found.robot.model, found.robot.model.createData()
    pin.forwardKinematics(model, data, q)
    pair = found.geom.collisionPairs[k]
    shapes = [found.geom.geometryObjects[i] for i in (pair.first, pair.second)]
    placed = [data.oMi[o.parentJoint] * o.placement for o in shapes]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-12  # far below the differences taken of it
    return float(coal.distance(shapes[0].geometry, coal.Transform3s(placed[0].rotation, placed[0].translation),
                               shapes[1].geometry, coal.Transform3s(placed[1].rotation, placed[1].translation),
                               request, result))


def near_rows(robot: kinelab.Robot, found: clearance.StepCollisions, q: np.ndarray) -> clearance.Rows:
    pin.computeJointJacobians(robot.model, robot.data, q)
    return clearance.rows(found, robot, DT)


@pytest.mark.parametrize("name", ["panda", "baxter"])
def test_each_row_is_coal_s_distance_and_its_rate(name: str) -> None:
    """At 40 seeded configurations: every near pair's distance equals coal's (asked to 1e-12) to 1e-6 m (the
    tolerance of GJK in the step), and its row's rate along a random direction equals the central difference of
    coal's distance (h = 1e-5 rad) to 1e-4 m/rad + 1 %, on
    every pair whose nearest feature is the same on both sides (a hull's corner handing over to another makes the
    distance a kink there: those samples, ≤ 20 %, are left out and counted)."""
    robot = as_robot(kinelab.load(name))
    environment = TABLE if name == "panda" else None
    found = clearance.step_collisions(robot, Collisions(environment=environment, margin=0.01, detection=0.3))
    rng = np.random.default_rng(7)
    checked = kinks = 0
    for _ in range(40):
        q = robot.random_q(rng)
        rows = near_rows(robot, found, q)
        for row, k in enumerate(rows.near):
            exact = coal_distance(found, q, int(k))
            assert abs(rows.distances[row] - exact) <= 1e-6
            if rows.distances[row] <= 1e-4:
                continue  # in contact: coal's depth is EPA's, not a smooth function
            u = rng.normal(size=robot.nv)
            h = 1e-5
            plus = coal_distance(found, pin.integrate(robot.model, q, h * u), int(k))
            minus = coal_distance(found, pin.integrate(robot.model, q, -h * u), int(k))
            fd, rate = (plus - minus) / (2 * h), float(rows.A[row] @ u)
            one_sided = (plus - exact) / h
            if abs(fd - one_sided) > 1e-3 * max(1.0, abs(fd)):
                kinks += 1
                continue
            checked += 1
            assert abs(rate - fd) <= 1e-4 + 0.01 * abs(fd), (k, rate, fd)
    assert checked >= 100 and kinks <= 0.2 * (checked + kinks)


def grippers_through_each_other(robot: kinelab.Robot, limits: Limits, steps: int) -> float:
    """Baxter's left gripper sent to the right one's place and the right to the left's, ``steps`` steps of 10 ms
    from the neutral configuration: the least of every monitored pair's distance less the margin after any step."""
    found = clearance.step_collisions(robot, Collisions(margin=0.01))
    q = robot.neutral()
    left, right = robot.hands
    tasks = [FrameTask(left, robot.frame_placement(q, right).translation, task="position"),
             FrameTask(right, robot.frame_placement(q, left).translation, task="position")]
    problem = WholeBody(robot, tasks, limits=limits)
    worst = np.inf
    for _ in range(steps):
        result = problem.step(q, DT)
        assert result.solved, result.status
        q = result.q
        worst = min(worst, found.closest(q)[1])
    return worst


def test_baxter_s_grippers_commanded_through_each_other_stay_apart() -> None:
    """300 steps: every pair clear of the margin less 1e-4 m after every step with the rows; without them the two
    arms cross (a pair 5 cm inside another)."""
    baxter = kinelab.load("baxter")
    assert grippers_through_each_other(baxter, Limits(collisions=Collisions(margin=0.01)), 300) >= -1e-4
    assert grippers_through_each_other(baxter, Limits(), 300) < -0.05


def test_a_hand_sent_below_a_table_stops_on_it() -> None:
    """Panda's hand sent 15 cm below the table top: after 250 steps it rests on the top, every pair clear of the
    margin less 1e-4 m after every step, the nearest pair the table's; the step names it in ``closest``."""
    panda = kinelab.load("panda")
    robot = as_robot(panda)
    spec = Collisions(environment=TABLE, margin=0.01)
    problem = WholeBody(panda, [FrameTask(robot.hands[0], np.array([0.5, 0.0, 0.07]), task="position")],
                        limits=Limits(collisions=spec))
    assert problem.route.startswith("readable: collisions")
    q, worst = rest_on_the_table(panda, 250)
    assert worst >= -1e-4
    result = problem.step(q, DT)
    assert result.closest is not None and "table" in (result.closest.first, result.closest.second)
    assert abs(result.closest.distance - 0.01) <= 1e-3
    assert robot.frame_placement(q, robot.hands[0]).translation[2] > 0.22  # on the top (0.22 m), not through it


def rest_on_the_table(panda: kinelab.Chain, steps: int) -> tuple[np.ndarray, float]:
    """Panda's hand sent 15 cm below the table top for ``steps`` steps: the last q, and the least of every monitored
    pair's distance less the margin after any step."""
    robot = as_robot(panda)
    spec = Collisions(environment=TABLE, margin=0.01)
    found = clearance.step_collisions(robot, spec)
    problem = WholeBody(panda, [FrameTask(robot.hands[0], np.array([0.5, 0.0, 0.07]), task="position")],
                        limits=Limits(collisions=spec))
    q, worst = robot.neutral(), np.inf
    for _ in range(steps):
        q = problem.step(q, DT).q
        worst = min(worst, found.closest(q)[1])
    return q, worst


def test_a_start_in_collision_is_brought_out() -> None:
    """The Panda resting on the table top (the test above), the table raised 2 cm: the start is 1 cm inside; the
    step is never infeasible, the nearest pair's clearance never shrinks, and it clears the margin within 200
    steps."""
    panda = kinelab.load("panda")
    robot = as_robot(panda)
    q, _ = rest_on_the_table(panda, 250)
    raised = Environment((Obstacle("box", (0.6, 0.6, 0.04), xyz=(0.5, 0.0, 0.22), name="table"),))
    spec = Collisions(environment=raised, margin=0.01)
    found = clearance.step_collisions(robot, spec)
    last = found.closest(q)[1]
    assert -0.021 < last < -0.019  # 1 cm inside: 2 cm short of the margin
    problem = WholeBody(panda, [FrameTask(robot.hands[0], np.array([0.5, 0.0, 0.07]), task="position")],
                        limits=Limits(collisions=spec))
    for _ in range(200):
        result = problem.step(q, DT)
        assert result.solved, result.status
        q = result.q
        now = found.closest(q)[1]
        assert now >= min(last, 0.0) - 1e-9
        last = now
    assert last >= -1e-4


def test_the_converged_solve_keeps_clear_and_names_the_nearest_pair() -> None:
    """A target 5 cm below the table top: the solve answers no success (the task cannot be met clear of it), its
    answer clear by the margin, the table named nearest; a target above the table: success, clear."""
    panda = kinelab.load("panda")
    robot = as_robot(panda)
    spec = Collisions(environment=TABLE, margin=0.01)
    hand = robot.hands[0]
    below = kinelab.solve(panda, [FrameTask(hand, np.array([0.5, 0.0, 0.15]), task="position")], seed=0,
                          limits=Limits(collisions=spec), time_budget=None, max_restarts=3)
    assert not below.success
    assert below.closest is not None and below.closest.distance >= 0.01 - 1e-6
    above = kinelab.solve(panda, [FrameTask(hand, np.array([0.45, 0.1, 0.45]), task="position")], seed=0,
                          limits=Limits(collisions=spec), time_budget=None, max_restarts=20)
    assert above.success and above.closest is not None and above.closest.distance >= 0.01


@pytest.mark.parametrize(("value", "words"), [
    (Collisions(), None), ("self", None), (TABLE, None), ("floor", "not valid"), (3, "not valid")])
def test_limits_take_what_collisions_take(value: object, words: str | None) -> None:
    if words is None:
        assert isinstance(Limits(collisions=value).collisions, Collisions)
    else:
        with pytest.raises(CollisionError, match=words):
            Limits(collisions=value)


@pytest.mark.parametrize(("field", "value"), [("detection", 0.0), ("detection", float("nan")), ("gain", 0.0),
                                              ("gain", 1.5), ("gain", True)])
def test_bad_step_settings_are_named(field: str, value: float) -> None:
    with pytest.raises(CollisionError, match=field if field != "gain" else "gain"):
        Collisions(**{field: value})


def test_a_robot_without_collision_geometry_is_refused_by_name() -> None:
    bare = kinelab.Robot.from_model(pin.buildSampleModelManipulator())
    q = bare.neutral()
    with pytest.raises(CollisionError, match="no collision geometry"):
        kinelab.step(bare, q, [FrameTask("effector_body", np.zeros(3), task="position")], DT,
                     limits=Limits(collisions="self"))


def test_the_step_follower_keeps_a_path_clear_of_the_table() -> None:
    """A vertical path of the hand from 25 cm above the table top to 10 cm into it (60 samples, the hand pointing
    down): without collisions every sample is met, through the table; with the table held, every row is clear by
    the margin (coal, every pair), the samples above it met, those the table keeps the hand from left unmet — none
    met by going through."""
    panda = kinelab.load("panda")
    robot = as_robot(panda)
    spec = Collisions(environment=TABLE, margin=0.01)
    found = clearance.step_collisions(robot, spec)
    down = pin.SE3(np.diag([1.0, -1.0, -1.0]), np.zeros(3))
    path = [pin.SE3(down.rotation, np.array([0.5, -0.1, z])) for z in np.linspace(0.47, 0.12, 60)]
    free = kinelab.track(panda, path, follower="step", seed=0)
    assert free.success.all()
    held = kinelab.track(panda, path, follower="step", seed=0, collisions=spec)
    slack = [found.closest(panda.to_pin_q(q))[1] for q in held.q]
    assert min(slack) >= -1e-6
    assert held.success[:20].all() and not held.success[-15:].any()


# Baxter's grippers pressed together, step 8,473 of tools/collision_goals.py's scene: 60 collision rows of rank 12
PRESSED = [0.0, -0.029572588528, -0.283964000852, -1.416580480619, 1.767622993822, 2.639727850732, 0.211576595271,
           -0.414357219397, 0.020832999818, 0.172972306665, -0.594919875579, 1.023020405017, 1.465835931966,
           -2.352980127259, -0.477888542426, -1.581505499064, 1.46e-10]


def test_many_degenerate_rows_still_give_a_step():
    """With the grippers pressed together the rows are many and nearly the same (DAQP's active set cycled there on
    this project's machine; ProxQP then answers): the step is solved and every pair stays clear of the margin."""
    pytest.importorskip("proxsuite")
    baxter = kinelab.load("baxter")
    found = clearance.step_collisions(baxter, Collisions(margin=0.01))
    home = baxter.neutral()
    left, right = baxter.hands
    a, b = baxter.frame_placement(home, left).translation, baxter.frame_placement(home, right).translation
    s = 0.5 - 0.5 * np.cos(2 * np.pi * 8473 * DT / 8.0)
    tasks = [FrameTask(left, a + s * (b - a), task="position"), FrameTask(right, b + s * (a - b), task="position")]
    q = np.array(PRESSED)
    for _ in range(20):
        result = kinelab.step(baxter, q, tasks, DT, limits=Limits(collisions=Collisions(margin=0.01)))
        assert result.solved, result.status
        q = result.q
        assert found.closest(q)[1] >= -1e-4


def test_a_mesh_obstacle_is_kept_at_the_margin(tmp_path):
    """A mesh obstacle (an example-robot-data STL, scaled 2×, in the hand's way; coal's distance from a hull to the
    mesh's triangles): the hand sent into it stops with every pair clear of the margin, the mesh named nearest."""
    import json
    import shutil

    panda = kinelab.load("panda")
    shutil.copy(panda.robot.source.parents[1] / "meshes" / "collision" / "link0.stl", tmp_path / "block.stl")
    (tmp_path / "scene.json").write_text(json.dumps({"obstacles": [
        {"shape": "mesh", "mesh": "block.stl", "size": [2.0], "xyz": [0.5, 0.0, 0.1], "name": "block"}]}))
    spec = Collisions(environment=Environment.from_file(tmp_path / "scene.json"), margin=0.01)
    robot = as_robot(panda)
    found = clearance.step_collisions(robot, spec)
    problem = WholeBody(panda, [FrameTask(robot.hands[0], np.array([0.5, 0.0, 0.1]), task="position")],
                        limits=Limits(collisions=spec))
    q, worst = robot.neutral(), np.inf
    for _ in range(300):
        result = problem.step(q, DT)
        q = result.q
        worst = min(worst, found.closest(q)[1])
    assert worst >= -1e-4 and result.closest is not None and result.closest.second == "block"
    assert abs(result.closest.distance - 0.01) <= 1e-3
