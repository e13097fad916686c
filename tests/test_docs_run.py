"""Docs that run: every Python block of README.md and docs/*.md is executed, and where a line is followed by a
comment line of the form ``# <repr>`` the expression's repr must be that comment; every JSON block parses (an
obstacle file loads as an Environment). A block that cannot run says so just above it:
``<!-- not run: <reason> -->``. The README's command reference is the parser's own (tests/cli/test_reference.py)
and its two install commands are what .ci/run runs."""

import ast
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"(?:<!-- not run: (?P<why>[^>]+?) -->\n)?```(?P<lang>\w*)\n(?P<body>.*?)```", re.S)


def blocks(lang):
    for page in PAGES:
        text = page.read_text()
        for m in FENCE.finditer(text):
            if m.group("lang") == lang:
                line = text[:m.start("body")].count("\n") + 1
                yield pytest.param(m.group("body"), m.group("why"), id=f"{page.name}:{line}")


def _is_expression(line):
    try:
        tree = ast.parse(line)
    except SyntaxError:
        return False
    return len(tree.body) == 1 and isinstance(tree.body[0], ast.Expr)


@pytest.mark.parametrize(("body", "why"), list(blocks("python")))
def test_every_python_block_runs_and_prints_what_it_says(body, why, tmp_path, monkeypatch):
    if why is not None:
        assert len(why.strip()) > 10, "a block left out says why"
        pytest.skip(why)
    monkeypatch.chdir(tmp_path)  # a block that writes (a map store, a page) writes here
    namespace: dict = {}
    lines = body.splitlines()
    pending: list[str] = []
    for k, line in enumerate(lines):
        follows = k + 1 < len(lines) and lines[k + 1].startswith("# ") and _is_expression(line)
        if follows:
            exec("\n".join(pending), namespace)  # noqa: S102 - the docs' own code, run as a reader would
            pending = []
            assert repr(eval(line, namespace)) == lines[k + 1][2:], line  # noqa: S307
        elif not (line.startswith("# ") and k > 0 and _is_expression(lines[k - 1])):
            pending.append(line)
    exec("\n".join(pending), namespace)  # noqa: S102
    scene = namespace.get("scene")
    if hasattr(scene, "close"):
        scene.close()


@pytest.mark.parametrize(("body", "why"), list(blocks("json")))
def test_every_json_block_parses_and_an_obstacle_file_loads(body, why, tmp_path):
    data = json.loads(body)
    if "obstacles" in data:
        from kinelab import Environment

        (tmp_path / "scene.json").write_text(body)
        assert len(Environment.from_file(tmp_path / "scene.json").obstacles) == len(data["obstacles"])


def test_the_pages_have_blocks_to_run():
    assert len(list(blocks("python"))) >= 5 and len(list(blocks("json"))) >= 1


def test_the_readme_names_every_registered_robot_and_no_other():
    from kinelab.robot.catalog import BUNDLED, ENTRIES

    readme = (ROOT / "README.md").read_text()
    table = re.findall(r"^\| `(\w+)` \|", readme, re.M)
    assert table == [e.name for e in BUNDLED]  # the bundled URDFs' table, in the catalog's order
    robots = readme[readme.index("## Robots"):readme.index("## Python")]
    named = set(re.findall(r"`(\w+)`", robots))
    assert set(ENTRIES) <= named, sorted(set(ENTRIES) - named)
