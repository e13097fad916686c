"""kinelab's compiled core: Cython modules built when kinelab is installed (``pip install -e .``), never at run time.

Importing this package checks that the compiled modules were built from the sources beside them: after an edit of
a ``.pyx`` file, using the old machine code silently would test code that is not there, so it is refused with the
command that rebuilds (``pip install -e .`` again, or ``python setup.py build_ext --inplace``).
"""

from __future__ import annotations

from pathlib import Path

from kinelab.core.digest import source_crc32
from kinelab.errors import KinelabError

REBUILD = "pip install -e . (or python setup.py build_ext --inplace)"


def _check_fresh() -> None:
    """Refuse a compiled core older than its sources (a checkout edited since the last build)."""
    try:
        from kinelab.core import _built
    except ImportError:
        raise KinelabError(f"kinelab's compiled core is not built in {Path(__file__).parent}: {REBUILD}") from None
    folder = Path(__file__).parent
    if any(folder.glob("*.pyx")) and source_crc32(folder) != getattr(_built, "SOURCE_CRC32", None):
        raise KinelabError(f"kinelab's compiled core is older than its sources in {folder} (a .pyx changed since "
                           f"the build): {REBUILD}")


_check_fresh()
