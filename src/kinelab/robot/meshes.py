"""Mesh paths: ``package://`` and relative URIs resolved for Pinocchio and yourdfpy, with a mesh-free fallback.

Kinematics never read meshes. Visual geometry does; where a mesh cannot be found the visual is
dropped with a warning (the robot still loads and still draws its primitive shapes).
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np
import pinocchio as pin

from kinelab.errors import OptionError, URDFError
from kinelab.robot import catalog
from kinelab.robot.folding import reduced
from kinelab.robot.mjcf import is_mjcf, meshes_outside

if TYPE_CHECKING:
    from kinelab.robot import Chain  # the package (chain.py imports this module)


def mesh_package_dirs(user: list[str] | None = None) -> list[str]:
    """Where ``package://`` URIs are looked up, in order: the user's directories, those of
    ``ROS_PACKAGE_PATH``, then example-robot-data's.

    Raises:
        URDFError: a user directory that does not exist (named, with the list given).
    """
    dirs = [str(d) for d in (user or [])]
    for d in dirs:
        if not Path(d).is_dir():
            raise URDFError(f"package directory {d!r} does not exist (package_dirs={dirs})")
    ros = [d for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
    return dirs + ros + catalog.package_dirs()


def search_dirs(package_dirs: list[str] | None) -> list[str]:
    """The directories a robot's meshes are looked up in: ``package_dirs`` as given, or (None) the defaults of
    :func:`mesh_package_dirs`."""
    return mesh_package_dirs() if package_dirs is None else list(package_dirs)


MESH_SUFFIXES = {".stl", ".dae", ".obj", ".ply", ".glb", ".gltf", ".off", ".3ds", ".fbx", ".mesh"}


def _package_candidates(rest: str, dirs: list[str]) -> list[tuple[Path, Path]]:
    """(file, the folder it must stay in) for ``NAME/path`` under each directory: DIR/NAME/path, DIR/path when
    DIR is the package NAME itself, and DIR/*/NAME/path one level down (a workspace's src folder)."""
    name, _, inner = rest.partition("/")
    out = []
    for d in map(Path, dirs):
        out.append((d / rest, d))
        if d.name == name:
            out.append((d / inner, d))
        out += [(package / inner, package) for package in sorted(d.glob(f"*/{name}"))[:1]]
    return out


def _within(path: Path, folder: Path) -> bool:
    """``path`` (links and ``..`` resolved) lies inside ``folder``."""
    try:
        path.resolve().relative_to(folder.resolve())
    except (ValueError, OSError):
        return False
    return True


def resolve_uri(uri: str, urdf_dir: str | Path, package_dirs: list[str] | None = None) -> Path | None:
    """The file a URDF mesh URI names, or None if it cannot be found.

    ``package://NAME/rest`` is looked up under each of ``package_dirs`` (default: :func:`mesh_package_dirs`)
    as described in :func:`_package_candidates`, and must stay inside the folder it was found under (a
    ``package://../../`` URI reaches nothing); ``file://`` and plain paths are taken relative to the URDF, or
    as they are when absolute (the file's author named them). Only mesh files count (by their suffix): a
    URDF cannot make the viewer embed an arbitrary file.
    """
    dirs = mesh_package_dirs() if package_dirs is None else list(package_dirs)
    if uri.startswith("package://"):
        rest = uri[len("package://"):].lstrip("/")  # "package:///name/..." (TALOS full v2) names the same file
        candidates = _package_candidates(rest, dirs) + [(Path(urdf_dir) / rest.split("/", 1)[-1], Path(urdf_dir))]
        found = [c for c, folder in candidates if _within(c, folder)]
    else:
        plain = uri[len("file://"):] if uri.startswith("file://") else uri
        found = [Path(plain) if Path(plain).is_absolute() else Path(urdf_dir) / plain]
    return next((c for c in found if c.suffix.lower() in MESH_SUFFIXES and c.is_file()), None)


def yourdfpy_filename_handler(urdf_path: str | Path, package_dirs: list[str] | None = None):
    """A yourdfpy ``filename_handler`` resolving URIs like :func:`resolve_uri` (unresolved ones pass through)."""
    urdf_dir = Path(urdf_path).parent

    def handler(fname: str) -> str:
        found = resolve_uri(fname, urdf_dir, package_dirs)
        return str(found) if found else fname

    return handler


def missing_meshes(urdf_path: str | Path, package_dirs: list[str] | None = None, kind: str = "visual") -> list[str]:
    """Mesh URIs of the ``<visual>`` (or ``<collision>``, ``kind``) elements that cannot be resolved."""
    root = ET.parse(urdf_path).getroot()
    urdf_dir = Path(urdf_path).parent
    uris = [m.get("filename", "") for el in root.iter(kind) for m in el.iter("mesh")]
    return [u for u in uris if resolve_uri(u, urdf_dir, package_dirs) is None]


def _with_resolved_meshes(urdf_path: Path, package_dirs: list[str], folder: Path, kind: str = "visual") -> Path:
    """A copy of the URDF whose ``kind`` ("visual" or "collision") meshes name the files kinelab resolved
    (absolute paths), and without the elements whose mesh cannot be found: Pinocchio then reads exactly what
    kinelab found."""
    tree = ET.parse(urdf_path)
    for link in tree.getroot().iter("link"):
        for vis in list(link.findall(kind)):
            mesh = vis.find("geometry/mesh")
            if mesh is None:
                continue
            found = resolve_uri(mesh.get("filename", ""), urdf_path.parent, package_dirs)
            if found is None:
                link.remove(vis)
            else:
                mesh.set("filename", str(found.resolve()))
    out = folder / urdf_path.name
    tree.write(out)
    return out


def build_visual_model(
    model: pin.Model, urdf_path: str | Path, package_dirs: list[str] | None = None, kind: str = "visual"
) -> pin.GeometryModel:
    """Pinocchio's VISUAL (or, ``kind="collision"``, COLLISION) geometry of ``model`` (the full, unreduced
    model of the URDF), its meshes found as :func:`resolve_uri` finds them; an element whose mesh cannot be
    found is left out with a warning naming the directories searched."""
    urdf_path = Path(urdf_path)
    dirs = search_dirs(package_dirs)
    missing = missing_meshes(urdf_path, dirs, kind)
    if missing:
        warnings.warn(f"{len(missing)} {kind} mesh(es) of {urdf_path} not found (first: {missing[0]}; searched "
                      f"{', '.join(dirs) or 'no package directory'}); those {kind} elements are left out: pass "
                      "package_dirs= (CLI --package-dir) or set ROS_PACKAGE_PATH", stacklevel=2)
    geometry_type = pin.GeometryType.COLLISION if kind == "collision" else pin.GeometryType.VISUAL
    said: list[str] = []

    with tempfile.TemporaryDirectory(prefix="kinelab-") as folder:  # Pinocchio reads it once, here
        resolved = _with_resolved_meshes(urdf_path, dirs, Path(folder), kind)
        with c_stderr_captured(said):  # urdfdom prints its complaints on the process's stderr
            try:
                geom = pin.buildGeomFromUrdf(model, str(resolved), geometry_type, package_dirs=dirs)
            except ValueError as err:  # coal's mesh loader: a file it cannot read
                said_ = [line.removeprefix("message:").strip() for line in str(err).splitlines()
                         if line.startswith("message:")] or ["no reason given"]
                raise URDFError(f"a {kind} mesh of {urdf_path} cannot be read ({' '.join(said_[0].split())}); fix or "
                                "remove the mesh file") from None
    _check_vertices(geom, urdf_path, kind)
    if said:
        warnings.warn(f"Pinocchio's URDF parser on {urdf_path.name} ({kind} geometry): {' '.join(said)}",
                      stacklevel=2)
    return geom


def _check_vertices(geom: pin.GeometryModel, urdf_path: Path, kind: str) -> None:
    """Refuse a mesh with a vertex that is not a finite number (a NaN in an STL): its collision tests and its
    drawing would be nonsense.

    Raises:
        URDFError: the geometry and its mesh file named.
    """
    for obj in geom.geometryObjects:
        vertices = getattr(obj.geometry, "vertices", None)
        if callable(vertices) and not np.isfinite(np.asarray(vertices())).all():
            raise URDFError(f"{kind} mesh {obj.meshPath or obj.name} of {urdf_path.name} has a vertex that is not a "
                            "finite number; fix the mesh file")


def _anonymous_file() -> BinaryIO:
    """A file with no name, for reading back what C code wrote: in memory on Linux (memfd), else a temporary
    file (whose module every URDF load would otherwise import)."""
    if hasattr(os, "memfd_create"):
        return os.fdopen(os.memfd_create("kinelab-stderr", os.MFD_CLOEXEC), "w+b")

    return tempfile.TemporaryFile(mode="w+b")


@contextlib.contextmanager
def c_stderr_captured(said: list[str]) -> Iterator[None]:
    """File descriptor 2 redirected to an anonymous file for the block; its lines appended to ``said``."""
    sys.stderr.flush()
    saved = os.dup(2)
    with _anonymous_file() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            said.extend(line.strip() for line in sink.read().decode("utf-8", "replace").splitlines() if line.strip())


def geometry_model(chain: Chain, package_dirs: list[str] | None, kind: str) -> pin.GeometryModel:
    """:meth:`kinelab.Chain.visual_model`: the chain's visual (or collision) geometry matched to its model (locked
    joints folded in, re-rooted as the model is), meshes resolved; empty for an in-memory model, or for an MJCF file
    whose meshes lie outside its folder (said in a warning)."""
    if not isinstance(kind, str) or kind not in ("visual", "collision"):
        raise OptionError("kind", kind, '"visual" or "collision"')
    b = chain._built
    if b.urdf_path is None or b.full is None:
        return pin.GeometryModel()  # an in-memory model brings no geometry: the viewer draws a stick figure
    if is_mjcf(b.urdf_path):
        geom = _mjcf_geometry(chain, b.urdf_path, kind)
    else:
        geom = build_visual_model(b.full, b.urdf_path, package_dirs or chain.package_dirs, kind)
    if b.lock_ids and geom.ngeoms:
        _, geom = reduced(b.full, list(b.lock_ids), pin.neutral(b.full) if b.q_ref is None else b.q_ref, geom)
    if b.bMw is not None:  # re-rooted at the base frame, as the model was
        _rerooted(geom, b.bMw)
    return geom


def _mjcf_geometry(chain: Chain, path: Path, kind: str) -> pin.GeometryModel:
    """The whole model's geometry of kind "visual" or "collision" from the chain's MJCF file at ``path``."""
    assert chain._built.full is not None  # a chain read from a file keeps the file's whole model
    return mjcf_geometry(chain._built.full, path, kind)


def mjcf_geometry(model: pin.Model, path: Path, kind: str) -> pin.GeometryModel:
    """The geometry of kind "visual" or "collision" an MJCF file at ``path`` gives its whole ``model``; empty (said
    in a warning) when one of its meshes lies outside the file's folder or Pinocchio cannot build it."""
    outside = meshes_outside(path)
    if outside:  # Pinocchio builds all of a file's geometry or none: none, said
        warnings.warn(f"{path.name}: mesh {outside[0]!r} lies outside the file's folder; kinelab "
                      f"reads no file outside it, so {model.name or path.stem} is drawn without its {kind} geometry",
                      stacklevel=3)
        return pin.GeometryModel()
    geometry_type = pin.GeometryType.COLLISION if kind == "collision" else pin.GeometryType.VISUAL
    try:
        return pin.buildGeomFromMJCF(model, str(path), geometry_type)
    except Exception as exc:  # noqa: BLE001 - the parser raises RuntimeError, ValueError, ...
        warnings.warn(f"{path.name}: Pinocchio cannot build its {kind} geometry ({type(exc).__name__}: {exc}); it is "
                      "drawn without it", stacklevel=3)
        return pin.GeometryModel()


def _rerooted(geom: pin.GeometryModel, bMw: pin.SE3) -> None:
    """Move the objects fixed to the universe into the base frame (in place), as the model was re-rooted."""
    for gid in range(geom.ngeoms):
        obj = geom.geometryObjects[gid]
        if obj.parentJoint == 0:
            obj.placement = bMw * obj.placement
            geom.geometryObjects[gid] = obj
