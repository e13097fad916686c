"""Progress bars that show where someone is watching: ``progress=None`` (the default of every long call) shows a
bar in a terminal and in Jupyter (tqdm's notebook bar when ipywidgets is installed, its text bar otherwise) and
stays quiet when the output goes to a file or a pipe, or when the environment sets ``KINELAB_PROGRESS=0`` (a
notebook rendered to a page, a batch job); True and False force it."""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Iterable
from typing import Any


def interactive() -> bool:
    """True in a Jupyter kernel or when stderr is a terminal, unless ``KINELAB_PROGRESS=0``."""
    if os.environ.get("KINELAB_PROGRESS") == "0":
        return False
    shell = sys.modules.get("IPython")
    if shell is not None:
        ipython = getattr(shell, "get_ipython", lambda: None)()
        if ipython is not None and getattr(ipython, "kernel", None) is not None:
            return True
    return bool(getattr(sys.stderr, "isatty", lambda: False)())


def bar(iterable: Iterable[Any] | None = None, *, progress: bool | None, **options: Any) -> Any:
    """A tqdm bar over ``iterable`` (or a manual one with ``total=``), shown as ``progress`` says (None: when
    :func:`interactive`); ``options`` go to tqdm (desc, unit, total, initial, leave)."""
    if importlib.util.find_spec("ipywidgets") is not None:
        from tqdm.auto import tqdm
    else:  # tqdm.auto would warn in Jupyter that it has no widgets: the text bar is the one to show
        from tqdm import tqdm

    show = interactive() if progress is None else bool(progress)
    return tqdm(iterable, disable=not show, **options)


def step(message: str, progress: bool | None = None) -> None:
    """Say what a command is about to do that takes a while (a page's meshes, its writing): one line on stderr,
    shown as ``progress`` says (None: when :func:`interactive`), so that a terminal is never silent for seconds."""
    if interactive() if progress is None else progress:
        print(f"kinelab: {message} ...", file=sys.stderr, flush=True)
