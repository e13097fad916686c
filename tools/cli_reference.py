"""Print the README's command-line reference from the parser itself: one usage per (sub)command.

Run ``python tools/cli_reference.py`` and paste its output into the README's "Command line" block;
``tests/cli/test_reference.py`` checks that the README names every option the parser has, and no other.
"""

import argparse
import re

from kinelab.cli.main import build_parser

SOURCE = ("[--tool TOOL] [--base BASE] [--srdf SRDF] [--group GROUP] [--package-dir PACKAGE_DIR] "
          "[--xacro-arg NAME=VALUE] [--lock JOINT=VALUE] [--trust-xacro]")


def usages(parser: argparse.ArgumentParser, prefix: str = "kinelab") -> list[str]:
    """``usage`` lines of every leaf command, without argparse's 'usage: ' and its -h."""
    lines = []
    for action in parser._actions:  # argparse keeps its subparsers here
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                lines += usages(sub, f"{prefix} {name}")
            return lines
    text = " ".join(parser.format_usage().split())
    return [text.removeprefix("usage: ").replace(" [-h]", "", 1)]


_GROUP = re.compile(r"\[(?:[^\[\]]|\[[^\[\]]*\])*\]|\S+")  # an option in brackets (one nesting) or a word


def _packed(usage: str, width: int) -> list[str]:
    """The usage over lines of at most ``width`` characters, never breaking inside an option's brackets."""
    lines = [""]
    for token in _GROUP.findall(usage):
        if lines[-1] and len(lines[-1]) + 1 + len(token) > width:
            lines.append("    ")
        lines[-1] += (" " if lines[-1].strip() else "") + token
    return lines


def reference(width: int = 110) -> str:
    """The block: every usage, the robot-source options written once as [SOURCE], wrapped at ``width``."""
    lines = []
    for usage in usages(build_parser()):
        usage = usage.replace(SOURCE, "[SOURCE]")
        lines += _packed(usage, width)
    lines += [""] + _packed("SOURCE = " + SOURCE, width)
    return "\n".join(lines)


if __name__ == "__main__":
    print(reference())
