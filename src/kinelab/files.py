"""Reading the user's files with their size checked first: a path to ``/dev/zero``, a fifo or a 10 GB file gets a
clear error before a byte is read, never an allocation that runs the machine out of memory."""

from __future__ import annotations

from pathlib import Path

from kinelab.errors import KinelabError

MAX_BYTES = 64 * 2**20  # [bytes] the largest robot, SRDF, obstacle or metadata file read (URDFs are kilobytes)


def as_path(value: object, what: str, error: type[KinelabError]) -> Path:
    """``value`` as a Path when it is one or a non-empty string.

    Raises:
        error: anything else (None, a number, ""), naming what was given and what is valid.
    """
    if isinstance(value, Path) or (isinstance(value, str) and value.strip()):
        return Path(value)
    raise error(f"{what} must be a path (a str or pathlib.Path), got {value!r}")


def checked_file(path: str | Path, what: str, error: type[KinelabError], limit: int = MAX_BYTES) -> Path:
    """``path`` when it names a regular file of at most ``limit`` bytes.

    Args:
        path: the file.
        what: what the file is, for the message ("URDF", "obstacle file").
        error: the KinelabError subclass to raise.
        limit: the largest size accepted [bytes].

    Raises:
        error: not a path, the file is missing, not a regular file (a folder, a device, a fifo), or larger than
            ``limit``.
    """
    path = as_path(path, what, error)
    try:
        info = path.stat()
    except OSError:
        raise error(f"{what} not found: {path}") from None
    if not path.is_file():
        raise error(f"{what} {path} is not a regular file (a folder, a device or a pipe); give a file")
    if info.st_size > limit:
        raise error(f"{what} {path} has {info.st_size} bytes; kinelab reads files of at most {limit} bytes")
    return path


def read_text(path: str | Path, what: str, error: type[KinelabError], limit: int = MAX_BYTES) -> str:
    """The text of ``path`` (UTF-8) after :func:`checked_file`.

    Raises:
        error: as :func:`checked_file`, or a text that is not UTF-8 (named).
    """
    with checked_file(path, what, error, limit).open("rb") as f:
        data = f.read(limit + 1)
    if len(data) > limit:  # it grew between the check and the read
        raise error(f"{what} {path} has more than {limit} bytes; kinelab reads files of at most {limit} bytes")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{what} {path} is not UTF-8 text: {exc}") from None
