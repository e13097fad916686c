"""Obstacles around a robot: planes, boxes, spheres, cylinders and capsules placed in its base frame.

An :class:`Environment` is a tuple of :class:`Obstacle` built in Python or read from a JSON file::

    {"obstacles": [
        {"shape": "plane", "xyz": [0, 0, 0], "name": "floor"},
        {"shape": "box", "size": [0.8, 1.2, 0.05], "xyz": [0.6, 0, 0.3], "rpy": [0, 0, 0.2], "name": "table"}
    ]}

Sizes in metres: a box's full side lengths (x, y, z); a sphere's radius; a cylinder's and a capsule's radius and
length along their z axis; a mesh's scale (one number, default 1) with ``mesh`` its file (STL, OBJ, DAE, ...;
in an obstacle file, a path relative to that file's folder and inside it; a mesh is its surface: a link
wholly inside a closed mesh that touches none of its triangles is not a contact). A plane is the boundary of the
solid half-space below it: the points whose height along the plane's z axis (its ``rpy`` turned) is below its
``xyz`` are inside the obstacle.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from kinelab.errors import KinelabError
from kinelab.files import as_path, read_text

MAX_OBSTACLES = 1000  # Pinocchio's geometry model keeps an n × n pair table, rebuilt per object: 1000 cost 0.1–0.8 s
MAX_DEPTH = 4  # {"obstacles": [{"size": [...]}]}
MAX_FILE_BYTES = 16 * 2**20  # [bytes] 1000 obstacles take about 150 kB
SIZES = {"plane": 0, "box": 3, "sphere": 1, "cylinder": 2, "capsule": 2, "mesh": 1}


MAX_EXTENT = 1e4  # [m] the largest size or distance of an obstacle (as of a robot's offsets)


class ObstacleError(KinelabError):
    """An obstacle or an obstacle file that cannot be used; names the obstacle and what is valid."""


@dataclass(frozen=True)
class Obstacle:
    """One obstacle, placed in the robot's base frame.

    Attributes:
        shape: "plane", "box", "sphere", "cylinder", "capsule" or "mesh".
        size: the shape's dimensions [m] (see the module's docstring); () for a plane; a mesh's scale (default 1).
        xyz: its position [m]; rpy: its orientation (roll, pitch, yaw [rad], Pinocchio's convention).
        name: a name for messages (default: the shape and its index).
        mesh: a mesh obstacle's file (read when the obstacle is checked).
    """

    shape: str
    size: tuple[float, ...] = ()
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = ""
    mesh: str = ""

    def __post_init__(self) -> None:
        label = self._check_kind()
        given = (1.0,) if self.shape == "mesh" and isinstance(self.size, tuple) and not self.size else self.size
        size, xyz, rpy = _numbers(label, "size", given), \
            _numbers(label, "xyz", self.xyz), _numbers(label, "rpy", self.rpy)
        if len(size) != SIZES[self.shape]:
            raise ObstacleError(f"obstacle {label!r}: a {self.shape} takes {SIZES[self.shape]} size number(s) "
                                f"[m], got {len(size)}")
        if any(s <= 0 for s in size):
            raise ObstacleError(f"obstacle {label!r}: sizes must be > 0 m, got {list(size)}")
        if max((*map(abs, size), *map(abs, xyz))) > MAX_EXTENT:
            raise ObstacleError(f"obstacle {label!r}: its size and position must lie within ±{MAX_EXTENT:g} m, got "
                                f"size {list(size)}, xyz {list(xyz)}")
        if len(xyz) != 3 or len(rpy) != 3:
            raise ObstacleError(f"obstacle {label!r}: xyz and rpy take 3 numbers each")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "xyz", xyz)
        object.__setattr__(self, "rpy", rpy)

    def _check_kind(self) -> str:
        """The obstacle's label for messages, once its shape, name and mesh are checked."""
        if not isinstance(self.shape, str) or not isinstance(self.name, str) or not isinstance(self.mesh, str):
            raise ObstacleError(f"an obstacle's shape, name and mesh are strings, got shape={self.shape!r}, "
                                f"name={self.name!r}, mesh={self.mesh!r}")
        label = self.name or self.shape
        if self.shape not in SIZES:
            raise ObstacleError(f"obstacle {label!r}: unknown shape {self.shape!r}; shapes are {', '.join(SIZES)}")
        if (self.shape == "mesh") != bool(self.mesh):
            raise ObstacleError(f"obstacle {label!r}: a mesh obstacle names its file (mesh=...), and only a mesh does")
        if self.shape == "mesh" and not Path(self.mesh).is_file():
            raise ObstacleError(f"obstacle {label!r}: mesh file {self.mesh} not found")
        return label

    @property
    def placement(self) -> pin.SE3:
        """bMobstacle: the obstacle's frame in the base frame."""
        return pin.SE3(pin.rpy.rpyToMatrix(*self.rpy), np.array(self.xyz))

    def geometry(self) -> Any:
        """The obstacle as a coal shape, in its own frame."""
        if self.shape == "plane":
            return coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)
        if self.shape == "box":
            return coal.Box(*self.size)
        if self.shape == "sphere":
            return coal.Sphere(self.size[0])
        if self.shape == "mesh":
            try:
                return coal.MeshLoader().load(self.mesh, np.full(3, self.size[0]))
            except Exception as exc:  # coal's loader raises its own error types for unreadable files
                raise ObstacleError(f"obstacle {self.name or 'mesh'!r}: cannot read mesh {self.mesh}: {exc}") from None
        return (coal.Cylinder if self.shape == "cylinder" else coal.Capsule)(self.size[0], self.size[1])


def _numbers(label: str, what: str, values: Any) -> tuple[float, ...]:
    try:
        if isinstance(values, str | bytes) or np.ndim(values) != 1 or np.iscomplexobj(values) \
                or any(isinstance(v, bool | np.bool_) for v in values):  # true is no length
            raise TypeError
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ObstacleError(f"obstacle {label!r}: {what} must be numbers, got {values!r}") from None
    if not all(math.isfinite(v) for v in out):
        raise ObstacleError(f"obstacle {label!r}: {what} must be finite numbers, got {list(out)}")
    return out


@dataclass(frozen=True)
class Environment:
    """The obstacles around a robot (base frame)."""

    obstacles: tuple[Obstacle, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.obstacles, list | tuple) or not all(isinstance(o, Obstacle) for o in self.obstacles):
            raise ObstacleError("an Environment holds a list or tuple of Obstacle objects")
        if len(self.obstacles) > MAX_OBSTACLES:
            raise ObstacleError(f"an environment holds at most {MAX_OBSTACLES} obstacles, got {len(self.obstacles)} "
                                "(merge small ones into a box or a mesh obstacle)")
        object.__setattr__(self, "obstacles", tuple(self.obstacles))

    @classmethod
    def from_file(cls, path: str | Path) -> Environment:
        """Read an obstacle file (JSON, see the module's docstring): data only, nothing in it runs.

        Raises:
            ObstacleError: a missing or malformed file, or a bad obstacle (its index named).
        """
        path = as_path(path, "obstacle file", ObstacleError)
        text = read_text(path, "obstacle file", ObstacleError, MAX_FILE_BYTES)
        try:
            data = json.loads(text)
        except ValueError as exc:
            raise ObstacleError(f"cannot read the obstacle file {path}: {exc}") from None
        except RecursionError:
            data = None  # nested past Python's limit: refused below with the others nested too deep
        rows = data.get("obstacles") if isinstance(data, dict) else None
        if not isinstance(rows, list) or _depth(data) > MAX_DEPTH:
            raise ObstacleError(f"{path}: an obstacle file is a JSON object with a list 'obstacles' of objects "
                                f"(nested at most {MAX_DEPTH} deep)")
        if len(rows) > MAX_OBSTACLES:
            raise ObstacleError(f"{path} lists {len(rows)} obstacles; an environment holds at most {MAX_OBSTACLES} "
                                "(merge small ones into a box or a mesh obstacle)")
        return cls(tuple(_obstacle(path, k, row) for k, row in enumerate(rows)))


def _obstacle(path: Path, k: int, row: object) -> Obstacle:
    """Obstacle ``k`` of the file at ``path``, from its JSON object (a mesh resolved beside the file).

    Raises:
        ObstacleError: not an object of the known keys, or a bad obstacle.
    """
    if not isinstance(row, dict) or set(row) - {"shape", "size", "xyz", "rpy", "name", "mesh"}:
        raise ObstacleError(f"{path}: obstacle {k} must be an object with keys shape, size, xyz, rpy, name "
                            "(and mesh)")
    if "mesh" in row:
        row = {**row, "mesh": _inside(path, row["mesh"], k)}
    return Obstacle(**{"name": f"{row.get('shape', '?')} {k}", **row})


def _depth(value: Any) -> int:
    """How deep lists and objects nest in a JSON value (a number or string: 0)."""
    stack, deepest = [(value, 1)], 0
    while stack:
        item, level = stack.pop()
        if isinstance(item, dict | list):
            deepest = max(deepest, level)
            if level <= MAX_DEPTH:
                stack.extend((child, level + 1) for child in (item.values() if isinstance(item, dict) else item))
    return deepest


def _inside(path: Path, mesh: Any, k: int) -> str:
    """A mesh path of an obstacle file, resolved against the file's folder; refused outside it (a file is data:
    it reads nothing beyond what the user pointed at)."""
    folder = path.resolve().parent
    found = (folder / str(mesh)).resolve()
    if not found.is_relative_to(folder):
        raise ObstacleError(f"{path}: obstacle {k}'s mesh {mesh!r} lies outside the file's folder {folder}; put the "
                            "mesh beside the obstacle file")
    return str(found)
