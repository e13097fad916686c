"""The ``kinelab`` command: parse, call the API, hand the result to the report renderers."""

from kinelab.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
