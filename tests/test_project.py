"""The project's own promises: CI runs the README's test command, and the code is ruff clean."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _commands(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines() if line.strip().startswith("python3 -m venv")]


def test_ci_runs_exactly_the_readme_test_command():
    readme = _commands((ROOT / "README.md").read_text())
    ci = _commands((ROOT / ".ci" / "run").read_text())
    assert len(readme) == 2 and "kinelab validate" in readme[0] and "pytest" in readme[1]
    assert ci == [readme[1]]


def test_readme_opens_with_the_two_commands():
    head = (ROOT / "README.md").read_text()[:1500]
    assert re.search(r"kinelab validate", head) and re.search(r"pytest", head)


def test_ruff_is_clean():
    pytest.importorskip("ruff", reason="ruff is part of the test extra")
    proc = subprocess.run([sys.executable, "-m", "ruff", "check", "src", "tests", "tools"], cwd=ROOT,
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout


def test_the_readme_python_example_runs():
    block = re.search(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102 - the README's own example
    assert namespace["res"].success
    assert namespace["a"].rank == 4  # youBot at zero: θ2 = θ3 = 0 and the gripper vertical, two losses
    namespace["scene"].close()
