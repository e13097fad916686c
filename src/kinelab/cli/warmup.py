"""``kinelab warmup``: compile every solver path now, with progress, instead of at its first use."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

from kinelab.robot import load


def add(sub: Any) -> None:
    """The ``warmup`` subcommand."""
    s = sub.add_parser("warmup", help="compile every solver path for this machine now (once after an install; "
                                      "later runs load the cached code)")
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Each path in turn, one line each as it finishes, on stderr; the total at the end."""
    from kinelab.ik import warmup

    t0 = time.perf_counter()
    print("kinelab: compiling every solver path for this machine (about a minute each the first time) ...",
          file=sys.stderr, flush=True)
    for name, seconds in warmup.run(load("ur5")):
        print(f"  {name}: ready ({seconds:.1f} s)", file=sys.stderr, flush=True)
    print(f"kinelab: every path is ready ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
    return 0
