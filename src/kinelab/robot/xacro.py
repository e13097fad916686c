"""xacro files, expanded to URDF by xacrodoc (the optional extra ``kinelab[xacro]``).

kinelab reads the expanded URDF like any other; ``package://`` URIs are kept for the mesh search of
:mod:`kinelab.robot.meshes`. The expansion is written to a temporary folder, never next to the user's file.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from kinelab.errors import URDFError

INSTALL_HINT = "pip install 'kinelab[xacro]' (xacrodoc)"


def is_xacro(path: Path) -> bool:
    """True for a ``.xacro`` file (``robot.urdf.xacro`` included)."""
    return path.suffix == ".xacro"


def expand(path: Path, args: dict[str, str] | None = None) -> Path:
    """The URDF that the xacro file at ``path`` expands to with ``args`` (xacro arguments, name → value).

    Raises:
        URDFError: xacrodoc missing (with the install hint), a missing file, or a file xacro cannot expand
            (xacro's reason: a missing argument, an undefined property or macro).
    """
    try:
        from xacrodoc import XacroDoc  # optional extra: imported only for a xacro file
    except ImportError:
        raise URDFError(f"{path.name} is a xacro file; reading it needs xacrodoc: {INSTALL_HINT}") from None
    if not path.is_file():
        raise URDFError(f"no such xacro file: {path}")
    try:
        doc = XacroDoc.from_file(str(path), walk_up=False, subargs={k: str(v) for k, v in (args or {}).items()})
        text = doc.to_urdf_string()
    except Exception as exc:  # noqa: BLE001 - xacro raises its own and plain exceptions for a bad file
        reason = " ".join(str(exc).split())  # one line: xacro's messages span several
        raise URDFError(f"xacro cannot expand {path}: {reason}") from None
    out = Path(tempfile.mkdtemp(prefix="kinelab-xacro-")) / (path.name.removesuffix(".xacro") or "robot.urdf")
    out.write_text(text)
    return out
