"""``kinelab validate``: every kinelab computation against Pinocchio, and the papers' results."""

from __future__ import annotations

import argparse
import shutil
import textwrap
from typing import TYPE_CHECKING

from kinelab import lazy
from kinelab.cli.common import Subcommands, json_flag, print_json, progress_of, seed_argument
from kinelab.report.outfolder import check_output_folder

if TYPE_CHECKING:
    from kinelab.report import render, validate
else:
    render = lazy.module("kinelab.report.render", globals())
    validate = lazy.module("kinelab.report.validate", globals())


def add(sub: Subcommands) -> None:
    """The ``validate`` subcommand."""
    s = sub.add_parser("validate", help="check every kinelab computation against Pinocchio on the bundled robots")
    s.add_argument("--robots", nargs="+", default=None,
                   help="robots to check (default: stanford era youbot panda ur5, the whole talos and baxter, and "
                        "fourbar delta cassie, which close loops)")
    s.add_argument("--n", type=int, default=None, help="random configurations per check (default: each check's own)")
    seed_argument(s)
    s.add_argument("--out", default=None,
                   help="the report folder (Markdown, HTML with the figures, JSON); default ./kinelab-report, "
                        "none with --json")
    json_flag(s)
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the checks, print the table, write the report; exit 1 when a check fails."""
    out = args.out or (None if args.json else "kinelab-report")  # --json alone writes no folder
    if out:
        check_output_folder(out, "validate")  # before the work, not after it
    report = validate.run(robots=args.robots, n=args.n, seed=args.seed, progress=progress_of(args),
                          lines=not args.json and not progress_of(args))
    if out:
        render.write_validate_report(report, out)
    if args.json:
        print_json(report.to_dict())
    else:
        width = shutil.get_terminal_size((120, 24)).columns
        print(textwrap.fill(render.provenance_line(report.provenance), width), end="\n\n")
        print(render.validate_table(report, width=width))
        print(f"report written to {out}")
    return 0 if report.passed else 1
