"""Builds kinelab's compiled core (``src/kinelab/core/*.pyx``, Cython) when kinelab is installed.

Everything else about the package is in ``pyproject.toml``. The build records the SHA-256 and CRC-32 of the sources it
compiled in ``src/kinelab/core/_built.py`` (generated, not tracked), which ``kinelab.core`` compares with the
sources beside it at import: a stale build is refused, never run. Both cores compile at once; an install whose
modules beside the sources were built from these very sources reuses them (``KINELAB_REBUILD=1`` compiles anyway).
"""

import importlib.machinery
import importlib.util
import os
from pathlib import Path

import numpy
from Cython.Build import cythonize
from setuptools import Distribution, Extension, find_packages, setup

ROOT = Path(__file__).resolve().parent
CORE = ROOT / "src" / "kinelab" / "core"


def _digest():
    spec = importlib.util.spec_from_file_location("kinelab_core_digest", CORE / "digest.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _up_to_date(sha256):
    """The modules beside the sources were built from exactly these sources (their SHA-256 in ``_built.py``) for
    this Python: the second install of a checkout (the README's second command) need not compile them again."""
    built = CORE / "_built.py"
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    modules = [CORE / f"{pyx.stem}{suffix}" for pyx in CORE.glob("*.pyx")]
    return (built.exists() and f'SOURCE_SHA256 = "{sha256}"' in built.read_text()
            and all(m.exists() and m.stat().st_mtime >= built.stat().st_mtime for m in modules))  # a build finished


class _Compiled(Distribution):
    """A distribution with compiled modules (a platform wheel) even when they are reused, not compiled."""

    def has_ext_modules(self):
        return True


SHA256 = _digest().source_sha256(CORE)
REUSE = _up_to_date(SHA256) and not os.environ.get("KINELAB_REBUILD")
if not REUSE:  # written before the modules, so that a build stopped half-way is never taken as finished
    (CORE / "_built.py").write_text(f'"""Written by setup.py: the sources the compiled core was built from."""\n\n'
                                    f'SOURCE_SHA256 = "{SHA256}"\n'
                                    f'SOURCE_CRC32 = "{_digest().source_crc32(CORE)}"\n')
# OpenMP runs the batches' rows in parallel (prange); -O3 without -ffast-math keeps IEEE arithmetic, so the kernels
# compute what their reference computes, bit for bit
# NumPy's C API (headers from the numpy that builds) lets an engine make its result arrays without a Python call
extensions = [Extension(f"kinelab.core.{pyx.stem}", [str(pyx.relative_to(ROOT))], include_dirs=[numpy.get_include()],
                        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
                        extra_compile_args=["-O3", "-fopenmp"], extra_link_args=["-fopenmp"])
              for pyx in sorted(CORE.glob("*.pyx"))]
JOBS = max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
if REUSE:
    print(f"kinelab: the compiled core beside its sources was built from them (SHA-256 {SHA256[:12]}): reused, not "
          "compiled again (KINELAB_REBUILD=1 compiles it anyway)")
setup(
    distclass=_Compiled,
    ext_modules=[] if REUSE else cythonize(extensions, language_level=3, include_path=[str(ROOT / "src")],
                                           nthreads=JOBS),
    options={"build_ext": {"parallel": JOBS}},
    package_dir={"": "src", "kinelab.urdf": "urdf"},
    packages=[*find_packages("src"), "kinelab.urdf"],
    package_data={"kinelab.urdf": ["*.urdf", "*.yaml", "*.xml"],
                  "kinelab.core": ["*.pyx", "*.pxd", "*.pxi", "*.pyi"]
                  + ([f"*{importlib.machinery.EXTENSION_SUFFIXES[0]}"] if REUSE else []),
                  "kinelab.view.teach": ["*.html", "*.js"]},
)
