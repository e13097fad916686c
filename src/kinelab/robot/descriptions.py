"""``rd:NAME`` sources: the robot descriptions of the ``robot_descriptions`` package (the optional extra
``kinelab[descriptions]``), read from that package's local cache.

robot_descriptions clones each description's git repository on first use (into
``~/.cache/robot_descriptions`` or ``$ROBOT_DESCRIPTIONS_CACHE``). kinelab never starts that download
itself: it looks for the clone first and, when it is missing, says which repository is missing and how to
fetch it, instead of waiting on a network that may not be there.
"""

from __future__ import annotations

import ast
import contextlib
import difflib
import importlib
import importlib.util
import io
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

from kinelab.errors import DescriptionError

PREFIX = "rd:"
INSTALL_HINT = "pip install 'kinelab[descriptions]'"


@dataclass(frozen=True)
class Description:
    """A robot_descriptions entry resolved on disk: its model file and the directories holding its packages."""

    name: str
    path: Path  # the URDF or MJCF file
    package_dirs: tuple[str, ...]  # where its package:// URIs resolve


def resolve(source: str) -> Description:
    """The files of ``rd:NAME`` from robot_descriptions' cache.

    Raises:
        DescriptionError: robot_descriptions is not installed (with the install hint), NAME is not one of
            its descriptions (close names listed), or its repository is not in the cache (the fetch
            command named; nothing is downloaded).
    """
    name = source[len(PREFIX):]
    _check_known(name, source)
    clone = _cache_path(name)
    if clone is not None and not clone.is_dir():
        raise DescriptionError(
            f"{source}: its repository is not in robot_descriptions' cache ({clone}); fetching it needs the "
            f"network: run python -c 'import robot_descriptions.{name}' once where there is one (or set "
            "ROBOT_DESCRIPTIONS_CACHE to a cache that has it)")
    module = _import(name, source)
    path = getattr(module, "URDF_PATH", None) or getattr(module, "MJCF_PATH", None)
    if path is None:
        raise DescriptionError(f"{source} names neither a URDF nor an MJCF file")
    dirs = [getattr(module, attr) for attr in ("PACKAGE_PATH", "REPOSITORY_PATH") if hasattr(module, attr)]
    return Description(name, Path(path), tuple(str(Path(d).parent) for d in dirs) + tuple(map(str, dirs)))


def _check_known(name: str, source: str) -> None:
    """Refuse a name robot_descriptions does not describe (close names listed), or its absence (the install hint).

    Raises:
        DescriptionError: either.
    """
    try:
        from robot_descriptions._descriptions import DESCRIPTIONS
    except ImportError:
        raise DescriptionError(f"{source} needs robot_descriptions: {INSTALL_HINT}") from None
    if name not in DESCRIPTIONS:
        close = difflib.get_close_matches(name, list(DESCRIPTIONS), n=5) or sorted(DESCRIPTIONS)[:5]
        raise DescriptionError(f"{source}: {name!r} is not a robot_descriptions description; close names: "
                               + ", ".join(PREFIX + c for c in close))


def _import(name: str, source: str):
    """The description's module; its clone is in the cache, so importing it only checks the clone out."""
    os.environ.setdefault("GIT_TERMINAL_PROMPT", "0")  # a fetch robot_descriptions still tries must not ask
    try:
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
            warnings.simplefilter("ignore")  # its deprecation notices are about its own names
            return importlib.import_module(f"robot_descriptions.{name}")
    except Exception as err:  # GitPython and robot_descriptions raise their own kinds
        reason = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise DescriptionError(f"{source}: robot_descriptions could not open its cached copy ({reason}); "
                               "it may need the network to fetch the pinned commit") from None


def _cache_path(name: str) -> Path | None:
    """Where robot_descriptions keeps the clone this description uses (None if its module names none)."""
    spec = importlib.util.find_spec(f"robot_descriptions.{name}")
    if spec is None or spec.origin is None:
        return None
    repo = _cloned_repository(Path(spec.origin))
    if repo is None:
        return None
    from robot_descriptions._repositories import REPOSITORIES

    if repo not in REPOSITORIES:
        return None
    cache_dir = Path(os.path.expanduser(os.environ.get("ROBOT_DESCRIPTIONS_CACHE", "~/.cache/robot_descriptions")))
    cache_path = REPOSITORIES[repo].cache_path
    commit = os.environ.get("ROBOT_DESCRIPTION_COMMIT")
    return cache_dir / (f"{cache_path}-{commit}/{cache_path}" if commit else cache_path)


def _cloned_repository(module_file: Path) -> str | None:
    """The repository a description module clones: the first argument of its ``_clone_to_cache`` call."""
    for node in ast.walk(ast.parse(module_file.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "_clone_to_cache" and node.args:
            arg = node.args[0]
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                return arg.value
    return None
