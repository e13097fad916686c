"""A xacro expansion bounded as a whole: run in a child process with a wall-clock limit, a memory limit and an
output limit, so that no file — however it nests, repeats or formats — takes more than :data:`SECONDS`,
:data:`MEMORY` bytes beyond the child's own start, or writes more than :data:`OUTPUT` bytes. The child's side is
:mod:`kinelab.robot.xacro_child`.

Limits per expression (:mod:`kinelab.robot.xacro_eval`) catch most abuse with a clear message; these catch the
rest: an expression whose own evaluation is slow (``round(1, -10**9)``), a quadratic one (``sum`` of a million
lists), a value repeated a thousand times, a URDF of a gigabyte. The child writes the URDF itself, so writing is
bounded too.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinelab import lazy
from kinelab.errors import URDFError

if TYPE_CHECKING:
    import subprocess
else:
    subprocess = lazy.module("subprocess", globals())

SECONDS = 20.0  # [s] the whole expansion, the child's start and the URDF's writing included
MEMORY = 1 << 30  # [bytes] the address space the expansion may add to the child's own
OUTPUT = 64 << 20  # [bytes] the largest URDF written (a humanoid's: about 1 MB)


def run(path: Path, job: dict[str, Any]) -> None:
    """Expand the xacro file ``job["path"]`` into ``job["out"]`` in a bounded child.

    Args:
        path: the xacro file (for messages).
        job: path, args (name → value), trusted, roots (folders it may read), out (where the URDF goes).

    Raises:
        URDFError: the expansion's own refusal or failure, or a limit passed (named, with its value).
    """
    try:
        done = subprocess.run([sys.executable, "-m", "kinelab.robot.xacro_child"], input=json.dumps(job),
                              capture_output=True, text=True, timeout=SECONDS)
    except subprocess.TimeoutExpired:
        raise URDFError(f"{path}: the expansion took more than {SECONDS:g} s (kinelab's limit for a whole xacro "
                        "expansion, writing included); a real robot's takes well under a second") from None
    lines = done.stdout.strip().splitlines()
    try:
        said = json.loads(lines[-1]) if lines else {}
    except json.JSONDecodeError:
        said = {}
    if done.returncode == 0 and said.get("ok"):
        return
    if "error" in said:
        raise URDFError(said["error"])
    last = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
    raise URDFError(f"{path}: the expansion ended abnormally ({last})")
