"""Write a notebook from a list of (kind, source) cells: `python tools/make_notebook.py SPEC.py OUT.ipynb`.

SPEC.py defines CELLS = [("md", "..."), ("code", "..."), ...]. Notebooks are committed without outputs;
editing the spec and regenerating keeps them reviewable as plain Python.
"""

import runpy
import sys

import nbformat


def main(spec: str, out: str) -> None:
    cells = runpy.run_path(spec)["CELLS"]
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    for kind, source in cells:
        make = nbformat.v4.new_markdown_cell if kind == "md" else nbformat.v4.new_code_cell
        nb.cells.append(make(source.strip("\n")))
    nbformat.write(nb, out)


if __name__ == "__main__":
    main(*sys.argv[1:])
