"""What a report ran on: when, which code (kinelab's version and, in a git checkout, its commit), which libraries
and compiled core, which processor, and the command — so a reader can tell one run from another and repeat it.

The commit is read from the checkout's ``.git`` files (HEAD, the ref it names, or ``packed-refs``); no program is
run. Outside a checkout it is None.
"""

from __future__ import annotations

import os
import platform
import shlex
import sys
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Any

import kinelab
from kinelab.core import _built

# the distributions that define the robots (example-robot-data, yourdfpy) and the reference (Pinocchio, coal,
# NumPy, SciPy): their versions go into every report
LIBRARIES = {"pinocchio": "pin", "coal": "coal", "example-robot-data": "example-robot-data",
             "yourdfpy": "yourdfpy", "numpy": "numpy", "scipy": "scipy"}


def provenance() -> dict[str, Any]:
    """The run's provenance: ``date`` (UTC, ISO 8601), ``command``, ``kinelab``, ``commit`` (or None), the
    version of each of :data:`LIBRARIES` by its key (``pinocchio``, ``coal``, ``example-robot-data``,
    ``yourdfpy``, ``numpy``, ``scipy``; "not installed" when absent), ``core`` (the compiled core's source
    SHA-256, first 12 hex digits), ``processor`` (its model), ``cores`` (logical processors) and ``python``."""
    return {"date": datetime.now(timezone.utc).isoformat(timespec="seconds"), "command": shlex.join(sys.argv),
            "kinelab": kinelab.__version__, "commit": commit_of(Path(__file__).resolve().parent),
            **{key: _version(dist) for key, dist in LIBRARIES.items()}, "core": _built.SOURCE_SHA256[:12],
            "processor": processor(), "cores": os.cpu_count() or 0, "python": platform.python_version()}


def _version(distribution: str) -> str:
    """The installed version of a distribution, or "not installed"."""
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return "not installed"


def commit_of(start: Path) -> str | None:
    """The commit checked out in the git work tree holding ``start`` (40 hex digits), or None."""
    for folder in (start, *start.parents):
        git = folder / ".git"
        if git.is_file():  # a worktree or submodule: "gitdir: PATH"
            text = git.read_text().strip()
            git = (folder / text.removeprefix("gitdir:").strip()) if text.startswith("gitdir:") else git
        if git.is_dir():
            return _resolved(git)
    return None


def _resolved(git: Path) -> str | None:
    """HEAD of the git directory ``git``, followed through its ref (loose or packed)."""
    try:
        head = (git / "HEAD").read_text().strip()
        if not head.startswith("ref:"):
            return head if len(head) == 40 else None
        ref = head.removeprefix("ref:").strip()
        common = Path((git / "commondir").read_text().strip()) if (git / "commondir").exists() else None
        roots = [git] + ([git / common] if common is not None else [])
        return next((found for root in roots if (found := _ref_in(root, ref)) is not None), None)
    except OSError:
        return None


def _ref_in(root: Path, ref: str) -> str | None:
    """The commit ``ref`` (``refs/heads/main``) names in the git directory ``root``, loose or packed, or None."""
    if (root / ref).is_file():
        return (root / ref).read_text().strip()
    if (root / "packed-refs").is_file():
        for line in (root / "packed-refs").read_text().splitlines():
            if line.endswith(" " + ref):
                return line.split()[0]
    return None


def processor() -> str:
    """The processor's model name (Linux: /proc/cpuinfo), else what the platform says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()
