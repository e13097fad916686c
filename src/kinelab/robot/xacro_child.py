"""The child of a bounded xacro expansion (:mod:`kinelab.robot.xacro_bounded`): ``python -m
kinelab.robot.xacro_child`` reads the job as JSON on stdin, expands within the memory and output limits, and says how
it ended on the last line of stdout (JSON)."""

from __future__ import annotations

import json
import resource
import signal
import sys
from pathlib import Path
from typing import Any

from kinelab.errors import URDFError
from kinelab.robot.xacro import expand_here
from kinelab.robot.xacro_bounded import MEMORY, OUTPUT


def main() -> int:
    """Read the job on stdin, expand within the memory and output limits, say how it ended."""
    job = json.loads(sys.stdin.read())
    path = Path(job["path"])
    _limit(resource.RLIMIT_AS, _address_space() + MEMORY)
    try:
        text = expand_here(path, job["args"], bool(job["trusted"]), [Path(r) for r in job["roots"]])
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # past the limit a write fails (EFBIG) instead of killing
        _limit(resource.RLIMIT_FSIZE, OUTPUT)
        Path(job["out"]).write_text(text)
    except URDFError as err:
        return _say({"error": str(err)})
    except MemoryError:
        return _say({"error": f"{path}: the expansion needs more than {MEMORY >> 20} MB (kinelab's limit for a "
                              "whole xacro expansion)"})
    except OSError as err:
        return _say({"error": f"{path}: the expanded URDF is larger than {OUTPUT >> 20} MB (kinelab's limit) or "
                              f"cannot be written ({err.strerror or err})"})
    return _say({"ok": True})


def _limit(kind: int, value: int) -> None:
    soft, hard = resource.getrlimit(kind)
    value = value if hard == resource.RLIM_INFINITY else min(value, hard)
    resource.setrlimit(kind, (value, hard))


def _address_space() -> int:
    """The child's address space now [bytes] (Python, pinocchio and xacro loaded)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmSize:"):
            return int(line.split()[1]) * 1024
    return 0


def _say(message: dict[str, Any]) -> int:
    print(json.dumps(message), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
