"""COLLADA meshes as their files draw them, for meshcat.

Pinocchio's meshcat visualiser hands a ``.dae`` file to the page as text, and the page's loader loses parts of
some files (the UR5's blue end caps float beside its joints). Here each COLLADA file is read once by trimesh,
every part placed by its node transform, and sent as triangles in the part's own colour, under the node path the
visualiser gave the geometry: its placement (and scale) is still set there, so FK, animations and the teach page
move it unchanged. STL and OBJ files carry no node transforms and keep meshcat's own loaders.
"""

from __future__ import annotations

import functools
import os
from typing import TYPE_CHECKING, Any

import meshcat.geometry as g
import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    import meshcat
    from pinocchio.visualize import MeshcatVisualizer

COLLADA = (".dae",)
DEFAULT_COLOUR = (0xC8C8C8, 1.0)  # a part with no material of its own and no robot-file colour

# one part of a mesh file: vertices (n, 3) float32, faces (m, 3) uint32, (colour 0xRRGGBB, opacity 0–1) or None
Part = tuple[np.ndarray, np.ndarray, "tuple[int, float] | None"]


@functools.lru_cache(maxsize=256)
def _parts(path: str, mtime_ns: int) -> tuple[Part, ...]:
    """The parts of a COLLADA file in its own frame [file units], node transforms applied. ``mtime_ns`` keys the
    cache to the file's version."""
    import trimesh

    scene = trimesh.load(path, force="scene")
    if not isinstance(scene, trimesh.Scene):
        raise ValueError(f"{path}: not a scene")
    parts = []
    for node in scene.graph.nodes_geometry:
        oMpart, name = scene.graph[node]
        mesh = scene.geometry[name]
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            continue
        vertices = trimesh.transform_points(mesh.vertices, oMpart)
        parts.append((vertices.astype(np.float32), np.asarray(mesh.faces, dtype=np.uint32), _colour(mesh)))
    return tuple(parts)


def _colour(mesh: Any) -> tuple[int, float] | None:
    """The part's own colour as 0xRRGGBB and its opacity (0–1), from its material; None when it has none."""
    material = getattr(mesh.visual, "material", None)
    rgba = getattr(material, "main_color", None)
    if rgba is None:
        return None
    r, g, b, a = (int(c) for c in np.asarray(rgba, dtype=float).ravel()[:4])
    return (r << 16) | (g << 8) | b, a / 255.0


def file_parts(path: str) -> tuple[Part, ...]:
    """The parts of the COLLADA file at ``path`` (see :func:`_parts`), read once per version of the file."""
    return _parts(path, os.stat(path).st_mtime_ns)


def is_collada(geometry: pin.GeometryObject) -> bool:
    """Whether the visual geometry is drawn from a COLLADA file."""
    return os.path.splitext(geometry.meshPath)[1].lower() in COLLADA and os.path.isfile(geometry.meshPath)


def draw_collada(viewer: meshcat.Visualizer, geom: pin.GeometryModel, paths: list[str]) -> None:
    """Replace what the page's loader made of each COLLADA geometry by its parts (see the module's docstring).

    Args:
        viewer: the meshcat viewer the geometries are drawn in.
        geom: the visual model; ``paths[i]`` is the meshcat path of ``geom.geometryObjects[i]``.
        paths: the node paths Pinocchio's visualiser gave the geometries.
    """
    for obj, path in zip(geom.geometryObjects, paths, strict=True):
        if not is_collada(obj):
            continue
        try:
            parts = file_parts(obj.meshPath)
        except (OSError, ValueError, KeyError, IndexError, AttributeError):
            continue  # a file trimesh cannot read: the page's own loader keeps drawing it
        node = viewer[path]
        node.delete()
        for k, (vertices, faces, own) in enumerate(parts):
            colour, opacity = own or _file_colour(obj)
            material = g.MeshPhongMaterial(color=colour, transparent=opacity < 1.0, opacity=opacity)
            node[f"part{k}"].set_object(g.TriangularMeshGeometry(vertices, faces), material)


def _file_colour(obj: pin.GeometryObject) -> tuple[int, float]:
    """The robot file's colour for a geometry (its ``<material>``), for parts with no material of their own: the
    mesh's materials win, as RViz draws them."""
    if not obj.overrideMaterial:
        return DEFAULT_COLOUR
    rgba = np.clip(np.asarray(obj.meshColor, dtype=float), 0.0, 1.0)
    return (int(rgba[0] * 255) << 16) | (int(rgba[1] * 255) << 8) | int(rgba[2] * 255), float(rgba[3])


def load_robot(viz: MeshcatVisualizer, root: str) -> None:
    """``viz.loadViewerModel(rootNodeName=root)`` (a Pinocchio ``MeshcatVisualizer``) with every COLLADA visual
    drawn as its file draws it."""
    viz.loadViewerModel(rootNodeName=root)
    model = viz.visual_model
    draw_collada(viz.viewer, model,
                 [viz.getViewerNodeName(obj, pin.GeometryType.VISUAL) for obj in model.geometryObjects])
