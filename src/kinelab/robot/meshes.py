"""Mesh paths: ``package://`` and relative URIs resolved for Pinocchio and yourdfpy, with a mesh-free fallback.

Kinematics never read meshes. Visual geometry does; where a mesh cannot be found the visual is
dropped with a warning (the robot still loads and still draws its primitive shapes).
"""

from __future__ import annotations

import tempfile
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from kinelab.robot import catalog


def resolve_uri(uri: str, urdf_dir: str | Path, package_dirs: list[str] | None = None) -> Path | None:
    """The file a URDF mesh URI names, or None if it cannot be found.

    ``package://NAME/rest`` is looked up as ``DIR/NAME/rest`` under each of ``package_dirs`` (default:
    the example-robot-data directories); ``file://`` and plain paths are taken relative to the URDF.
    """
    dirs = catalog.package_dirs() if package_dirs is None else list(package_dirs)
    if uri.startswith("package://"):
        rest = uri[len("package://"):]
        candidates = [Path(d) / rest for d in dirs] + [Path(urdf_dir) / rest.split("/", 1)[-1]]
    else:
        plain = uri[len("file://"):] if uri.startswith("file://") else uri
        candidates = [Path(plain) if Path(plain).is_absolute() else Path(urdf_dir) / plain]
    return next((c for c in candidates if c.is_file()), None)


def yourdfpy_filename_handler(urdf_path: str | Path, package_dirs: list[str] | None = None):
    """A yourdfpy ``filename_handler`` resolving URIs like :func:`resolve_uri` (unresolved ones pass through)."""
    urdf_dir = Path(urdf_path).parent

    def handler(fname: str) -> str:
        found = resolve_uri(fname, urdf_dir, package_dirs)
        return str(found) if found else fname

    return handler


def missing_meshes(urdf_path: str | Path, package_dirs: list[str] | None = None) -> list[str]:
    """Mesh URIs of ``<visual>`` elements that cannot be resolved."""
    root = ET.parse(urdf_path).getroot()
    urdf_dir = Path(urdf_path).parent
    uris = [m.get("filename", "") for m in root.iter("mesh")]
    return [u for u in uris if resolve_uri(u, urdf_dir, package_dirs) is None]


def _without_unresolved_visuals(urdf_path: Path, package_dirs: list[str] | None) -> Path:
    tree = ET.parse(urdf_path)
    for link in tree.getroot().iter("link"):
        for vis in list(link.findall("visual")):
            mesh = vis.find("geometry/mesh")
            if mesh is not None and resolve_uri(mesh.get("filename", ""), urdf_path.parent, package_dirs) is None:
                link.remove(vis)
    out = Path(tempfile.mkdtemp(prefix="kinelab-")) / urdf_path.name
    tree.write(out)
    return out


def build_visual_model(
    model: pin.Model, urdf_path: str | Path, package_dirs: list[str] | None = None
) -> pin.GeometryModel:
    """Pinocchio's VISUAL geometry of ``model`` (the full, unreduced model of the URDF)."""
    urdf_path = Path(urdf_path)
    dirs = catalog.package_dirs() if package_dirs is None else list(package_dirs)
    missing = missing_meshes(urdf_path, dirs)
    if missing:
        warnings.warn(f"{len(missing)} mesh(es) of {urdf_path.name} not found (first: {missing[0]}); "
                      "those visuals are left out", stacklevel=2)
        urdf_path = _without_unresolved_visuals(urdf_path, dirs)
    return pin.buildGeomFromUrdf(model, str(urdf_path), pin.GeometryType.VISUAL, package_dirs=dirs)
