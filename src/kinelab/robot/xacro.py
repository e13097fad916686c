"""xacro files, expanded to URDF by xacrodoc (the optional extra ``kinelab[xacro]``), as data.

A xacro file can hold programs: ``$(eval ...)`` is Python's ``eval`` with its builtins, ``$(env ...)`` and
``$(optenv ...)`` read the environment, ``xacro.load_yaml`` reads any file, and a ``${...}`` expression can
reach objects through ``__`` names or ``str.format``. kinelab refuses all of these unless the user trusts the
file by name (``load(..., trust_xacro=True)``, ``--trust-xacro`` on the command line), naming the construct
and its line; properties, arithmetic, macros, conditionals, ``$(arg ...)``, ``$(find ...)`` and includes
expand as usual. Map workers load a xacro robot with the trust its user gave, never more.

kinelab reads the expanded URDF like any other; ``package://`` URIs are kept for the mesh search of
:mod:`kinelab.robot.meshes`. The expansion is written to a temporary folder, never next to the user's file.
"""

from __future__ import annotations

import contextlib
import re
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from kinelab.errors import OptionError, URDFError
from kinelab.scratch import scratch_dir

INSTALL_HINT = "pip install 'kinelab[xacro]' (xacrodoc)"
# what an untrusted file may not use, and how to find it in the text to name its line
UNSAFE = {
    "$(eval ...)": re.compile(r"\$\(\s*eval\b"),
    "$(env ...)": re.compile(r"\$\(\s*env\b"),
    "$(optenv ...)": re.compile(r"\$\(\s*optenv\b"),
    "load_yaml": re.compile(r"load_yaml"),
    "a '__' name": re.compile(r"\.\s*__\w|__\w+__"),
    "str.format": re.compile(r"\.\s*format\b|format_map"),
}
_LOCK = threading.Lock()  # the guard patches xacro's module state for the length of one expansion


class _RefusedError(Exception):
    def __init__(self, construct: str):
        super().__init__(construct)
        self.construct = construct


def is_xacro(path: Path) -> bool:
    """True for a ``.xacro`` file (``robot.urdf.xacro`` included)."""
    return path.suffix == ".xacro"


def expand(path: Path, args: dict[str, str] | None = None, trusted: bool = False) -> Path:
    """The URDF that the xacro file at ``path`` expands to with ``args`` (xacro arguments, name → value).

    Args:
        path: the xacro file.
        args: xacro arguments (name → value).
        trusted: let the file run what xacro runs (``$(eval)``, ``$(env)``, ``load_yaml``); False: refuse them.

    Raises:
        URDFError: xacrodoc missing (with the install hint), a missing file, a construct refused without trust
            (named, with its file and line), or a file xacro cannot expand (xacro's reason: a missing argument,
            an undefined property or macro).
    """
    _check_declared(path, args or {})
    try:
        from xacrodoc import XacroDoc  # optional extra: imported only for a xacro file
    except ImportError:
        raise URDFError(f"{path.name} is a xacro file; reading it needs xacrodoc: {INSTALL_HINT}") from None
    if not path.is_file():
        raise URDFError(f"no such xacro file: {path}")
    try:
        with _LOCK, (contextlib.nullcontext() if trusted else _guarded()):
            doc = XacroDoc.from_file(str(path), walk_up=False, subargs={k: str(v) for k, v in (args or {}).items()})
            text = doc.to_urdf_string()
    except Exception as exc:  # noqa: BLE001 - xacro raises its own and plain exceptions for a bad file
        refused = _refusal(exc)
        if refused is not None:
            raise URDFError(f"{path}: {refused} {_where(path, refused)} would run code or read the machine; a "
                            "robot file is data: load it with trust_xacro=True (--trust-xacro) only if you trust "
                            "it") from None
        reason = " ".join(str(exc).split())  # one line: xacro's messages span several
        raise URDFError(f"xacro cannot expand {path}: {reason}") from None
    out = scratch_dir("kinelab-xacro-") / (path.name.removesuffix(".xacro") or "robot.urdf")
    out.write_text(text)
    return out


def _refusal(exc: BaseException) -> str | None:
    """The refused construct behind a xacro exception (xacro wraps what it catches), or None."""
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, _RefusedError):
            return seen.construct
        seen = getattr(seen, "exc", None) or seen.__cause__ or seen.__context__
    return None


def _where(path: Path, construct: str) -> str:
    """"at line N" of the first use in the file itself, or "in a file it includes"."""
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        if UNSAFE[construct].search(line):
            return f"at line {number}"
    return "in a file it includes"


def _refuse(construct: str) -> Callable[..., Any]:
    def refused(*_args: Any, **_kwargs: Any) -> Any:
        raise _RefusedError(construct)
    return refused


@contextlib.contextmanager
def _guarded() -> Iterator[None]:
    """xacro with its code-running and machine-reading entry points replaced by refusals for the block."""
    import xacro
    from xacro import substitution_args as sa

    plain_eval = xacro.safe_eval

    def checked_eval(expr: str, globals: Any, locals: Any = None) -> Any:  # noqa: A002 - xacro's own names
        for construct in ("a '__' name", "str.format", "load_yaml"):
            if UNSAFE[construct].search(expr):
                raise _RefusedError(construct)
        return plain_eval(expr, globals, locals)

    saved: list[tuple[Any, str, Any]] = []

    def swap(owner: Any, name: str, value: Any) -> None:
        saved.append((owner, name, getattr(owner, name)))
        setattr(owner, name, value)

    swap(sa, "_eval", _refuse("$(eval ...)"))
    swap(sa, "_env", _refuse("$(env ...)"))
    swap(sa, "_optenv", _refuse("$(optenv ...)"))
    swap(xacro, "safe_eval", checked_eval)
    swap(xacro, "load_yaml", _refuse("load_yaml"))
    symbols = xacro._global_symbols
    plain_symbols = {k: symbols.get(k) for k in ("load_yaml",)}
    namespace = symbols.get("xacro")
    plain_ns = None if namespace is None else namespace.get("load_yaml")
    try:
        symbols["load_yaml"] = _refuse("load_yaml")
        if namespace is not None:
            namespace["load_yaml"] = _refuse("load_yaml")
        yield
    finally:
        for owner, name, value in reversed(saved):
            setattr(owner, name, value)
        symbols.update(plain_symbols)
        if namespace is not None:
            namespace["load_yaml"] = plain_ns


_ARG = re.compile(r"<xacro:arg\s[^>]*name\s*=\s*[\"']([^\"']+)[\"']")
_INCLUDE = re.compile(r"<xacro:include\s[^>]*filename\s*=\s*[\"']([^\"']+)[\"']")


def _check_declared(path: Path, args: dict[str, str]) -> None:
    """Refuse an argument that the file does not declare (``<xacro:arg name=...>``): xacro would ignore it
    silently. Includes given as plain relative paths are read too; when the file includes one kinelab cannot
    read without expanding it (``$(find pkg)/...``), an argument may be declared there and none is refused."""
    if not args or not path.is_file():
        return
    declared: set[str] = set()
    todo, seen = [path], set()
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.add(current)
        text = current.read_text(errors="replace")
        declared.update(_ARG.findall(text))
        for name in _INCLUDE.findall(text):
            if "$" in name:
                return  # an include only xacro can resolve: its arguments are unknown here
            todo.append((current.parent / name).resolve())
    unknown = sorted(set(args) - declared)
    if unknown:
        raise OptionError("xacro_args", {k: args[k] for k in unknown},
                          f"arguments {path.name} declares: {', '.join(sorted(declared)) or 'none'}",
                          f"{path.name} declares no xacro argument {unknown[0]!r} (xacro would ignore it); it "
                          f"declares: {', '.join(sorted(declared)) or 'none'}")
