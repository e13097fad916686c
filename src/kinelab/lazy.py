"""Names a package serves on first use (PEP 562): the solvers, SciPy and the collision model cost most of a
second to import, which ``kinelab fk``, ``info`` and ``robots`` (and a user who only loads a robot) should not pay."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def loader(package: str, namespace: dict[str, Any], table: dict[str, tuple[str, str]]) -> Callable[[str], Any]:
    """A module ``__getattr__`` that imports ``table[name] = (module, attribute)`` on first access and keeps it.

    Args:
        package: the package's name (for the AttributeError of an unknown name).
        namespace: the package's ``globals()``, where a loaded name is kept.
        table: name → (module, attribute).

    Returns:
        The function to assign to the package's ``__getattr__``.
    """

    def module_getattr(name: str) -> Any:
        if name not in table:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attribute = table[name]
        value = getattr(importlib.import_module(module), attribute)
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
