"""The notebooks' rendered copies: the renderer builds a page with the outputs, and every notebook has one."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_renderer_executes_a_notebook_into_a_self_contained_page(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "render_notebooks.py"), "03", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    page = (tmp_path / "03_biquaternion_stanford.html").read_text()
    assert "final M0 = -1.0" in page  # an output, so the notebook ran
    assert "data:image/png;base64," in page  # the figures are embedded
    assert "about 40 s" in page and "would need ε" in page  # the worked-out model time


def test_every_notebook_has_a_rendered_page_in_the_docs():
    notebooks = sorted(p.stem for p in (ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    pages = sorted(p.stem for p in (ROOT / "docs" / "notebooks").glob("*.html"))
    assert notebooks and pages == notebooks


def test_the_rendered_pages_carry_no_machine_path_and_no_warning():
    """A committed page shows what a reader sees: no stderr output (a warning names the renderer's files) and no
    path of the machine that rendered it."""
    for page in sorted((ROOT / "docs" / "notebooks").glob("*.html")):
        text = page.read_text()
        assert 'data-mime-type="application/vnd.jupyter.stderr"' not in text, page.name  # an output, not the CSS
        for machine in ("/work/", "/root/", "/home/", "site-packages"):
            assert machine not in text, (page.name, machine)
