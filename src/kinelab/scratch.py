"""Private temporary folders that go away with what needs them: a xacro expansion lives as long as its Chain,
a bench's stripped URDFs as long as the process; none is left in the temporary directory afterwards."""

from __future__ import annotations

import shutil
import tempfile
import weakref
from pathlib import Path


class _Process:
    """Stands for the process: a folder it owns is removed when the interpreter exits."""


_PROCESS = _Process()


def scratch_dir(prefix: str, owner: object | None = None) -> Path:
    """A new private folder (``tempfile.mkdtemp``), removed with everything in it when ``owner`` is collected and
    in any case when the process exits.

    Args:
        prefix: the folder name's prefix, e.g. "kinelab-xacro-".
        owner: the object whose life the folder follows (None: the process).

    Returns:
        The folder's path.
    """
    path = Path(tempfile.mkdtemp(prefix=prefix))
    weakref.finalize(_PROCESS, shutil.rmtree, path, True)
    if owner is not None:
        own(owner, path)
    return path


def own(owner: object, path: Path) -> None:
    """Remove the folder ``path`` when ``owner`` is collected (as well as at exit)."""
    weakref.finalize(owner, shutil.rmtree, path, True)
