"""The source papers' experiments, used by notebooks, ``kinelab validate`` and the tests."""
