"""The folders reports are written to: never a folder of the user's, never half written.

A report folder is written whole into a temporary folder beside it and renamed into place. An existing
folder is replaced only when it is empty or is a kinelab report of the same kind (its ``.kinelab-report``
marker says so, or it holds only the files that kind writes); any other folder is refused by name, so no
``--out`` can delete a user's files. ``.``, ``..`` and the folders above the working one are refused outright.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from kinelab.errors import KinelabError
from kinelab.files import interrupted, output_folder, stop_if_interrupted, umask

MARKER = ".kinelab-report"
FIGURES = ("era_elbow.png", "era_wrist.png", "era_shoulder.png", "seed001_convergence.png")  # validate's figures
KINDS = {"validate": ("report.json", "report.md", "report.html"), "bench": ("bench.json", "bench.md", "bench.png")}


def check_output_folder(out: str | Path, kind: str) -> Path:
    """Make sure a ``kind`` report ("validate" or "bench") can be written to the folder ``out`` before any work.

    Raises:
        KinelabError: ``out`` is ``.``, ``..`` or above the working folder, a link, a file, a folder holding
            anything but a kinelab report of this kind, or not writable.
    """
    final = Path(out)
    if final.name in ("", ".", "..") or final.resolve() in (Path.cwd(), *Path.cwd().parents):
        raise KinelabError(f"cannot write the report to {str(out)!r}: give a folder of its own (such as "
                           f"./kinelab-{kind}), not the working folder or one above it")
    output_folder(final, "report")  # a link, a file, a device, a FIFO or a socket: refused by name
    if final.is_dir() and not _replaceable(final, kind):
        strangers = sorted(p.name for p in final.iterdir() if p.name not in (MARKER, *KINDS[kind]))
        raise KinelabError(f"cannot write the report to {out}: the folder exists and is not a kinelab {kind} report "
                           f"(it holds {', '.join(strangers[:3])}{', ...' if len(strangers) > 3 else ''}); "
                           "give a new or empty folder")
    existing = final.parent.resolve()
    while not existing.exists():
        existing = existing.parent
    try:  # a real probe: permission bits say nothing to root, nor about read-only or special filesystems
        shutil.rmtree(tempfile.mkdtemp(prefix=".kinelab-probe-", dir=existing))
    except OSError:
        raise KinelabError(f"cannot write the report to {out}: {existing} is not a writable folder") from None
    return final


def _replaceable(folder: Path, kind: str) -> bool:
    """Empty, marked as a report of this kind, or an unmarked earlier report: the kind's main file (its JSON)
    beside nothing but the files and figures this kind writes, by name (a folder of the user's figures is not
    one)."""
    marker = folder / MARKER
    if marker.is_file():
        with contextlib.suppress(OSError, UnicodeDecodeError):
            return marker.read_text(errors="strict")[:100].strip() == kind
        return False
    names = {p.name: p.is_file() for p in folder.iterdir()}
    if not names:
        return True
    ours = set(KINDS[kind]) | (set(FIGURES) if kind == "validate" else set())
    return KINDS[kind][0] in names and all(is_file and name in ours for name, is_file in names.items())


@contextlib.contextmanager
def atomic_folder(out: str | Path, kind: str) -> Iterator[Path]:
    """A temporary folder beside ``out`` that replaces ``out`` only when the block ends normally: an
    interrupted or failed report leaves the previous one (or nothing) in place, never a mixture.

    Raises:
        KinelabError: as :func:`check_output_folder`.
    """
    final = check_output_folder(out, kind)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{final.name}.", dir=final.parent))
    try:
        yield tmp
        (tmp / MARKER).write_text(kind + "\n")
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    tmp.chmod(0o777 & ~umask())
    if interrupted():  # a Ctrl-C a library swallowed: the old report stays
        shutil.rmtree(tmp, ignore_errors=True)
        stop_if_interrupted(str(final))
    old = final.with_name(f".{final.name}.old-{os.getpid()}") if final.exists() else None
    if old is not None:
        final.rename(old)
    tmp.rename(final)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
