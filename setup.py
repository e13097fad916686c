"""Builds kinelab's compiled core (``src/kinelab/core/*.pyx``, Cython) when kinelab is installed.

Everything else about the package is in ``pyproject.toml``. The build records the SHA-256 and CRC-32 of the sources it
compiled in ``src/kinelab/core/_built.py`` (generated, not tracked), which ``kinelab.core`` compares with the
sources beside it at import: a stale build is refused, never run.
"""

import importlib.util
from pathlib import Path

import numpy
from Cython.Build import cythonize
from setuptools import Extension, find_packages, setup

ROOT = Path(__file__).resolve().parent
CORE = ROOT / "src" / "kinelab" / "core"


def _digest():
    spec = importlib.util.spec_from_file_location("kinelab_core_digest", CORE / "digest.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


(CORE / "_built.py").write_text(f'"""Written by setup.py: the sources the compiled core was built from."""\n\n'
                                f'SOURCE_SHA256 = "{_digest().source_sha256(CORE)}"\n'
                                f'SOURCE_CRC32 = "{_digest().source_crc32(CORE)}"\n')
# OpenMP runs the batches' rows in parallel (prange); -O3 without -ffast-math keeps IEEE arithmetic, so the kernels
# compute what their reference computes, bit for bit
# NumPy's C API (headers from the numpy that builds) lets an engine make its result arrays without a Python call
extensions = [Extension(f"kinelab.core.{pyx.stem}", [str(pyx.relative_to(ROOT))], include_dirs=[numpy.get_include()],
                        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
                        extra_compile_args=["-O3", "-fopenmp"], extra_link_args=["-fopenmp"])
              for pyx in sorted(CORE.glob("*.pyx"))]
setup(
    ext_modules=cythonize(extensions, language_level=3, include_path=[str(ROOT / "src")]),
    package_dir={"": "src", "kinelab.urdf": "urdf"},
    packages=[*find_packages("src"), "kinelab.urdf"],
    package_data={"kinelab.urdf": ["*.urdf", "*.yaml", "*.xml"], "kinelab.core": ["*.pyx", "*.pxd", "*.pxi", "*.pyi"],
                  "kinelab.view.teach": ["*.html", "*.js"]},
)
