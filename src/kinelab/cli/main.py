"""The ``kinelab`` command: the parser of every subcommand, and how a run ends.

Each command lives in a module of its own with its parser beside its handler (:mod:`~kinelab.cli.robots`,
:mod:`~kinelab.cli.fk`, :mod:`~kinelab.cli.ik`, :mod:`~kinelab.cli.branches`, :mod:`~kinelab.cli.singular`,
:mod:`~kinelab.cli.view`, :mod:`~kinelab.cli.bench`, :mod:`~kinelab.cli.maps`, :mod:`~kinelab.cli.validate`);
what they share is in :mod:`~kinelab.cli.common`. User errors print one line and exit with code 2; Ctrl-C exits
with 130. Every command that prints results takes ``--json`` for a stable machine-readable form (see README).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any

import kinelab
from kinelab.cli.common import Parser
from kinelab.errors import KinelabError
from kinelab.files import held_interrupts, output_target, stop_if_interrupted

# each command → the module with its parser and handler, in the order ``kinelab --help`` lists them
COMMANDS = {"robots": "robots", "info": "robots", "fk": "fk", "ik": "ik", "branches": "branches",
            "singular": "singular", "view": "view", "animate": "view", "bench": "bench", "map": "maps",
            "validate": "validate", "teach": "teach"}


class _Version(argparse.Action):
    """``--version``, the installed version looked up only when asked for (the lookup costs 60 ms a start)."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any,
                 option_string: str | None = None) -> None:
        print(f"kinelab {kinelab.__version__}")  # on stdout, as argparse's own version action prints it
        parser.exit()


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The ``kinelab`` command line: one subparser per command.

    Args:
        argv: the arguments about to be parsed: when their first word names a command, only that command's module
            is imported and its parser built (a command starts without the others' imports); otherwise (None,
            ``--help``, a mistyped command) every command's, so that help and errors list them all.
    """
    p = Parser(prog="kinelab",
               description="Kinematics of serial arms, whole robots and closed chains, checked against Pinocchio.")
    p.add_argument("--version", action=_Version, nargs=0, help="show kinelab's version and exit")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    named = COMMANDS.get(argv[0]) if argv else None
    modules = [named] if named else list(dict.fromkeys(COMMANDS.values()))
    for module in modules:
        importlib.import_module(f"kinelab.cli.{module}").add(sub)
    return p


def _one_line(message: Warning | str, category: type[Warning], filename: str, lineno: int,
              line: str | None = None) -> str:
    """A warning as the CLI shows it: one line, no source path."""
    return f"kinelab: warning: {' '.join(str(message).split())}\n"


MAX_MESSAGE = 2000  # [characters] of an error line; the rest is counted, not printed


def one_line(message: str) -> str:
    """An error message on one line of at most MAX_MESSAGE characters."""
    text = " ".join(message.split())
    return text if len(text) <= MAX_MESSAGE else f"{text[:MAX_MESSAGE]}… ({len(text)} characters)"


def main(argv: list[str] | None = None) -> int:
    """Run one command; a user error prints one line and returns 2, Ctrl-C returns 130 (and replaces no output,
    even where a library swallowed the interrupt)."""
    with held_interrupts():  # before the commands' imports: a Ctrl-C a library swallows is still remembered
        return _run(argv)


def _run(argv: list[str] | None) -> int:
    warnings.formatwarning = _one_line
    try:
        words = list(sys.argv[1:] if argv is None else argv)
        args = build_parser(words).parse_args(words)
        args.command_line = words  # what resumes an interrupted command
        if getattr(args, "html", None):  # a page that could not be written is refused before the work it shows
            output_target(args.html, "page")
        code: int = args.func(args)
        stop_if_interrupted("the output")  # a Ctrl-C swallowed on the way: the command did not finish
        return code
    except KinelabError as exc:
        print(f"kinelab: error: {one_line(str(exc))}", file=sys.stderr)
        return getattr(exc, "exit_code", 2)  # 2: the user's input; a failure of the tool's own says otherwise
    except KeyboardInterrupt as stop:
        note = getattr(stop, "note", "")
        print(f"kinelab: interrupted{'; ' + note if note else ''}", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (| head): say nothing more
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
