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


def test_a_helper_changed_in_another_module_drops_the_cached_kernel(tmp_path):
    """numba keys a kernel's cache on its own file: change a helper it calls elsewhere and the cached kernel
    keeps the old arithmetic. drop_stale_cache removes the package's cache files when a module with kernels
    changed, so the next process compiles the new code."""
    import subprocess

    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "helper.py").write_text("from numba import njit\n\n\n@njit(cache=True)\ndef scale(x):\n"
                                       "    return 2 * x\n")
    (package / "kernel.py").write_text("from numba import njit\n\nfrom pkg.helper import scale\n\n\n"
                                       "@njit(cache=True)\ndef run(x):\n    return scale(x) + 1\n")
    call = ("import sys; from pathlib import Path; from kinelab.ik.compiling import drop_stale_cache; "
            "dropped = drop_stale_cache(Path(sys.argv[1])); from pkg.kernel import run; print(dropped, run(10))")

    def fresh_process() -> str:
        env = {**__import__("os").environ, "PYTHONPATH": str(tmp_path)}
        done = subprocess.run([sys.executable, "-c", call, str(package)], capture_output=True, text=True, env=env,
                              timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        return done.stdout.strip()

    assert fresh_process() == "False 21"  # nothing cached yet: the stamp is written, the kernel compiled
    assert fresh_process() == "False 21"  # unchanged: the cache serves
    (package / "helper.py").write_text("from numba import njit\n\n\n@njit(cache=True)\ndef scale(x):\n"
                                       "    return 3 * x\n")
    assert fresh_process() == "True 31"  # the helper changed: the cache is dropped and the new code runs
    assert fresh_process() == "False 31"
