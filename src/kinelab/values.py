"""What kind of number a setting's value is, said once for every layer: a finite real or an integer (never a bool,
which Python counts as both), within a range. Python's and NumPy's numbers alike (for a type checker a NumPy
integer that passes is an ``int``, a NumPy float a ``float``: they behave as one)."""

from __future__ import annotations

import math
import numbers
from typing import TypeGuard


def is_real(value: object, lo: float = -math.inf, hi: float = math.inf, *, above: bool = False
            ) -> TypeGuard[float]:
    """True for a finite real number (not a bool) with lo ≤ value ≤ hi (lo < value with ``above``)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return False
    number = float(value)
    return math.isfinite(number) and (number > lo if above else number >= lo) and number <= hi


def is_whole(value: object, lo: float = -math.inf, hi: float = math.inf) -> TypeGuard[int]:
    """True for an integer (a Python or NumPy int, not a bool) with lo ≤ value ≤ hi."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool) and lo <= int(value) <= hi


def mixes_non_reals(value: object) -> bool:
    """True for a list or tuple (nested or not) holding a bool, a complex number or anything else that is not a
    real number: NumPy would turn ``[0.1, True]`` into floats without a word. Arrays are judged by their dtype
    instead (this looks at Python sequences only)."""
    if not isinstance(value, list | tuple):
        return False
    import numpy as np  # here: this lowest layer is read by start-up paths that load no NumPy

    try:
        items = np.array(value, dtype=object).ravel()
    except ValueError:  # ragged: not numbers in a shape
        return True
    return any(isinstance(x, bool | np.bool_) or not isinstance(x, numbers.Real) for x in items)
