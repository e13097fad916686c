"""Calling a numba kernel without numba's per-call typing (:class:`TypedKernel`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba


class TypedKernel:
    """A numba kernel called through the compiled entry point of the argument types it first saw.

    numba types every argument on every call, and a NamedTuple argument is typed in Python: 2–3 µs per
    call for kinelab's kernel tuples, as much as a converged solve costs. kinelab builds every argument
    of its kernels itself, with fixed dtypes, layouts and scalar types (``float``, ``int``, ``bool``), so
    after the first call (which compiles or loads the kernel through the dispatcher, with numba's own
    type check) the same compiled function serves every later call. A call whose argument types could
    differ must go through the dispatcher (``kernel.py_dispatcher``) instead.
    """

    def __init__(self, dispatcher: Any):
        self.py_dispatcher = dispatcher
        self._entry: Callable[..., Any] | None = None

    def __call__(self, *args: Any) -> Any:
        """Call the compiled entry point (the dispatcher on the first call)."""
        if self._entry is not None:
            return self._entry(*args)
        result = self.py_dispatcher(*args)
        signature = tuple(numba.typeof(a) for a in args)
        self._entry = self.py_dispatcher.overloads[signature].entry_point
        return result
