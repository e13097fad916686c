"""The README's command-line reference is the parser's own (tools/cli_reference.py): no option missing, none
that does not exist."""

import re
import runpy
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_readme_command_reference_is_the_parser_s():
    reference = runpy.run_path(str(ROOT / "tools" / "cli_reference.py"))["reference"]()
    readme = (ROOT / "README.md").read_text()
    block = re.search(r"## Command line\n\n```\n(.*?)```", readme, re.S).group(1)
    assert block.rstrip("\n") == reference


def test_every_option_named_in_the_readme_exists():
    from kinelab.cli.main import build_parser

    options = set()
    stack = [build_parser()]
    while stack:
        parser = stack.pop()
        for action in parser._actions:
            options.update(action.option_strings)
            if hasattr(action, "choices") and isinstance(action.choices, dict):
                stack += list(action.choices.values())
    readme = (ROOT / "README.md").read_text()
    commands = re.findall(r"kinelab (?:robots|info|fk|ik|branches|singular|view|animate|bench|map|validate)\b[^`\n]*",
                          readme)
    named = {option for line in commands for option in re.findall(r"(?<![\w-])(--[a-z][a-z-]+)", line)}
    assert len(commands) > 10 and named <= options, sorted(named - options)
