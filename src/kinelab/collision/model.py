"""A robot's collision model: its URDF's ``<collision>`` geometry on the reduced chain, the obstacles around
it, the pairs worth checking, and a conservative sphere per object for a cheap first test.

Pairs: every two robot objects on different joints, except those on adjacent joints (a link and its parent
touch at their joint by design), those the robot's SRDF disables (``disable_collisions``) and those that do
not move relative to each other; and every moving robot object against every obstacle (the base's own
geometry stands where it is mounted). The exact test is Pinocchio's (coal's GJK/EPA on meshes and
primitives), with ``margin`` as coal's security margin.

The first test: each object's axis-aligned box in its own frame, turned into the sphere around it (centre
and half-diagonal, in its joint's frame); a pair whose spheres are farther apart than ``margin`` cannot
collide, so the exact test runs only on the others. A plane's test is the sphere's height above it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.collision.obstacles import Environment, Obstacle
from kinelab.collision.spheres import PLANE, Frames
from kinelab.collision.spheres import candidates as sphere_candidates
from kinelab.errors import KinelabError
from kinelab.robot import Chain, Robot
from kinelab.robot.meshes import mesh_package_dirs, missing_meshes
from kinelab.robot.mjcf import is_mjcf

TOUCH = 1e-6  # [m] pairs this near contact count as colliding (CollisionModel.checked_margin)


class CollisionError(KinelabError):
    """Collisions asked of a robot that has no collision geometry, or a bad collision setting; says which."""


@dataclass(frozen=True)
class Collisions:
    """What a solve must avoid.

    Attributes:
        self_collisions: the robot against itself.
        environment: the obstacles (base frame), or None.
        margin: a clearance every pair must keep [m] (≥ 0).
        detection: the whole-body step only: a pair enters the step's QP once it is nearer than margin + detection
            [m] (> 0); farther pairs cost nothing.
        gain: the whole-body step only: ξ of the velocity damper ḋ ≥ −ξ (d − margin)/dt, in (0, 1] (the share of
            the remaining clearance a step may close).
    """

    self_collisions: bool = True
    environment: Environment | None = None
    margin: float = 0.0
    detection: float = 0.05
    gain: float = 0.5

    def __post_init__(self) -> None:
        if not isinstance(self.self_collisions, bool | np.bool_):
            raise CollisionError(f"self_collisions is True or False, got {self.self_collisions!r}")
        if not _is_clearance(self.margin):
            raise CollisionError(f"the collision margin is a clearance ≥ 0 m, got {self.margin!r}")
        if not _is_clearance(self.detection) or self.detection == 0:
            raise CollisionError(f"the detection distance is a distance > 0 m, got {self.detection!r}")
        if not _is_clearance(self.gain) or not 0 < self.gain <= 1:
            raise CollisionError(f"the collision gain is a number in (0, 1], got {self.gain!r}")
        if self.environment is not None and not isinstance(self.environment, Environment):
            raise CollisionError(f"environment must be a kinelab.Environment, got {type(self.environment).__name__}")
        if not self.self_collisions and self.environment is None:
            raise CollisionError("collisions with neither self_collisions nor an environment check nothing")


def _is_clearance(value: object) -> bool:
    """A finite real number ≥ 0 (not a bool)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and bool(np.isfinite(value)) and value >= 0


def as_collisions(value: object) -> Collisions | None:
    """A :class:`Collisions` from what entry points accept: None (no check), "self", an Environment (itself
    and the obstacles) or a Collisions.

    Raises:
        CollisionError: anything else, named.
    """
    if value is None or isinstance(value, Collisions):
        return value
    if isinstance(value, str) and value == "self":
        return Collisions()
    if isinstance(value, Environment):
        return Collisions(environment=value)
    raise CollisionError(f"collisions={value!r} is not valid: None, 'self', a kinelab.Environment or a "
                         "kinelab.Collisions(self_collisions=, environment=, margin=, detection=, gain=)")


@dataclass(frozen=True)
class Contact:
    """The first colliding pair found: the two objects' names and their distance [m] (≤ margin; negative:
    penetration depth, as coal reports it)."""

    first: str
    second: str
    distance: float

    def __str__(self) -> str:
        return f"{self.first} and {self.second} ({self.distance * 1e3:+.1f} mm)"


@dataclass(eq=False)
class CollisionModel:
    """The geometry, the pairs and the first-test spheres of one robot and one :class:`Collisions`.

    Objects on joint 0 (the base's geometry, the obstacles) stand still; a plane obstacle's first test uses its
    point ``centres`` and unit ``normals`` (base frame).
    """

    robot: Chain
    geom: pin.GeometryModel
    pairs: np.ndarray  # (P, 2) object indices, the moving object first
    centres: np.ndarray  # (G, 3) sphere centres in each object's joint frame [m]
    radii: np.ndarray  # (G,) [m]; PLANE for a plane
    normals: np.ndarray  # (G, 3) a plane's unit normal; zero elsewhere
    joints: np.ndarray  # (G,) each object's parent joint
    margin: float
    summary: str
    spec: Collisions | None = None
    frames: Frames | None = None
    hulls: Any = field(default=None)
    data: Any = field(default=None)
    gdata: Any = field(default=None)
    hdata: Any = field(default=None)

    def __post_init__(self) -> None:
        self.data, self.gdata = self.robot.model.createData(), pin.GeometryData(self.geom)
        self._found = np.empty(len(self.pairs), dtype=np.int64)
        for req in self.gdata.collisionRequests:
            req.security_margin = self.checked_margin

    @property
    def checked_margin(self) -> float:
        """The clearance the checks ask of every pair [m]: ``margin`` and TOUCH (two shapes that touch are one
        collision or none by the exact test's starting guess, which its previous calls leave: a pair is called
        colliding within TOUCH of contact, the same way every time, so that an answer called clear is clear by
        Pinocchio's ``computeCollisions`` at the user's margin)."""
        return self.margin + TOUCH

    def _hull_data(self) -> Any:
        """The convex hulls' geometry data, the hulls computed on the first check (a model built only to say
        what it holds, as ``kinelab info`` does, never runs qhull)."""
        if self.hdata is None:
            self.hulls = _hulls(self.geom)
            self.hdata = pin.GeometryData(self.hulls)
            for req in self.hdata.collisionRequests:
                req.security_margin = self.checked_margin
        return self.hdata

    def contact(self, q: ArrayLike, first_test: bool = True) -> Contact | None:
        """The first pair at q (rad or m, one number per joint) closer than the margin, with its distance, or
        None.

        Args:
            q: the configuration.
            first_test: skip the pairs whose spheres are apart (False: the exact test on every pair).

        Raises:
            ConfigurationError: q not n finite numbers.
        """
        k = self.colliding_pair(q, first_test)
        return None if k is None else self.contact_of(k)

    def contacts(self, q: ArrayLike) -> list[Contact]:
        """Every pair at q closer than the margin, each with its distance (the exact test on the pairs the first
        tests leave)."""
        q = self.robot.check_q(q)
        spheres = self.candidates(q)
        pin.forwardKinematics(self.robot.model, self.data, self.robot.to_pin_q(q))
        pin.updateGeometryPlacements(self.robot.model, self.data, self.geom, self.gdata)
        return [self.contact_of(int(k)) for k in spheres if pin.computeCollision(self.geom, self.gdata, int(k))]

    def colliding_pair(self, q: ArrayLike, first_test: bool = True) -> int | None:
        """The index of the first pair at q closer than the margin, or None (no distance computed: cheaper
        than :meth:`contact`)."""
        q = self.robot.check_q(q)
        model = self.robot.model
        spheres = self.candidates(q) if first_test else np.arange(len(self.pairs))
        if spheres.size == 0:
            return None
        pin.forwardKinematics(model, self.data, self.robot.to_pin_q(q))
        candidates = [int(k) for k in spheres]
        if first_test:  # the convex hulls next: a pair whose hulls are apart cannot collide
            hdata = self._hull_data()
            pin.updateGeometryPlacements(model, self.data, self.hulls, hdata)
            candidates = [k for k in candidates if pin.computeCollision(self.hulls, hdata, k)]
            if not candidates:
                return None
        pin.updateGeometryPlacements(model, self.data, self.geom, self.gdata)
        for k in candidates:
            if pin.computeCollision(self.geom, self.gdata, int(k)):
                return int(k)
        return None

    def candidates(self, q: np.ndarray) -> np.ndarray:
        """The pairs whose spheres the first test cannot separate at q (checked n floats); every pair when the
        compiled test cannot read the chain's joints (:func:`_frames`)."""
        f = self.frames
        if f is None:  # a mimic follower in the chain: no sphere test, the hulls take every pair
            return np.arange(len(self.pairs))
        count = sphere_candidates(q, f.parents, f.place_R, f.place_t, f.axis, f.kind, f.q_index, self.joints,
                                  self.centres, self.radii, self.normals, self.pairs, self.checked_margin,
                                  self._found)
        return self._found[:count]

    def contact_of(self, k: int) -> Contact:
        """Pair k as a :class:`Contact`, its distance computed at the placements of the last check."""
        pair = self.geom.collisionPairs[k]
        distance = pin.computeDistance(self.geom, self.gdata, k).min_distance
        return Contact(self.geom.geometryObjects[pair.first].name, self.geom.geometryObjects[pair.second].name,
                       float(distance))


def collision_model(robot: Chain, collisions: Collisions) -> CollisionModel:
    """The robot's collision model for ``collisions``, built once per Chain and setting.

    Raises:
        CollisionError: the robot has no collision geometry (an in-memory model, or a file without
            ``<collision>`` elements).
    """
    models: dict[Collisions, CollisionModel] = robot.derived("collision models", lambda r: {})
    if collisions not in models:
        models[collisions] = _build(robot, collisions)
    return models[collisions]


def _build(robot: Chain, collisions: Collisions) -> CollisionModel:
    _check_meshes(robot)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # missing meshes were refused above, by name
        geom = robot.visual_model(kind="collision")
    if geom.ngeoms == 0:
        raise CollisionError(f"{robot.name} has no collision geometry (no <collision> element in its file, or a "
                             "model built in memory): collisions cannot be checked")
    found = paired(robot, geom, collisions)
    summary = (f"{found.own} collision object(s) of {robot.name}, {len(found.obstacles)} obstacle(s); "
               f"{len(found.pairs)} pairs checked ({found.left_out[0]} on adjacent links and {found.left_out[1]} "
               f"disabled by the SRDF left out), margin {collisions.margin:g} m")
    return CollisionModel(robot, geom, np.array(found.pairs, dtype=np.int64).reshape(-1, 2), *found.spheres,
                          found.joints, float(collisions.margin), summary, collisions, _frames(robot))


@dataclass(frozen=True)
class Paired:
    """A geometry's objects (the robot's ``own`` first, then the obstacles), their joints, the pairs added to it and
    how many self pairs were left out (adjacent, by the SRDF, by the caller's filter); ``spheres``: the first
    test's centres, radii and normals."""

    objects: list[Any]
    joints: np.ndarray
    own: int
    obstacles: tuple[Obstacle, ...]
    pairs: list[tuple[int, int]]
    left_out: tuple[int, int, int]
    spheres: tuple[np.ndarray, np.ndarray, np.ndarray]


def paired(robot: Chain | Robot, geom: pin.GeometryModel, collisions: Collisions,
           keep: Callable[[list[tuple[int, int]]], list[tuple[int, int]]] | None = None) -> Paired:
    """Append the obstacles to ``geom`` and add every pair worth checking (see the module's docstring): the
    robot's own pairs (those ``keep`` keeps, when given) and every moving object against every obstacle."""
    own = geom.ngeoms
    obstacles = tuple(collisions.environment.obstacles) if collisions.environment is not None else ()
    _add_obstacles(geom, obstacles)
    objects = list(geom.geometryObjects)
    joints = np.array([o.parentJoint for o in objects], dtype=np.int64)
    pairs, (adjacent, by_srdf) = _self_pairs(robot, objects, own) if collisions.self_collisions else ([], (0, 0))
    kept = pairs if keep is None else keep(pairs)
    filtered = len(pairs) - len(kept)
    kept = kept + [(i, own + k) for i in range(own) if joints[i] != 0 for k in range(len(obstacles))]
    for i, j in kept:
        geom.addCollisionPair(pin.CollisionPair(int(i), int(j)))
    return Paired(objects, joints, own, obstacles, kept, (adjacent, by_srdf, filtered),
                  _spheres(objects, own, obstacles))


def _add_obstacles(geom: pin.GeometryModel, obstacles: Sequence[Obstacle]) -> None:
    """Append the obstacles to the model, fixed to the universe (joint 0, frame 0) at their placements."""
    for k, obstacle in enumerate(obstacles):
        geom.addGeometryObject(pin.GeometryObject(obstacle.name or f"{obstacle.shape} {k}", 0, 0,
                                                  obstacle.placement, obstacle.geometry()))


def _frames(robot: Chain) -> Frames | None:
    """The model's joints as the compiled sphere test reads them; None when a joint is not one of the chain's
    (a mimic follower): the sphere test is then skipped."""
    model = robot.model
    index = {j.name: i for i, j in enumerate(robot.joints)}
    if robot.mimics or any(model.names[j] not in index for j in range(1, model.njoints)):
        return None
    J = model.njoints
    axis = np.zeros((J, 3))
    for j in range(1, J):
        axis[j] = robot.joints[index[model.names[j]]].axis_local
    return Frames(np.array(model.parents, dtype=np.int64),
                  np.array([m.rotation for m in model.jointPlacements]),
                  np.array([m.translation for m in model.jointPlacements]), axis,
                  np.array([0] + [int(robot.joints[index[model.names[j]]].kind == "prismatic") for j in range(1, J)],
                           dtype=np.int64),
                  np.array([0] + [index[model.names[j]] for j in range(1, J)], dtype=np.int64))


def _hulls(geom: pin.GeometryModel) -> pin.GeometryModel:
    """The geometry with every mesh replaced by its convex hull (qhull, computed once): a hull contains its
    mesh, so hulls that do not meet are a proof that the meshes do not."""
    hulls = geom.copy()
    for k, obj in enumerate(geom.geometryObjects):
        if isinstance(obj.geometry, coal.BVHModelBase):
            mesh = obj.geometry.clone()
            mesh.buildConvexHull(True, "Qt")
            convex = mesh.convex
            convex.computeLocalAABB()
            hull = pin.GeometryObject(obj)
            hull.geometry = convex
            hulls.geometryObjects[k] = hull
    return hulls


def _check_meshes(robot: Chain) -> None:
    """Refuse a robot whose collision meshes cannot all be found (a missing mesh would be a hole in the check);
    report SRDF pairs that name links the model does not have."""
    path = robot.urdf_path
    if path is not None and not is_mjcf(Path(path)):
        dirs = mesh_package_dirs() if robot.package_dirs is None else list(robot.package_dirs)
        missing = missing_meshes(path, dirs, "collision")
        if missing:
            raise CollisionError(f"{robot.name}: {len(missing)} collision mesh(es) not found (first: {missing[0]}; "
                                 f"searched {', '.join(dirs) or 'no package directory'}): collisions cannot be "
                                 "checked; pass package_dirs= to kinelab.load (CLI --package-dir)")
    _check_srdf_links(robot)


def _check_srdf_links(robot: Chain) -> None:
    """Warn of SRDF pairs that name links the model does not have (they are ignored)."""
    if robot.srdf is None:
        return
    links = {f.name for f in robot.model.frames}
    unknown = sorted({n for pair in robot.srdf.disabled_collisions for n in pair if n not in links})
    if unknown:
        warnings.warn(f"{robot.srdf.path}: disable_collisions names link(s) {', '.join(unknown)} that "
                      f"{robot.name}'s model does not have; those pairs are ignored", stacklevel=4)


def _self_pairs(robot: Chain | Robot, objects: list[Any], own: int) -> tuple[list[tuple[int, int]], tuple[int, int]]:
    """The robot's own pairs worth checking, and how many were left out as adjacent and as SRDF-disabled."""
    parents = robot.model.parents
    link = [robot.model.frames[o.parentFrame].name for o in objects[:own]]
    disabled = {frozenset(p) for p in (robot.srdf.disabled_collisions if robot.srdf is not None else ())}
    pairs, adjacent, by_srdf = [], 0, 0
    for i in range(own):
        for j in range(i + 1, own):
            a, b = objects[i].parentJoint, objects[j].parentJoint
            if a == b:
                continue  # no relative motion
            if parents[a] == b or parents[b] == a:
                adjacent += 1
            elif frozenset((link[i], link[j])) in disabled:
                by_srdf += 1
            else:
                pairs.append((i, j))
    return pairs, (adjacent, by_srdf)


def _spheres(objects: list[Any], own: int, obstacles: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per object: the centre (its joint's frame) and radius of the sphere around its box, and a plane's normal."""
    G = len(objects)
    centres, radii, normals = np.zeros((G, 3)), np.zeros(G), np.zeros((G, 3))
    for g, obj in enumerate(objects):
        if g >= own and obstacles[g - own].shape == "plane":
            centres[g], radii[g] = obj.placement.translation, PLANE
            normals[g] = obj.placement.rotation[:, 2]
            continue
        obj.geometry.computeLocalAABB()
        box = obj.geometry.aabb_local
        lo, hi = np.asarray(box.min_), np.asarray(box.max_)
        centres[g] = obj.placement.act(0.5 * (lo + hi))
        radii[g] = 0.5 * float(np.linalg.norm(hi - lo))
    return centres, radii, normals
