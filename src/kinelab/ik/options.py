"""What every solver's options object shares: construction from keyword arguments, validation helpers.

Each solver has one frozen options dataclass (``FRDMOptions``, ``BiquatOptions``, ``DLSOptions``) with
every default written once and every value checked once, on construction. ``solve(..., **options)``
builds it; a caller that solves many targets with the same options can build it once and pass it as
``options=``.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import Any, TypeVar

from kinelab.errors import OptionError
from kinelab.values import is_real, is_whole

T = TypeVar("T")


def resolve(cls: type[T], solver: str, options: T | None, kwargs: dict[str, Any]) -> T:
    """A solver's options: ``options`` as given, the defaults, or ``cls(**kwargs)`` (cached).

    Raises:
        OptionError: both an options object and keyword options, an unknown option, or a bad value.
    """
    if options is not None:
        if not isinstance(options, cls):
            raise OptionError("options", options, f"a {cls.__name__}(...) for solver {solver!r}, or keyword options")
        if kwargs:
            name = next(iter(kwargs))
            raise OptionError(name, kwargs[name], f"give either options={cls.__name__}(...) or keyword options, "
                                                  "not both")
        return options
    return from_kwargs(cls, solver, kwargs) if kwargs else _defaults(cls)  # type: ignore[arg-type]


@functools.cache
def _defaults(cls: type[T]) -> T:
    return cls()


def from_kwargs(cls: type[T], solver: str, kwargs: dict[str, Any]) -> T:
    """``cls(**kwargs)``, an unknown name refused with the valid ones listed.

    Hashable keyword sets are cached: the options of a solve in a loop are built and checked once.

    Raises:
        OptionError: an unknown option, or a value outside what the option accepts.
    """
    try:
        key = tuple(sorted(kwargs.items()))
        hash(key)
    except TypeError:  # an unhashable value (a dict of kicks, a list of weights): build without the cache
        return _build(cls, solver, kwargs)
    return _cached(cls, solver, key)  # type: ignore[arg-type]


@functools.lru_cache(maxsize=256)
def _cached(cls: type, solver: str, key: tuple) -> Any:
    return _build(cls, solver, dict(key))


def _build(cls: type[T], solver: str, kwargs: dict[str, Any]) -> T:
    names = [f.name for f in dataclasses.fields(cls)]  # type: ignore[arg-type]
    unknown = [k for k in kwargs if k not in names]
    if unknown:
        valid = ", ".join(names)
        raise OptionError(unknown[0], kwargs[unknown[0]], valid,
                          f"unknown option {unknown[0]!r} for solver {solver!r}; its options are: {valid}")
    return cls(**kwargs)


def choice(name: str, value: object, valid: tuple[str, ...], what: str | None = None) -> None:
    """Refuse ``value`` unless it is one of ``valid`` (``what`` names the kind in the message)."""
    if not isinstance(value, str) or value not in valid:
        label = what or name
        raise OptionError(name, value, ", ".join(valid),
                          f"unknown {label} {value!r} (option {name}); valid: {', '.join(valid)}")


MAX_COUNT = 2**31 - 1  # the largest count (sweeps, restarts, samples): what the kernels' C int holds


def positive(name: str, value: object, *, allow_none: bool = False, integer: bool = False,
             zero: bool = False) -> None:
    """Refuse anything but a finite number > 0 (≥ 0 with ``zero``; an int of at most MAX_COUNT with ``integer``)."""
    if value is None and allow_none:
        return
    if not _in_range(value, integer, zero):
        kind = "an integer" if integer else "a finite number"
        bound = ("≥ 0" if zero else "> 0 (positive)") + (f" and at most {MAX_COUNT}" if integer else "")
        raise OptionError(name, value, f"{kind} {bound}" + (" or None" if allow_none else ""))


def _in_range(value: object, integer: bool, zero: bool) -> bool:
    """A number (not a bool; an integer with ``integer``), finite and > 0 (≥ 0 with ``zero``)."""
    if integer and not is_whole(value, hi=MAX_COUNT):
        return False
    return is_real(value, 0, above=not zero)


def finite(name: str, value: object) -> None:
    """Refuse anything but a finite real number."""
    if not is_real(value):
        raise OptionError(name, value, "a finite number")


def flag(name: str, value: object, *, allow_none: bool = False) -> None:
    """Refuse anything but True or False (or None with ``allow_none``)."""
    if not (isinstance(value, bool) or (value is None and allow_none)):
        raise OptionError(name, value, "True or False" + (" or None" if allow_none else ""))
