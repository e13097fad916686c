"""tools/install.py, the README's install: pip's output passed through, a line whenever pip is quiet, pip's status."""

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _install():
    spec = importlib.util.spec_from_file_location("kinelab_install", ROOT / "tools" / "install.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_quiet_command_gets_a_line_naming_what_pip_does(capsys):
    """A command that prints pip's compile line then stays silent 2 s, heartbeats every 0.5 s: the lines pass
    through in order, at least one heartbeat names the compile, and the command's status comes back."""
    script = "import sys, time; print('Building editable for kinelab (pyproject.toml): started'); " \
             "sys.stdout.flush(); time.sleep(2.0); print('done'); sys.exit(3)"
    status = _install().run([sys.executable, "-c", script], quiet_s=0.5)
    out = capsys.readouterr().out.splitlines()
    assert status == 3
    assert out[0].startswith("Building editable for kinelab") and out[-1] == "done"
    beats = out[1:-1]
    assert beats and all("still compiling kinelab's core" in beat for beat in beats)


def test_the_phases_follow_pips_lines():
    install = _install()
    assert install.phase("Installing collected packages: numpy, pin", "x").startswith("installing the packages")
    assert install.phase("  Installing build dependencies: started", "x") == "installing the build's dependencies"
    assert install.phase("Requirement already satisfied: numpy", "downloading") == "downloading"


def test_the_readme_installs_through_it():
    """Both README commands install through tools/install.py (so neither is silent while pip works)."""
    commands = [line for line in (ROOT / "README.md").read_text().splitlines() if line.startswith("python3 -m venv")]
    assert len(commands) == 2 and all(".venv/bin/python tools/install.py" in c for c in commands)
