"""The project's own promises: CI runs the README's test command (then ruff, mypy and the docs build as steps of
its own), the README's example runs, the notebooks are their sources, the layers import downwards only."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: kinelab's layers, lowest first: a module imports its own layer and lower ones only.
LAYERS = ["errors", "values", "files", "lazy", "scratch", "progress", "geometry", "core", "robot", "collision", "dq",
          "typing", "ik", "wholebody", "analysis", "maps", "studies", "view", "report", "cli"]


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


def test_the_readme_python_example_runs(tmp_path, monkeypatch):
    """In an empty folder: whatever the example writes (a map) must not land in, or come from, the repository."""
    monkeypatch.chdir(tmp_path)
    block = re.search(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102 - the README's own example
    assert namespace["res"].success
    assert namespace["a"].rank == 4  # youBot at zero: θ2 = θ3 = 0 and the gripper vertical, two losses
    namespace["scene"].close()


def test_each_notebook_is_its_jupytext_source():
    """notebooks/NN_*.py (jupytext percent format) are the sources; the .ipynb must be their conversion."""
    jupytext = pytest.importorskip("jupytext", reason="jupytext is part of the test extra")
    import nbformat

    sources = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.py"))
    assert len(sources) >= 4
    for source in sources:
        expected = [(c.cell_type, c.source) for c in jupytext.read(source).cells]
        written = nbformat.read(source.with_suffix(".ipynb"), as_version=4)
        assert [(c.cell_type, c.source) for c in written.cells] == expected, source.name
        assert all(not c.get("outputs") for c in written.cells if c.cell_type == "code"), "commit without outputs"


def test_the_package_tree_has_no_import_cycles_and_lower_layers_import_no_higher_ones():
    """Layers, lowest first; a module may import its own layer's modules and lower layers only."""
    import ast

    rank = {name: i for i, name in enumerate(LAYERS)}
    src = ROOT / "src" / "kinelab"
    for path in [*src.rglob("*.py"), *src.rglob("*.pyi")]:  # a compiled module's stub imports what it names too
        parts = path.relative_to(src).with_suffix("").parts
        if parts[0] == "__init__":
            continue
        own = rank[parts[0]]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("kinelab."):
                target = node.module.split(".")[1]
                assert rank[target] <= own, f"{path.relative_to(ROOT)} imports {node.module}"


def test_the_architecture_page_names_the_layers_in_order_and_every_package():
    """docs/architecture.md's layer table is the order the test above holds, and every package of src/kinelab is on
    the page: the drawing cannot fall behind the tree unnoticed."""
    page = (ROOT / "docs" / "architecture.md").read_text()
    table = page.split("## Layers, lowest first", 1)[1].split("\n## ", 1)[0]
    first_cells = [line.split("|")[1] for line in table.splitlines() if line.startswith("| `")]
    assert [name for cell in first_cells for name in re.findall(r"`(\w+)`", cell)] == LAYERS
    packages = sorted(p.parent.relative_to(ROOT / "src" / "kinelab").as_posix()
                      for p in (ROOT / "src" / "kinelab").rglob("__init__.py") if p.parent.name != "kinelab")
    missing = [name for name in packages if f"{name.split('/')[-1]}/" not in page and f"`{name}`" not in page]
    assert not missing, f"packages not on docs/architecture.md: {missing}"


def test_no_module_imports_itself_back():
    """No import cycle between kinelab's modules (module-level and function-level imports alike)."""
    import ast

    src = ROOT / "src" / "kinelab"
    graph: dict[str, set[str]] = {}
    for path in src.rglob("*.py"):
        rel = path.relative_to(src).with_suffix("").parts
        name = ".".join(("kinelab", *rel[:-1])) if rel[-1] == "__init__" else ".".join(("kinelab", *rel))
        deps = graph.setdefault(name, set())
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("kinelab"):
                deps.add(node.module)
                deps.update(f"{node.module}.{a.name}" for a in node.names)
    graph = {k: {d for d in v if d in graph and d != k} for k, v in graph.items()}
    packages = {k for k in graph if (src / k.replace("kinelab.", "", 1).replace(".", "/") / "__init__.py").exists()
                or k == "kinelab"}
    state: dict[str, int] = {}

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for dep in sorted(graph[node]):
            if dep in packages:  # a package's __init__ re-exports; its submodules are the real edges
                continue
            if state.get(dep) == 1:
                raise AssertionError("import cycle: " + " -> ".join([*trail, node, dep]))
            if dep not in state:
                visit(dep, [*trail, node])
        state[node] = 2

    for module in sorted(graph):
        if module not in state and module not in packages:
            visit(module, [])
    assert len(state) >= 40  # every module of the tree was walked


@pytest.mark.parametrize("script", [
    "import kinelab; kinelab.load('ur5', prepare=False).fk([0.1] * 6)",
    "from kinelab.robot import load; load('ur5').fk([0.1] * 6)",
    "from kinelab.cli import main; main(['fk', 'ur5', '0', '0', '0', '0', '0', '0'])",
    "from kinelab.cli import main; main(['robots'])",
])
def test_a_load_fk_robots_or_help_imports_no_solver_and_no_jit(script):
    """Start-up (#32): what a load and an fk need, nothing more: no numba (no solver kernel), no collision model,
    no closed form, no maps or reports (``kinelab.load`` readies an arm's solvers since #71: without that, the load
    alone)."""
    import subprocess
    import sys

    probe = (f"import sys, contextlib, io\nwith contextlib.redirect_stdout(io.StringIO()):\n    {script}\n"
             "print(' '.join(sorted(m for m in sys.modules if m.split('.')[0] in ('numba', 'scipy', 'matplotlib') or "
             "m.startswith(('kinelab.collision', 'kinelab.ik.analytic', 'kinelab.maps', 'kinelab.report.b', "
             "'kinelab.report.v', 'kinelab.report.r')))))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-1000:]
    assert done.stdout.strip() == "", done.stdout


def test_load_is_the_function_whichever_way_it_was_reached_first():
    """``kinelab.load`` first, then ``from kinelab.robot import load``: while the module was named ``load`` too, the
    second gave the module (a CLI command after a notebook cell: 'module' object is not callable)."""
    import subprocess
    import sys

    code = ("import kinelab; kinelab.load; from kinelab.robot import load; import kinelab.robot as r; "
            "assert callable(load) and callable(r.load), (load, r.load)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_the_readme_names_the_youbot_joints_as_the_cli_takes_them():
    """#60 item 4: the README and `robots` named the youBot's joints X_C, Y_C, θ, θ1..θ5, the CLI wants platform_x,
    ..., arm_joint_5."""
    import kinelab

    row = next(line for line in (ROOT / "README.md").read_text().splitlines() if line.startswith("| `youbot` |"))
    names = [j.name for j in kinelab.load("youbot").joints]
    assert names[:3] == ["platform_x", "platform_y", "platform_yaw"] and names[-1] == "arm_joint_5"
    assert all(n in row for n in ("platform_x", "platform_y", "platform_yaw", "arm_joint_1", "arm_joint_5"))


GLOSSARY_TERMS = ("branch", "cuspidal", "SEW angle", "Good–Turing", "Newton–Kantorovich", "Anderson acceleration",
                  "fold quadrant", "lap change", "merit", "Procrustes", "Jlog3", "floor", "judge", "share",
                  "certified", "monitor", "bypass", "step")


def test_the_glossary_defines_the_words_the_readme_and_the_reports_use():
    """#72 item 5: each term a user meets in the README, the CLI or the reports has its entry (a bold headword)."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "glossary.md").read_text().lower()
    missing = [t for t in GLOSSARY_TERMS if f"**{t.lower()}" not in text]
    assert missing == []
