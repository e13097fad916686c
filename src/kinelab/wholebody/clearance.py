"""Collision avoidance as rows of the whole-body step: the robot's own pairs and the obstacles around it, each near
pair one inequality of the QP (a velocity damper on its distance).

The geometry is the robot's ``<collision>`` geometry with every mesh replaced by its convex hull (a hull contains
its mesh: hulls kept apart keep the meshes apart, and coal's GJK/EPA gives a hull pair's signed distance, depth
included, where two meshes only say that they touch), and the obstacles of the :class:`~kinelab.Collisions` value
(world frame; a chain's base frame). The pairs: every two robot objects on different joints, except those on
adjacent joints, those its SRDF disables and those whose hulls already touch at the neutral configuration (within
0.1 mm: they touch by design, as the "default" collisions MoveIt's setup assistant leaves out); every moving object
against every obstacle. A self pair nearer than the margin at the neutral configuration is left out as well: its
design cannot keep the margin (Baxter's shoulder and elbow shells are 4 mm apart), and the neutral configuration
keeps every pair that is held.

Each step: a sphere about each object (its box's, in its joint's frame) says which pairs may be nearer than
``margin + detection`` (the broadphase: the others cost nothing); coal's distance of each of those gives d, the
nearest points p₁, p₂ and the normal n from the first object to the second. With J(p) the world-aligned Jacobian of
a point fixed on an object's joint, ḋ = nᵀ(J₂(p₂) − J₁(p₁)) v, and the row is the velocity damper

    nᵀ(J₂(p₂) − J₁(p₁)) v ≥ −ξ (d − margin) / dt,

which lets a pair close at most the share ξ of its clearance in one step and, from a start nearer than ``margin``
(or in contact), asks it apart at the same rate (capped at what the velocity bounds allow: never infeasible by
itself).

:class:`Clearance` is that, as an inequality of the step (:class:`~kinelab.wholebody.constraints.Inequality`):
``Limits(collisions=...)`` holds one.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pinocchio as pin

from kinelab.collision.model import CollisionError, Collisions, Contact, _hulls, paired
from kinelab.collision.spheres import PLANE
from kinelab.ik.result import Status
from kinelab.robot.tree import Robot
from kinelab.wholebody.constraints import Held, Inequality

WORLD = pin.ReferenceFrame.WORLD

SETTLE = 1e-5  # [m] the rows hold margin + SETTLE: a damper meets its bound from above, and a solve's answer is clear
GJK_TOLERANCE = 1e-9  # coal's default (1e-6) leaves far pairs' nearest points, hence their rows' normals, off by 1e-3
TOUCHING = 1e-4  # [m] self pairs nearer than margin + TOUCHING at the neutral configuration are left out


@dataclass(eq=False)
class StepCollisions:
    """One robot's collision geometry and pairs for one :class:`~kinelab.Collisions` value, with their scratch.

    Attributes:
        geom: the hulls and obstacles; pairs: (P, 2) object indices (the moving one first); joints: (G,) each
        object's parent joint; centres, radii, normals: the broadphase's spheres (a plane: PLANE and its normal);
        spec: the value; summary: what is checked, in words.
    """

    robot: Robot
    geom: pin.GeometryModel
    pairs: np.ndarray
    joints: np.ndarray
    centres: np.ndarray
    radii: np.ndarray
    normals: np.ndarray
    spec: Collisions
    summary: str
    gdata: pin.GeometryData = field(init=False)
    after: pin.Data = field(init=False)
    last: tuple[bytes, tuple[Contact | None, float]] | None = field(init=False, default=None)

    def __post_init__(self) -> None:
        self.gdata = pin.GeometryData(self.geom)
        self.after = self.robot.model.createData()  # the scratch of the placements at a step's answer
        for request in self.gdata.distanceRequests:
            request.gjk_tolerance = GJK_TOLERANCE

    def near(self, data: pin.Data, reach: float) -> np.ndarray:
        """The pairs whose spheres are nearer than ``reach`` [m] at the placements in ``data`` (``oMi``)."""
        R = np.array([m.rotation for m in data.oMi])
        t = np.array([m.translation for m in data.oMi])
        world = np.einsum("gij,gj->gi", R[self.joints], self.centres) + t[self.joints]
        a, b = self.pairs[:, 0], self.pairs[:, 1]
        gap = np.linalg.norm(world[a] - world[b], axis=1) - self.radii[a] - self.radii[b]
        plane = self.radii[b] == PLANE
        if plane.any():
            gap[plane] = np.einsum("ij,ij->i", world[a[plane]] - self.centres[b[plane]],
                                   self.normals[b[plane]]) - self.radii[a[plane]]
        return np.flatnonzero(gap < reach)

    def distances(self, data: pin.Data, pairs: np.ndarray) -> list[pin.DistanceResult]:
        """coal's distance of each pair at the placements in ``data`` (its nearest points and normal in the world)."""
        pin.updateGeometryPlacements(self.robot.model, data, self.geom, self.gdata)
        return [pin.computeDistance(self.geom, self.gdata, int(k)) for k in pairs]

    def contact(self, k: int, distance: float) -> Contact:
        """Pair k's names with a distance [m]."""
        pair = self.geom.collisionPairs[int(k)]
        names = self.geom.geometryObjects
        return Contact(names[pair.first].name, names[pair.second].name, float(distance))

    def closest(self, q: np.ndarray) -> tuple[Contact | None, float]:
        """The nearest pair at q over every pair, and the least of each pair's distance less its clearance [m]
        (< 0: a pair nearer than it keeps); (None, inf) without pairs. The last q's answer is kept: a solve's
        verdict asks for the slack and the pair at the same q."""
        if len(self.pairs) == 0:
            return None, float("inf")
        key = np.asarray(q, dtype=float).tobytes()
        if self.last is not None and self.last[0] == key:
            return self.last[1]
        data = self.robot.model.createData()
        pin.forwardKinematics(self.robot.model, data, q)
        d = np.array([r.min_distance for r in self.distances(data, np.arange(len(self.pairs)))])
        k = int(np.argmin(d))
        found = self.contact(k, d[k]), float(d[k] - self.spec.margin)
        self.last = (key, found)
        return found


def step_collisions(robot: Robot, collisions: Collisions) -> StepCollisions:
    """The robot's step geometry for ``collisions``, built once per robot and value.

    Raises:
        CollisionError: the robot has no collision geometry.
    """
    built: dict[Collisions, StepCollisions] = robot.derived("step collisions", lambda r: {})
    if collisions not in built:
        built[collisions] = _build(robot, collisions)
    return built[collisions]


def _build(robot: Robot, collisions: Collisions) -> StepCollisions:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        own_geom = robot.visual_model(kind="collision")
    if own_geom.ngeoms == 0:
        raise CollisionError(f"{robot.name} has no collision geometry (no <collision> element in its file, or a "
                             "model built in memory): the step cannot keep its links apart")
    geom = _hulls(own_geom)
    found = paired(robot, geom, collisions,
                   keep=lambda pairs: _apart_at_neutral(robot, geom, pairs, collisions.margin + TOUCHING))
    adjacent, by_srdf, near = found.left_out
    summary = (f"{found.own} collision object(s) of {robot.name} (convex hulls), {len(found.obstacles)} obstacle(s); "
               f"{len(found.pairs)} pairs ({adjacent} adjacent, {by_srdf} disabled by the SRDF and {near} within the "
               f"margin at the neutral configuration left out), margin {collisions.margin:g} m")
    return StepCollisions(robot, geom, np.array(found.pairs, dtype=np.int64).reshape(-1, 2), found.joints,
                          *found.spheres, collisions, summary)


def _apart_at_neutral(robot: Robot, geom: pin.GeometryModel, pairs: list[tuple[int, int]], apart: float
                      ) -> list[tuple[int, int]]:
    """The self pairs whose hulls are farther than ``apart`` [m] at the neutral configuration."""
    if not pairs:
        return pairs
    probe = geom.copy()
    for i, j in pairs:
        probe.addCollisionPair(pin.CollisionPair(int(i), int(j)))
    data, gdata = robot.model.createData(), pin.GeometryData(probe)
    pin.updateGeometryPlacements(robot.model, data, probe, gdata, robot.neutral())
    d = np.array([pin.computeDistance(probe, gdata, k).min_distance for k in range(len(pairs))])
    return [pairs[k] for k in np.flatnonzero(d > apart)]


@dataclass(frozen=True)
class Rows:
    """The step's collision rows A v ≥ b, the pairs near at the step's start (indices into ``pairs``) with their
    distances [m], and the nearest of them (None: none near)."""

    A: np.ndarray
    b: np.ndarray
    near: np.ndarray
    distances: np.ndarray
    closest: Contact | None


def rows(found: StepCollisions, robot: Robot, dt: float) -> Rows:
    """The velocity damper of every pair nearer than margin + detection, at the placements and joint Jacobians in
    ``robot.data`` (``computeJointJacobians`` run at the step's q).

    Args:
        found: the step geometry (:func:`step_collisions`).
        robot: its robot.
        dt: the step [s].
    """
    spec, data = found.spec, robot.data
    hold = spec.margin + SETTLE
    near = found.near(data, hold + spec.detection)
    if near.size == 0:
        return Rows(np.zeros((0, robot.nv)), np.zeros(0), near, np.zeros(0), None)
    results = found.distances(data, near)
    d = np.array([r.min_distance for r in results])
    keep = np.flatnonzero(d < hold + spec.detection)
    near, d, results = near[keep], d[keep], [results[i] for i in keep]
    if near.size == 0:
        return Rows(np.zeros((0, robot.nv)), np.zeros(0), near, d, None)
    A = _rates(found, data, near, *_witnesses(results))
    k = int(np.argmin(d))
    return Rows(A, -spec.gain * (d - hold) / dt, near, d, found.contact(near[k], d[k]))


def overshoot(found: StepCollisions, robot: Robot, start: Rows, v: np.ndarray, q_next: np.ndarray, dt: float
              ) -> tuple[np.ndarray, np.ndarray] | None:
    """Rows for the pairs a step's answer brings nearer than it may (None: none; :func:`too_near`). The damper is
    first-order on the nearest points at the start, and a step can leave it two ways: a pair's nearest points
    change within the step (another corner of a hull comes nearest), and the distance curves (a rotation's second
    order). So the points found at ``q_next`` are carried back to the start on their objects and held there as one
    more row each, asking in addition for what the first order missed: the new row's linear prediction of the
    distance at ``q_next`` less the distance found there.

    Args:
        found: the step geometry.
        robot: its robot (``robot.data``: the start's placements and Jacobians).
        start: the rows at the start (:func:`rows`).
        v: the step's answer [nv].
        q_next: where it goes, q ⊕ v·dt.
        dt: the step [s].

    Returns:
        (A, b) of the new rows, or None.
    """
    after, pairs, results = too_near(found, robot, start, q_next)
    if not pairs.size:
        return None
    data, hold = robot.data, found.spec.margin + SETTLE
    p1, p2, n = _witnesses(results)
    joints = found.joints[found.pairs[pairs]]
    p1 = np.array([_carried(data, after, j, p) for j, p in zip(joints[:, 0], p1, strict=True)])
    p2 = np.array([_carried(data, after, j, p) for j, p in zip(joints[:, 1], p2, strict=True)])
    A = _rates(found, data, pairs, p1, p2, n)
    d = np.einsum("ij,ij->i", n, p2 - p1)
    missed = np.maximum(d + (A @ v) * dt - np.array([r.min_distance for r in results]), 0.0)
    return A, (-found.spec.gain * (d - hold) + missed) / dt


def too_near(found: StepCollisions, robot: Robot, start: Rows, q_next: np.ndarray
             ) -> tuple[pin.Data, np.ndarray, list[pin.DistanceResult]]:
    """The placements at ``q_next``, and the pairs that end nearer than they may there with their distances:
    nearer than the margin, or (a pair that started nearer) than it started. Every pair is looked at — the near
    ones at the start, and any whose spheres are within the margin at ``q_next`` (a fast step can bring a far pair
    from beyond the detection distance)."""
    after = found.after
    pin.forwardKinematics(robot.model, after, q_next)
    pairs = np.union1d(start.near, found.near(after, found.spec.margin))
    results = found.distances(after, pairs)
    started = dict(zip(start.near.tolist(), start.distances.tolist(), strict=True))
    low = [i for i, (k, r) in enumerate(zip(pairs.tolist(), results, strict=True))
           if r.min_distance < min(found.spec.margin, started.get(k, np.inf)) - 1e-9]
    return after, pairs[low], [results[i] for i in low]


def _witnesses(results: list[pin.DistanceResult]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(m, 3) each: the nearest points on the first and second objects and the normal from the first to the second
    (world frame)."""
    p1 = np.array([r.getNearestPoint1() for r in results], dtype=float).reshape(-1, 3)
    p2 = np.array([r.getNearestPoint2() for r in results], dtype=float).reshape(-1, 3)
    n = np.array([r.normal for r in results], dtype=float).reshape(-1, 3)
    return p1, p2, n


def _carried(data: pin.Data, after: pin.Data, joint: int, point: np.ndarray) -> np.ndarray:
    """A world point at ``after``'s placements, fixed on ``joint``, where it is at ``data``'s."""
    return np.asarray(data.oMi[int(joint)].act(after.oMi[int(joint)].actInv(np.asarray(point, dtype=float))))


def _rates(found: StepCollisions, data: pin.Data, pairs: np.ndarray, p1: np.ndarray, p2: np.ndarray,
           normals: np.ndarray) -> np.ndarray:
    """(m, nv): nᵀ(J₂(p₂) − J₁(p₁)) of each pair, the rate at which its points p₁ (on its first object) and p₂ (on
    its second) part along n. With joint j's world Jacobian (``computeJointJacobians`` run), a point p it carries
    moves at J_lin v + ω × p, so nᵀ J(p) = nᵀ J_lin + (p × n)ᵀ J_ang (zero for the world's joint 0)."""
    joints = found.joints[found.pairs[pairs]]
    model = found.robot.model
    world = {0: np.zeros((6, model.nv))}
    for j in np.unique(joints):
        if j != 0:
            world[int(j)] = pin.getJointJacobian(model, data, int(j), WORLD)
    out = np.zeros((len(pairs), model.nv))
    for side, (points, sign) in enumerate(((p1, -1.0), (p2, 1.0))):
        J = np.stack([world[int(j)] for j in joints[:, side]])
        out += sign * (np.einsum("mi,miv->mv", normals, J[:, :3])
                       + np.einsum("mi,miv->mv", np.cross(points, normals), J[:, 3:]))
    return out


@dataclass(frozen=True)
class Clearance(Inequality):
    """Every monitored pair kept ``margin`` apart (an inequality of the step: a row per near pair).

    Attributes:
        collisions: the pairs, obstacles, margin, detection distance and gain (:class:`~kinelab.Collisions`).
    """

    collisions: Collisions
    broken: ClassVar[Status] = Status.COLLISION

    @property
    def label(self) -> str:
        """The inequality in words."""
        return f"every pair {self.collisions.margin:g} m apart"

    def check(self, robot: Robot) -> None:
        """Build the robot's step geometry (once per robot and value).

        Raises:
            CollisionError: the robot has no collision geometry.
        """
        step_collisions(robot, self.collisions)

    def rows(self, robot: Robot, q: np.ndarray, dt: float) -> Held:
        """The velocity damper of every near pair (:func:`rows`)."""
        found = step_collisions(robot, self.collisions)
        start = rows(found, robot, dt)
        return Held(start.A, start.b, closest=start.closest, memo=(found, start))

    def overshoot(self, robot: Robot, held: Held, v: np.ndarray, q_next: np.ndarray, dt: float
                  ) -> tuple[np.ndarray, np.ndarray] | None:
        """The pairs the answer brings nearer than it may, carried back as rows (:func:`overshoot`)."""
        found, start = held.memo
        return overshoot(found, robot, start, v, q_next, dt)

    def breaks(self, robot: Robot, held: Held, q_next: np.ndarray) -> bool:
        """Whether a pair ends nearer than it may (:func:`too_near`)."""
        found, start = held.memo
        return bool(too_near(found, robot, start, q_next)[1].size)

    def slack(self, robot: Robot, q: np.ndarray) -> float:
        """The nearest pair's distance less the margin [m] (inf: no pairs)."""
        return step_collisions(robot, self.collisions).closest(q)[1]

    def nearest(self, robot: Robot, q: np.ndarray) -> Contact | None:
        """The nearest pair over every monitored pair (coal's distance)."""
        return step_collisions(robot, self.collisions).closest(q)[0]
