"""``pip install -e`` of this checkout that is never quiet for more than 10 s.

pip prints nothing while it installs build dependencies, compiles kinelab's core (about a minute on two cores) or
unpacks the wheels it downloaded; a user or a CI log sees a silent terminal. This runs the same pip command in the
same Python, passes pip's lines through as they come, and when pip has said nothing for 8 s prints one line saying
what pip is doing and for how long. Standard library only: it runs before kinelab is installed.

Usage (from the repository root, in the virtual environment's Python)::

    .venv/bin/python tools/install.py            # pip install -e .
    .venv/bin/python tools/install.py '.[test]'  # pip install -e '.[test]'

Exit status: pip's, or 130 after Ctrl-C (pip stopped, one line said).
"""

from __future__ import annotations

import queue
import subprocess
import sys
import threading
import time

QUIET_S = 8.0  # [s] under 10 s with a busy machine's delay
#: pip's line prefixes and what pip does after each, for the heartbeat line.
PHASES = (
    ("Installing build dependencies", "installing the build's dependencies"),
    ("Getting requirements to build", "asking the build what it needs"),
    ("Installing backend dependencies", "installing the build's dependencies"),
    ("Preparing editable metadata", "reading kinelab's metadata"),
    ("Preparing metadata", "reading a package's metadata"),
    ("Collecting", "resolving the dependencies"),
    ("Downloading", "downloading"),
    ("Building editable for kinelab", "compiling kinelab's core (about a minute on two cores)"),
    ("Building wheel", "building a wheel"),
    ("Installing collected packages", "installing the packages (unpacking the wheels)"),
)


def phase(line: str, current: str) -> str:
    """What pip does after printing ``line`` (``current`` when the line does not say)."""
    text = line.strip()
    for prefix, words in PHASES:
        if text.startswith(prefix):
            return words
    return current


def _reader(stream: object, lines: queue.Queue[str | None]) -> None:
    for line in stream:  # type: ignore[attr-defined]
        lines.put(line)
    lines.put(None)


def run(command: list[str], quiet_s: float = QUIET_S) -> int:
    """Run ``command``, echo its output, and print a heartbeat after every ``quiet_s`` [s] of silence.

    Returns:
        The command's exit status; 130 after Ctrl-C (the command stopped).
    """
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1)
    lines: queue.Queue[str | None] = queue.Queue()
    threading.Thread(target=_reader, args=(process.stdout, lines), daemon=True).start()
    start = last = time.monotonic()
    doing = "starting"
    try:
        while True:
            try:
                line = lines.get(timeout=0.2)
            except queue.Empty:
                now = time.monotonic()
                if now - last >= quiet_s:
                    print(f"  … pip is still {doing} ({now - start:.0f} s since the start)", flush=True)
                    last = now
                continue
            if line is None:
                return process.wait()
            print(line, end="", flush=True)
            last = time.monotonic()
            doing = phase(line, doing)
    except KeyboardInterrupt:
        process.terminate()
        process.wait()
        print("install stopped (Ctrl-C); run the same command again to resume", file=sys.stderr)
        return 130


def main(argv: list[str]) -> int:
    """``pip install -e TARGET`` (TARGET ``.`` unless given, e.g. ``'.[test]'``) with heartbeats."""
    target = argv[0] if argv else "."
    return run([sys.executable, "-m", "pip", "install", "--progress-bar", "off", "-e", target])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
