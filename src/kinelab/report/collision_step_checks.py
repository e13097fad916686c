"""``kinelab validate``'s checks of collisions in the whole-body step (:mod:`kinelab.wholebody.clearance`), on a
whole robot with collision geometry: each near pair's distance against coal's own (its shapes placed by Pinocchio's
FK), each row's rate against coal's central difference, and the robot's two hands sent through each other for a
run of steps with every pair held clear of the margin.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from kinelab.collision.model import Collisions
from kinelab.report.check import Check
from kinelab.robot.tree import Robot
from kinelab.wholebody.clearance import StepCollisions, rows, step_collisions
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.problem import WholeBody
from kinelab.wholebody.tasks import FrameTask

SPEC = Collisions(margin=0.01, detection=0.3)  # a wide detection: many pairs' rows checked
H = 1e-5  # [rad or m] the central difference's step
STEPS, DT = 300, 0.01


def collision_step_check(robot: Robot, n: int, seed: int) -> list[Check]:
    """The rows against coal and its differences; the hands sent through each other, every pair clear."""
    if robot.visual_model(kind="collision").ngeoms == 0:
        return [Check(robot.name, "whole body: collisions in the step (no collision geometry: not checked)", 1.0,
                      1.0, "yes/no")]
    found = step_collisions(robot, SPEC)
    (apart, depth), rate, checked = _rows_against_coal(robot, found, min(n, 20), seed)
    rows_of = "whole body: collision rows:"
    out = [Check(robot.name, f"{rows_of} distance of pairs apart against coal's own", apart, 1e-8, "m",
                 f"near pairs at {min(n, 20)} configurations (GJK at 1e-9 in the step)"),
           Check(robot.name, f"{rows_of} depth of pairs in contact against coal's own", depth, 1e-5, "m",
                 "EPA at its own tolerance (1e-6)"),
           Check(robot.name, f"{rows_of} rate against coal's central difference", rate, 1e-4, "m/rad",
                 f"beyond 1 % of the rate, on {checked} pairs whose nearest feature stays (a hull's corner handing "
                 "over is a kink)")]
    if len(robot.hands) == 2:
        slack = _hands_through_each_other(robot)
        out.append(Check(robot.name, f"whole body: collision step: {STEPS} steps, hands sent through each other, "
                                     "least distance less the margin", slack, -1e-4, "m", "coal on every pair",
                         at_least=True))
    return out


def _coal(found: StepCollisions, q: np.ndarray, k: int) -> float:
    """Pair k's distance by coal alone (tolerance 1e-12), each shape at its joint's placement times its own."""
    data = found.robot.model.createData()
    pin.forwardKinematics(found.robot.model, data, q)
    pair = found.geom.collisionPairs[k]
    a, b = (found.geom.geometryObjects[i] for i in (pair.first, pair.second))
    Ma, Mb = data.oMi[a.parentJoint] * a.placement, data.oMi[b.parentJoint] * b.placement
    request = coal.DistanceRequest()
    request.gjk_tolerance = 1e-12
    return float(coal.distance(a.geometry, coal.Transform3s(Ma.rotation, Ma.translation), b.geometry,
                               coal.Transform3s(Mb.rotation, Mb.translation), request, coal.DistanceResult()))


def _rows_against_coal(robot: Robot, found: StepCollisions, count: int, seed: int
                       ) -> tuple[tuple[float, float], float, int]:
    """((largest distance difference of pairs apart, of pairs in contact) [m], largest rate difference beyond 1 %
    [m/rad], rates checked)."""
    rng = np.random.default_rng(seed)
    apart = depth = rate = 0.0
    checked = 0
    for _ in range(count):
        q = robot.random_q(rng)
        pin.computeJointJacobians(robot.model, robot.data, q)
        near = rows(found, robot, DT)
        for row, k in enumerate(near.near):
            exact = _coal(found, q, int(k))
            if exact > 0:
                apart = max(apart, abs(near.distances[row] - exact))
            else:
                depth = max(depth, abs(near.distances[row] - exact))
            if exact <= 1e-4:
                continue  # in contact: EPA's depth, not a smooth function
            u = rng.normal(size=robot.nv)
            plus = _coal(found, pin.integrate(robot.model, q, H * u), int(k))
            minus = _coal(found, pin.integrate(robot.model, q, -H * u), int(k))
            fd = (plus - minus) / (2 * H)
            if abs((plus - exact) - (exact - minus)) / H > 1e-3 * max(1.0, abs(fd)):
                continue  # a kink: the nearest feature changes within the difference
            rate = max(rate, abs(float(near.A[row] @ u) - fd) - 0.01 * abs(fd))
            checked += 1
    return (apart, depth), max(rate, 0.0), checked


def _hands_through_each_other(robot: Robot) -> float:
    """The least of every pair's distance less the margin over the steps (each hand sent to the other's start)."""
    spec = Collisions(margin=0.01)
    found = step_collisions(robot, spec)
    q = robot.standing()
    left, right = robot.hands
    a, b = robot.frame_placement(q, left).translation, robot.frame_placement(q, right).translation
    tasks = [FrameTask(left, b, task="position"), FrameTask(right, a, task="position")]
    tasks += [FrameTask(foot, robot.frame_placement(q, foot)) for foot in robot.feet]
    problem = WholeBody(robot, tasks, limits=Limits(collisions=spec))
    worst = np.inf
    for _ in range(STEPS):
        q = problem.step(q, DT).q
        worst = min(worst, found.closest(q)[1])
    return float(worst)
