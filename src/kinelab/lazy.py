"""kinelab's one way of importing late: what a package serves on first use (PEP 562, :func:`loader`) and what a
module uses from another on first use (:func:`module`).

The solvers, SciPy and the collision model cost most of a second to import, which ``kinelab fk``, ``info`` and
``robots`` (and a user who only loads a robot) should not pay, and ``kinelab --help`` builds every command's parser
without any command's work. A module that needs another only on such a path names it at its top, under
``TYPE_CHECKING`` for the type checker and through :func:`module` at run time::

    if TYPE_CHECKING:
        from kinelab.report import render
    else:
        render = lazy.module("kinelab.report.render", globals())
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import types
from collections.abc import Callable
from typing import Any


class _Later(types.ModuleType):
    """A module not imported yet: the first attribute read imports it, and puts the module itself where this
    stands in the namespace that holds it (so that every later read is the module's own, as after an import)."""

    def __init__(self, name: str, namespace: dict[str, Any]) -> None:
        super().__init__(name)
        self.__dict__["_namespace"] = namespace

    def __getattr__(self, attribute: str) -> Any:
        real = importlib.import_module(self.__name__)
        namespace = self.__dict__["_namespace"]
        for key, value in list(namespace.items()):
            if value is self:
                namespace[key] = real
        return getattr(real, attribute)


def module(name: str, namespace: dict[str, Any]) -> types.ModuleType:
    """The module ``name``, imported when one of its attributes is first read (the module itself when it is
    imported already).

    Args:
        name: the module's full name ("kinelab.report.render").
        namespace: the ``globals()`` of the module that names it, where the name is replaced by the module once
            it is imported.

    Returns:
        The module, or a stand-in that imports it on first use.
    """
    loaded = sys.modules.get(name)
    return loaded if loaded is not None else _Later(name, namespace)


def loader(package: str, namespace: dict[str, Any], table: dict[str, tuple[str, str]]) -> Callable[[str], Any]:
    """A module ``__getattr__`` that imports ``table[name] = (module, attribute)`` on first access and keeps it; a
    name that is none of the table's but one of the package's subpackages or modules imports that (``kinelab.robot``
    after ``import kinelab``, as when the package imported it eagerly).

    Args:
        package: the package's name (for the AttributeError of an unknown name).
        namespace: the package's ``globals()``, where a loaded name is kept.
        table: name → (module, attribute).

    Returns:
        The function to assign to the package's ``__getattr__``.
    """

    def module_getattr(name: str) -> Any:
        if name in table:
            module, attribute = table[name]
            value = getattr(importlib.import_module(module), attribute)
        elif not name.startswith("_") and importlib.util.find_spec(f"{package}.{name}") is not None:
            value = importlib.import_module(f"{package}.{name}")  # a subpackage read as an attribute (kinelab.robot)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    return module_getattr


def __getattr__(name: str) -> Any:
    """``package_version``: kinelab's installed version, looked up on first use ("0+unknown" in a source tree
    that was never installed)."""
    if name != "package_version":
        raise AttributeError(f"module 'kinelab.lazy' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("kinelab")
    except PackageNotFoundError:
        return "0+unknown"
