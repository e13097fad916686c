"""The bypass policy a user's tables ask for (the paper's rule; the CLI's ``--on-singular``): plain Python, so
that the command line can build its parser without loading the compiled solver."""

from __future__ import annotations

from typing import Any

from kinelab.errors import OptionError

SWITCHABLE = {"kick": "kicks", "interval": "intervals", "freeze": "freeze"}


def bypass_plan(tables: dict[str, Any], on_singular: tuple[str, ...] = ()) -> dict[str, Any]:
    """FRDM's ``active`` and ``policy`` options for bypass tables given by a user (the CLI's flags).

    The paper's rule: intervals and frozen joints hold from the first sweep unless named in ``on_singular``,
    kicks are applied when the monitor fires; the bypasses named in ``on_singular`` ("kick", "interval",
    "freeze") are switched on by the monitor in that order, kicks last when not named; with no bypass the
    monitor answers by an automatic kick.

    Args:
        tables: the bypass tables given ("kicks", "intervals", "freeze" → their dicts).
        on_singular: bypasses to switch on only when the monitor fires, in order.

    Returns:
        The option fields ``active`` (when some table holds from the start) and ``policy``.

    Raises:
        OptionError: a name in ``on_singular`` that is not a bypass, or one whose table was not given.
    """
    _check_switched(tables, on_singular)
    switched = tuple(SWITCHABLE[name] for name in on_singular)
    held = tuple(key for key in ("intervals", "freeze") if key in tables and key not in switched)
    policy = switched + (("kicks",) if "kicks" in tables and "kicks" not in switched else ())
    return {**({"active": held} if held else {}), "policy": policy or ("auto_kick",)}


def _check_switched(tables: dict[str, Any], on_singular: tuple[str, ...]) -> None:
    """Refuse a name in ``on_singular`` that is no bypass, or one whose table was not given."""
    for name in on_singular:
        if name not in SWITCHABLE:
            raise OptionError("on_singular", name, ", ".join(SWITCHABLE))
        if SWITCHABLE[name] not in tables:
            raise OptionError("on_singular", name, f"a bypass with its table: {name!r} needs its joints "
                              f"(--{name} JOINT=... on the command line, {SWITCHABLE[name]}= in Python)")
