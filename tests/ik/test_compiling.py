"""The compile announcement reads numba's cache: it speaks when a kernel has no cached machine code for its
current source, and not once the code is cached."""

from __future__ import annotations

import importlib
import sys
import warnings

import pytest

from kinelab.ik import compiling


def test_an_uncached_kernel_is_announced_and_a_cached_one_is_not(tmp_path, monkeypatch):
    (tmp_path / "fresh_kernel.py").write_text("from numba import njit\n\n\n@njit(cache=True)\n"
                                              "def twice(x):\n    return 2 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(compiling, "_SAID", set())
    module = importlib.import_module("fresh_kernel")
    try:
        with pytest.warns(compiling.CompileNotice, match="compiling the test path for this machine: about 60 s"):
            compiling.announce("the test path", [module.twice])
        assert module.twice(21) == 42  # compiles and writes the cache
        compiling._SAID.clear()
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            compiling.announce("the test path", [module.twice])  # cached now: silent
    finally:
        sys.modules.pop("fresh_kernel", None)


def test_a_path_is_announced_once_per_process(monkeypatch):
    monkeypatch.setattr(compiling, "_cached", lambda kernel: False)
    monkeypatch.setattr(compiling, "_SAID", set())
    with pytest.warns(compiling.CompileNotice) as said:
        compiling.announce("FRDM", [None])
        compiling.announce("FRDM", [None])
    assert len(said) == 1 and "about 60 s" in str(said[0].message)
