"""The user's files, read and written safely.

Reading: a path to ``/dev/zero``, a fifo or a 10 GB file gets a clear error before a byte is read, never an
allocation that runs the machine out of memory. Writing: one writer (:func:`write_output`) that creates a new file or
replaces a regular one, never a device, a pipe, a folder or a file behind a link out of its folder."""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from kinelab import lazy
from kinelab.errors import KinelabError

if TYPE_CHECKING:
    import tempfile
    from collections.abc import Iterator
else:
    tempfile = lazy.module("tempfile", globals())

MAX_BYTES = 64 * 2**20  # [bytes] the largest robot, SRDF, obstacle or metadata file read (URDFs are kilobytes)
_interrupted = [False]  # a Ctrl-C seen within held_interrupts(): no output is replaced after it


@contextlib.contextmanager
def held_interrupts() -> Iterator[None]:
    """Within the block, remember Ctrl-C (SIGINT) even where a library catches the KeyboardInterrupt it raises (some
    guard their optional imports with ``except BaseException``): once seen, :func:`write_output` and
    :func:`stop_if_interrupted` refuse to go on. The command line runs in such a block; the handler before it is
    put back after. Off the main thread (where no handler can be set) the block changes nothing."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_interrupt(signum: int, frame: object) -> None:
        _interrupted[0] = True
        raise KeyboardInterrupt

    _interrupted[0] = False
    previous = signal.signal(signal.SIGINT, on_interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        _interrupted[0] = False


def interrupted() -> bool:
    """Whether a Ctrl-C was seen within :func:`held_interrupts`."""
    return _interrupted[0]


def interrupt_taken() -> None:
    """A command took the Ctrl-C as its normal end (a server stopping): it stops nothing more."""
    _interrupted[0] = False


def stop_if_interrupted(what: str) -> None:
    """Raise KeyboardInterrupt when a Ctrl-C was seen (``what``: what is left as it was, for the message)."""
    if _interrupted[0]:
        raise KeyboardInterrupt(f"{what} left as it was")


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


def umask() -> int:
    """The process's file-mode creation mask, read without changing it where Linux shows it (``/proc/self/status``);
    elsewhere set and restored at once."""
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _kind_of(mode: int) -> str:
    """What a file of this ``st_mode`` is, in words."""
    for test, words in ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
                        (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                        (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return words
    return "not a regular file"


def _link_target(path: Path, what: str) -> Path:
    """The file the link at ``path`` leads to, as :func:`output_target` takes it: only within the link's folder.

    Raises:
        KinelabError: a link out of its folder, or to what output_target refuses.
    """
    target = Path(os.path.realpath(path))
    if target.parent != Path(os.path.realpath(path.parent)):
        raise KinelabError(f"cannot write the {what} to {path}: it is a link to {target}, outside its folder; "
                           "kinelab replaces regular files only (give the file's own path)")
    return output_target(target, what) if target != path else target


def output_target(path: str | Path, what: str) -> Path:
    """The file a write to ``path`` may create or replace, refusing anything else by name.

    A path that does not exist names a new file (its folder must exist); an existing regular file is replaced; a
    symbolic link is followed only to a regular file (or a new one) in the link's own folder.

    Args:
        path: where the user asked the output to go.
        what: what is written ("page", "report"), for the message.

    Returns:
        The path to write (the link's target where ``path`` is a link).

    Raises:
        KinelabError: not a path; a folder, device, FIFO or socket; a link out of its folder or to such a thing;
            a missing folder.
    """
    path = as_path(path, f"the {what}'s path", KinelabError)
    try:
        info = path.lstat()
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise KinelabError(f"cannot write the {what} to {path}: {exc.strerror or exc}") from None
    if info is not None and stat.S_ISLNK(info.st_mode):
        return _link_target(path, what)
    if info is not None and not stat.S_ISREG(info.st_mode):
        hint = f" such as {path / 'view.html'}" if stat.S_ISDIR(info.st_mode) else ""
        raise KinelabError(f"cannot write the {what} to {path}: it is {_kind_of(info.st_mode)}; kinelab writes a new "
                           f"file or replaces a regular one: give a file name{hint}")
    if not path.parent.is_dir():
        raise KinelabError(f"cannot write the {what} to {path}: the folder {path.parent} does not exist")
    return path


def output_folder(path: str | Path, what: str) -> Path:
    """``path`` as a folder kinelab may create or write into: new, or an existing folder that is not a link.

    Args:
        path: the folder.
        what: what goes there ("map", "report"), for the message.

    Raises:
        KinelabError: not a path; a link; a file, device, FIFO or socket.
    """
    path = as_path(path, f"the {what}'s folder", KinelabError)
    try:
        info = path.lstat()
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise KinelabError(f"cannot write the {what} to {path}: {exc.strerror or exc}") from None
    if stat.S_ISLNK(info.st_mode):
        raise KinelabError(f"cannot write the {what} to {path}: it is a symbolic link; give a folder of its own")
    if not stat.S_ISDIR(info.st_mode):
        kind = "a file" if stat.S_ISREG(info.st_mode) else _kind_of(info.st_mode)
        raise KinelabError(f"cannot write the {what} to {path}: it is {kind}, not a folder")
    return path


def write_output(path: str | Path, data: str | bytes, what: str = "file") -> Path:
    """Write ``data`` to ``path`` whole: into a new file beside it, then renamed into place (never half a file).

    The one writer of every file kinelab writes (pages, reports, maps' pages, JSON): it creates a new file (mode by
    the umask, as any tool) or replaces a regular file keeping its mode, and refuses anything else that exists
    (:func:`output_target`).

    Args:
        path: the file to write.
        data: its contents (text is written as UTF-8).
        what: what it is ("page", "report"), for messages.

    Returns:
        The path written (a link's target where ``path`` is a link in the same folder).

    Raises:
        KinelabError: as :func:`output_target`, or the folder is not writable (the system's reason).
    """
    target = output_target(path, what)
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        mode = 0o666 & ~umask()
    raw = data.encode("utf-8") if isinstance(data, str) else data

    tmp: str | None = None
    try:
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.")
        with os.fdopen(fd, "wb") as f:
            f.write(raw)
        os.chmod(tmp, mode)
        stop_if_interrupted(str(target))
        os.replace(tmp, target)
        tmp = None
    except OSError as exc:
        raise KinelabError(f"cannot write the {what} to {path}: {exc.strerror or exc}") from None
    finally:
        if tmp is not None:  # not renamed into place (a failure, or Ctrl-C): nothing of it is left
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return target
