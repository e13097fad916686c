"""Names a package serves on first use (PEP 562): the solvers, SciPy and the collision model cost most of a
second to import, which ``kinelab fk``, ``info`` and ``robots`` (and a user who only loads a robot) should not pay."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from typing import Any


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
