"""xacro files, expanded to URDF by xacro (the optional extra ``kinelab[xacro]``), as data.

A xacro file is a program in xacro's own design: ``${...}`` is Python's ``eval`` with objects in reach,
``$(eval ...)`` is Python's ``eval`` too, ``$(env ...)``, ``$(optenv ...)`` and ``$(cwd)`` read the machine,
``load_yaml`` reads any file, and an include reads any path. Unless the user trusts the file by name
(``load(..., trust_xacro=True)``, ``--trust-xacro``), kinelab expands it as data:

- every ``${...}`` goes through :mod:`kinelab.robot.xacro_eval` (no attribute access, no calls but a fixed list of
  math functions, bounded powers and repetitions);
- ``$(eval)``, ``$(env)``, ``$(optenv)``, ``$(cwd)`` are refused, naming the construct, its file and line;
- an include resolves against the including file's folder and must lie in the file's own folder, its ROS
  package (the nearest folder above it with a ``package.xml``) or a package directory the user gave
  (``package_dirs``, ``ROS_PACKAGE_PATH``); ``$(find PKG)`` looks only there;
- the whole expansion runs in a child process bounded in time, memory and output (:mod:`kinelab.robot.xacro_bounded`),
  has an element limit (:data:`ELEMENTS`), every file read a size limit, and xacro's module state is reset before
  and restored after each expansion;
- an include pattern with wildcards is listed only when the folder above its first wildcard lies inside those
  folders (a pattern outside them is refused without revealing what it would match).

Properties, math (``pi``, ``radians``, ``sqrt``...), conditionals, macros with parameters and blocks,
``$(arg)``, ``$(find)``, ``$(dirname)``, namespaced includes expand as usual. The include and size limits hold
for a trusted file too. The expansion is written to a private temporary folder, never beside the user's file.
"""

from __future__ import annotations

import contextlib
import importlib.util
import re
import shutil
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from kinelab.errors import OptionError, URDFError
from kinelab.files import checked_file, read_text
from kinelab.robot import xacro_bounded as bounded
from kinelab.robot import xacro_eval
from kinelab.robot.meshes import mesh_package_dirs
from kinelab.scratch import scratch_dir

INSTALL_HINT = "pip install 'kinelab[xacro]' (xacro)"
SECONDS = bounded.SECONDS  # [s] the longest expansion (a real robot's takes well under a second)
ELEMENTS = 50_000  # elements an expansion may process (a humanoid's description: a few thousand)
UNTRUSTED = {"$(eval ...)": "_eval", "$(env ...)": "_env", "$(optenv ...)": "_optenv"}  # xacro's handlers
_LOCK = threading.Lock()  # xacro keeps its state in its module: one expansion at a time


def is_xacro(path: Path) -> bool:
    """True for a ``.xacro`` file (``robot.urdf.xacro`` included)."""
    return path.suffix == ".xacro"


def expand(path: Path, args: dict[str, str] | None = None, trusted: bool = False,
           package_dirs: list[str] | None = None) -> Path:
    """The URDF that the xacro file at ``path`` expands to with ``args`` (xacro arguments, name → value).

    Args:
        path: the xacro file.
        args: xacro arguments (name → value).
        trusted: let the file run what xacro runs (Python expressions, ``$(eval)``, ``$(env)``, ``load_yaml``).
        package_dirs: folders that hold the ROS packages its includes and ``$(find)`` may read.

    Returns:
        The expanded URDF's path, in a private temporary folder.

    Raises:
        URDFError: xacro missing (with the install hint), a missing or oversized file, a construct refused without
            trust (named, with its file and line), an include outside the folders it may read, an expansion past
            its limits, or a file xacro cannot expand (xacro's reason).
    """
    checked_file(path, "xacro file", URDFError)
    roots = _roots(path, package_dirs or [])
    _check_declared(path, args or {}, roots)
    if importlib.util.find_spec("xacro") is None:  # optional extra: imported only by the expansion
        raise URDFError(f"{path.name} is a xacro file; reading it needs xacro: {INSTALL_HINT}")
    out = scratch_dir("kinelab-xacro-") / (path.name.removesuffix(".xacro") or "robot.urdf")
    try:
        bounded.run(path, {"path": str(path), "args": {k: str(v) for k, v in (args or {}).items()},
                           "trusted": trusted, "roots": [str(r) for r in roots], "out": str(out)})
    except BaseException:
        shutil.rmtree(out.parent, ignore_errors=True)  # a refused expansion leaves nothing (a 64 MB URDF, say)
        raise
    return out


def expand_here(path: Path, args: dict[str, str], trusted: bool, roots: list[Path]) -> str:
    """The URDF text the xacro file at ``path`` expands to, in this process (:mod:`kinelab.robot.xacro_bounded`
    calls it in a child bounded in time, memory and output).

    Raises:
        URDFError: a construct refused, an include outside the roots, a limit passed, or xacro's own reason.
    """
    import xacro

    try:
        with _LOCK, _session(xacro, path, roots, trusted):
            doc = xacro.parse(None, str(path))
            xacro.process_doc(doc, mappings=args)
            text: str = doc.toxml()
            return text
    except _RefusalError as refusal:
        raise URDFError(str(refusal)) from None
    except Exception as exc:  # noqa: BLE001 - xacro raises its own and plain exceptions for a bad file
        raise URDFError(_failure(path, exc)) from None


class _RefusalError(Exception):
    """A construct refused, an include outside the roots, or a limit passed: the message is the user's."""


def _failure(path: Path, exc: BaseException) -> str:
    """The message for an expansion that failed: a refusal or limit found in xacro's chain of exceptions (xacro
    wraps what it catches), else xacro's own reason on one line."""
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, _RefusalError):
            return str(seen)
        if isinstance(seen, xacro_eval.LimitError):
            return f"{path}: {seen}; kinelab expands files within {SECONDS:g} s and {ELEMENTS} elements"
        if isinstance(seen, RecursionError):
            return f"xacro cannot expand {path}: its macros or includes nest without end"
        if isinstance(seen, MemoryError):
            return (f"{path}: the expansion needs more than {bounded.MEMORY >> 20} MB (kinelab's limit for a whole "
                    "xacro expansion)")
        seen = getattr(seen, "exc", None) or seen.__cause__ or seen.__context__
    return f"xacro cannot expand {path}: {_cut(' '.join(str(exc).split()))}"


def _cut(text: str, most: int = 400) -> str:
    """xacro's reason cut to ``most`` characters (it quotes whole expressions: a 6 MB list literal, say)."""
    return text if len(text) <= most else f"{text[:most]}… ({len(text)} characters)"


def _roots(path: Path, package_dirs: list[str]) -> list[Path]:
    """The folders an expansion may read: the file's own, its package's, and the package directories given."""
    folder = path.resolve().parent
    package = next((p for p in (folder, *folder.parents) if (p / "package.xml").is_file()), None)
    return [folder, *([package] if package else []), *(Path(d).resolve() for d in mesh_package_dirs(package_dirs))]


def _inside(path: Path, roots: list[Path]) -> bool:
    resolved = path.resolve()
    return any(resolved.is_relative_to(root) for root in roots)


def _find_package(name: str, roots: list[Path]) -> Path | None:
    """``$(find name)`` within the roots: a root that is the package (by folder name or its package.xml), or a
    folder of that name one or two levels below a root (a workspace's ``src``)."""
    for root in roots:
        xml = root / "package.xml"
        if root.name == name or (xml.is_file() and f"<name>{name}</name>" in read_text(xml, "package.xml", URDFError)):
            return root
        for candidate in (root / name, *sorted(root.glob(f"*/{name}"))[:1]):
            if candidate.is_dir() and _inside(candidate, roots):
                return candidate
    return None


@contextlib.contextmanager
def _session(xacro: Any, path: Path, roots: list[Path], trusted: bool) -> Iterator[None]:
    """xacro set up for one expansion of ``path``: fresh module state, the confined reader and finder, the budget,
    and (untrusted) the safe evaluator and the refusals; everything restored afterwards."""
    from xacro import substitution_args as sa

    budget = xacro_eval.Budget(SECONDS, ELEMENTS)
    saved: list[tuple[Any, str, Any]] = []

    def swap(owner: Any, name: str, value: Any) -> None:
        saved.append((owner, name, getattr(owner, name)))
        setattr(owner, name, value)

    context = dict(xacro.substitution_args_context)
    for name in ("filestack", "macrostack", "all_includes", "verbosity"):
        swap(xacro, name, getattr(xacro, name))
    xacro.init_stacks(str(path))
    xacro.all_includes, xacro.verbosity = [], 0
    xacro.substitution_args_context.clear()
    swap(xacro, "parse", _confined_parse(xacro, xacro.parse, roots))
    swap(xacro, "get_include_files", _confined_patterns(xacro, xacro.get_include_files, roots))
    swap(xacro, "eval_all", _counted(xacro.eval_all, budget))
    swap(xacro, "eval_extension", _extensions(xacro, xacro.eval_extension, trusted))
    swap(sa, "_eval_find", lambda name: _found(name, roots))
    if not trusted:
        swap(xacro, "safe_eval", _safe_eval(xacro, budget))
        for construct, handler in UNTRUSTED.items():
            swap(sa, handler, _refuser(xacro, construct))
    try:
        yield
    finally:
        for owner, name, value in reversed(saved):
            setattr(owner, name, value)
        xacro.substitution_args_context.clear()
        xacro.substitution_args_context.update(context)


def _found(name: str, roots: list[Path]) -> str:
    found = _find_package(name, roots)
    if found is None:
        raise _RefusalError(f"$(find {name}): no package {name!r} in the folders the file may read "
                       f"({', '.join(map(str, roots))}); pass the folder that holds it in package_dirs "
                       "(--package-dir)")
    return str(found)


def _confined_parse(xacro: Any, parse: Callable[..., Any], roots: list[Path]) -> Callable[..., Any]:
    """xacro's ``parse`` for a file name: the file must lie inside the roots and within the size limit."""

    def confined(inp: Any, filename: str | None = None) -> Any:
        if inp is not None or filename is None:
            return parse(inp, filename)
        file = Path(filename)
        if not _inside(file, roots):
            raise _RefusalError(f"{_current(xacro)} includes {file}, outside the folders a robot file may read "
                           f"({', '.join(map(str, roots))}); pass the folder that holds it in package_dirs "
                           "(--package-dir)")
        if not file.exists():
            xacro.filestack.pop()  # as xacro's own parse does for a missing file
            raise xacro.XacroException(f"No such file or directory: {file}", exc=FileNotFoundError(str(file)))
        return parse(read_text(file, "xacro file", URDFError))

    return confined


def _confined_patterns(xacro: Any, get_include_files: Callable[..., Any], roots: list[Path]) -> Callable[..., Any]:
    """xacro's include resolver, a wildcard pattern refused before it is listed unless the folder above its first
    wildcard lies inside the roots: ``/etc/*`` once named files outside them, one refusal at a time."""

    def confined(filename_spec: str, symbols: Any) -> Iterator[str]:
        spec = xacro.abs_filename_spec(xacro.eval_text(filename_spec, symbols))
        if _WILDCARD.search(spec) and not _inside(Path(_WILDCARD.split(spec, maxsplit=1)[0] + "x").parent, roots):
            raise _RefusalError(f"{_current(xacro)} includes the pattern {spec}, outside the folders a robot file may "
                                f"read ({', '.join(map(str, roots))}); it is not listed")
        yield from get_include_files(filename_spec, symbols)

    return confined


def _counted(eval_all: Callable[..., Any], budget: xacro_eval.Budget) -> Callable[..., Any]:
    def counted(node: Any, macros: Any, symbols: Any) -> Any:
        budget.tick()
        return eval_all(node, macros, symbols)

    return counted


def _extensions(xacro: Any, eval_extension: Callable[[str], Any], trusted: bool) -> Callable[[str], Any]:
    """``$(...)`` with ``$(dirname)`` naming the folder of the file being read, and ``$(cwd)`` refused."""

    def extension(s: str) -> Any:
        if s.strip() == "$(cwd)" and not trusted:
            _refuse(xacro, "$(cwd)", "$(cwd)")
        xacro.substitution_args_context["filename"] = xacro.filestack[-1] if xacro.filestack else None
        return eval_extension(s)

    return extension


def _safe_eval(xacro: Any, budget: xacro_eval.Budget) -> Callable[..., Any]:
    """xacro's ``safe_eval`` replaced by the data-only evaluator, reading the file's own symbols only."""

    def lookup_in(table: Any) -> Callable[[str], Any]:
        def lookup(name: str) -> Any:
            current = table
            while isinstance(current, xacro.Table):  # the file's tables, never xacro's global symbols
                if dict.__contains__(current, name):
                    value = current[name]
                    return xacro_eval.Namespace(lookup_in(value)) if isinstance(value, xacro.NameSpace) else value
                current = current.parent
            raise KeyError(name)

        return lookup

    def safe_eval(expr: str, symbols: Any, _locals: Any = None) -> Any:
        budget.tick()
        try:
            return xacro_eval.evaluate(expr, lookup_in(symbols))
        except xacro_eval.RefusedError as refused:
            if refused.too_large:
                raise _RefusalError(f"{_current(xacro)}: {refused.construct} {_where(_current(xacro), expr)} is "
                                    "more than kinelab builds while reading a robot file") from None
            _refuse(xacro, refused.construct, expr)

    return safe_eval


def _refuser(xacro: Any, construct: str) -> Callable[..., Any]:
    key = construct.split(" ")[0]

    def refused(*_args: Any, **_kwargs: Any) -> Any:
        _refuse(xacro, construct, key)

    return refused


def _refuse(xacro: Any, construct: str, text: str) -> None:
    """Raise the refusal of ``construct``, found by ``text`` in the file being read."""
    raise _RefusalError(f"{_current(xacro)}: {construct} {_where(_current(xacro), text)} would run code or read the "
                   "machine; a robot file is data: load it with trust_xacro=True (--trust-xacro) only if you trust "
                   "it")


def _current(xacro: Any) -> Path:
    return Path(xacro.filestack[-1]) if xacro.filestack and xacro.filestack[-1] else Path("<xacro>")


def _where(file: Path, text: str) -> str:
    """"at line N" of the first line of ``file`` holding ``text`` (or its first line), else ""."""
    needle = text.strip().splitlines()[0] if text.strip() else text
    with contextlib.suppress(OSError, URDFError):
        for number, line in enumerate(read_text(file, "xacro file", URDFError).splitlines(), start=1):
            if needle and needle in line:
                return f"at line {number}"
    return "in an expression"


_WILDCARD = re.compile(r"[*?\[]")
_ARG = re.compile(r"<xacro:arg\s[^>]*name\s*=\s*[\"']([^\"']+)[\"']")
_INCLUDE = re.compile(r"<xacro:include\s[^>]*filename\s*=\s*[\"']([^\"']+)[\"']")


def _declared(path: Path, roots: list[Path]) -> set[str] | None:
    """The arguments the file and the plain relative includes inside the roots declare, or None when it includes one
    only xacro can resolve (``$(find pkg)/...``)."""
    declared: set[str] = set()
    todo, seen = [path], set()
    while todo:
        current = todo.pop()
        if current in seen or not _inside(current, roots) or not current.is_file():
            continue
        seen.add(current)
        text = read_text(current, "xacro file", URDFError)
        declared.update(_ARG.findall(text))
        includes = _INCLUDE.findall(text)
        if any("$" in name for name in includes):
            return None
        todo += [(current.parent / name).resolve() for name in includes]
    return declared


def _check_declared(path: Path, args: dict[str, str], roots: list[Path]) -> None:
    """Refuse an argument that the file does not declare (``<xacro:arg name=...>``): xacro would ignore it
    silently. Includes given as plain relative paths inside the roots are read too; when the file includes one
    kinelab cannot read without expanding it (``$(find pkg)/...``), an argument may be declared there and none
    is refused."""
    if not args:
        return
    declared = _declared(path, roots)
    if declared is None:
        return  # an include only xacro can resolve: its arguments are unknown here
    unknown = sorted(set(args) - declared)
    if unknown:
        listed = ", ".join(sorted(declared)) or "none"
        raise OptionError("xacro_args", {k: args[k] for k in unknown}, f"arguments {path.name} declares: {listed}",
                          f"{path.name} declares no xacro argument {unknown[0]!r} (xacro would ignore it); it "
                          f"declares: {listed}")

