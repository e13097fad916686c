"""Collisions in a scene: the obstacles drawn where they stand, and the links in contact coloured red."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import coal
import meshcat.geometry as g
import numpy as np
import pinocchio as pin

from kinelab.collision.model import CollisionModel, Contact
from kinelab.collision.obstacles import Environment, Obstacle
from kinelab.typing import Configuration

if TYPE_CHECKING:
    from kinelab.view.scene import Scene

OBSTACLE_COLOURS = ((0x469990, "teal"), (0x9A6324, "brown"), (0x808000, "olive"), (0x911EB4, "purple"),
                    (0xBFEF45, "lime"), (0xFABED4, "pink"))  # none red (contacts), blue (joints) or orange
CONTACT_COLOR = 0xE6194B
PLANE_SIDE = 4.0  # [m] the square drawn for an (unbounded) plane


def draw_collisions(scene: Scene, model: CollisionModel, q: Configuration) -> list[Contact]:
    """Draw ``model``'s obstacles in ``scene`` and colour red the robot's visuals on the links in contact at q
    (the robot drawn at q first); returns the contacts, which the caption lists."""
    scene.show(q)
    scene.view = "collisions"
    if model.spec is not None and model.spec.environment is not None:
        draw_obstacles(scene, model.spec.environment)
    contacts = model.contacts(q)
    overlay_contacts(scene, model, {n for c in contacts for n in (c.first, c.second)})
    scene.legend["collisions"] = ("red links: in contact — " + "; ".join(str(c) for c in contacts)) if contacts \
        else "no contact at this q (margin " + f"{model.margin:g} m)"
    return contacts


def draw_obstacles(scene: Scene, environment: Environment) -> Scene:
    """Draw the obstacles (translucent, each its own colour, named with it in the caption; a plane as a 4 m
    square) in ``scene``; returns the scene."""
    named = draw_obstacle_nodes(scene.viewer, environment)
    if named:
        scene.legend["obstacles"] = f"{len(named)} obstacle(s), translucent: " + "; ".join(named)
    return scene


def draw_obstacle_nodes(viewer: Any, environment: Environment) -> list[str]:
    """Draw the obstacles under ``viewer["obstacles"]``; returns each one's colour and name, for a legend."""
    named = []
    for k, obstacle in enumerate(environment.obstacles):
        colour, word = OBSTACLE_COLOURS[k % len(OBSTACLE_COLOURS)]
        node = viewer["obstacles"][f"{k}"]
        # faint enough that a red link seen through an obstacle still reads red; no depth writes, so that one
        # translucent surface never hides another (or the robot) behind it
        opacity = 0.15 if obstacle.shape == "plane" else 0.35
        node.set_object(_shape(obstacle), g.MeshLambertMaterial(color=colour, opacity=opacity, transparent=True,
                                                                depthWrite=False))
        node.set_transform(_placement(obstacle).homogeneous)
        named.append(f"{word}: {obstacle.name or 'obstacle ' + str(k + 1)} ({obstacle.shape})")
    return named


def overlay_contacts(scene: Scene, model: CollisionModel, names: set[str]) -> None:
    """The robot's collision objects in contact, drawn red over its visuals at the placements of the last check
    (unlit: a mesh without normals would draw black under a lit material; no depth test: drawn at the mesh's own
    depth, the copy and the mesh would fight pixel by pixel, red and black stripes, and a table would hide it)."""
    scene.viewer["contacts"].delete()  # the contacts of an earlier q
    for k, obj in enumerate(model.geom.geometryObjects):
        if obj.name not in names or obj.parentJoint == 0:
            continue
        shape = _mesh(obj.geometry)
        if shape is None:
            continue
        node = scene.viewer["contacts"][f"{k}"]
        node.set_object(shape, g.MeshBasicMaterial(color=CONTACT_COLOR, opacity=0.7, transparent=True,
                                                   depthTest=False))
        node.set_transform(model.gdata.oMg[k].homogeneous)


def _mesh(geometry: Any) -> Any:
    """A coal geometry as a meshcat one (meshes as triangles; boxes, spheres, cylinders as such), else None."""
    if isinstance(geometry, coal.BVHModelBase):
        tris = [geometry.tri_indices(i) for i in range(geometry.num_tris)]
        return g.TriangularMeshGeometry(np.asarray(geometry.vertices()),
                                        np.array([[t[0], t[1], t[2]] for t in tris], dtype=np.uint32))
    if isinstance(geometry, coal.Box):
        return g.Box(list(2 * np.asarray(geometry.halfSide)))
    if isinstance(geometry, coal.Sphere):
        return g.Sphere(geometry.radius)
    return None


def _shape(obstacle: Obstacle) -> Any:
    s = obstacle.size
    if obstacle.shape == "plane":
        return g.Box([PLANE_SIDE, PLANE_SIDE, 1e-3])
    if obstacle.shape == "box":
        return g.Box(list(s))
    if obstacle.shape == "sphere":
        return g.Sphere(s[0])
    if obstacle.shape == "mesh":
        return _mesh(obstacle.geometry())
    return g.Cylinder(s[1] + (2 * s[0] if obstacle.shape == "capsule" else 0.0), s[0])


def _placement(obstacle: Obstacle) -> pin.SE3:
    """Where meshcat's shape stands: its cylinders run along y, kinelab's (coal's) along z."""
    if obstacle.shape in ("cylinder", "capsule"):
        return obstacle.placement * pin.SE3(pin.rpy.rpyToMatrix(np.pi / 2, 0.0, 0.0), np.zeros(3))
    return obstacle.placement
