"""Execute the notebooks and write each as a self-contained HTML page under docs/notebooks/.

    python tools/render_notebooks.py            # every notebook
    python tools/render_notebooks.py 05 03      # those whose names start with these numbers
    python tools/render_notebooks.py --out DIR  # elsewhere (the tests render into a temporary folder)

Needs the test or notebooks extra (nbclient, nbconvert). Plots are embedded as images and the 3-D views as
static meshcat pages, so the HTML opens offline; a notebook that fails to run stops the script with its
error.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def render(notebook: Path, out_dir: Path, timeout: int = 600) -> Path:
    """Run ``notebook`` (in the notebooks folder) and write its HTML page into ``out_dir``; returns the page."""
    import nbformat
    from nbclient import NotebookClient
    from nbconvert import HTMLExporter
    from nbconvert.preprocessors import CoalesceStreamsPreprocessor

    nb = nbformat.read(notebook, as_version=4)
    NotebookClient(nb, timeout=timeout, kernel_name="python3",
                   resources={"metadata": {"path": str(notebook.parent)}}).execute()
    exporter = HTMLExporter(embed_images=True)
    exporter.register_preprocessor(CoalesceStreamsPreprocessor, enabled=True)  # one block per cell's printout
    body, _ = exporter.from_notebook_node(nb)
    out_dir.mkdir(parents=True, exist_ok=True)
    page = out_dir / (notebook.stem + ".html")
    page.write_text(body, encoding="utf-8")
    return page


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("prefixes", nargs="*", help="notebook numbers to render (default: all)")
    parser.add_argument("--out", default=str(ROOT / "docs" / "notebooks"), help="folder for the HTML pages")
    args = parser.parse_args(argv)
    os.environ["KINELAB_PROGRESS"] = "0"  # a page shows results, not the bars of the run that made them
    notebooks = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    chosen = [nb for nb in notebooks if not args.prefixes or nb.name[:2] in args.prefixes]
    if not chosen:
        print(f"no notebook matches {args.prefixes}", file=sys.stderr)
        return 2
    for nb in chosen:
        print(f"{nb.name} -> {render(nb, Path(args.out))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
