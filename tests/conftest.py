import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from helpers import BUNDLED, ERD_ARMS

import kinelab


@pytest.fixture(scope="session", autouse=True)
def session_temp():
    """One temporary folder for everything the session writes outside pytest's tmp_path: kinelab's xacro expansions,
    the CLI's subprocesses, Chromium's profiles, Dask's scratch space (TMPDIR, inherited by every child). Removed
    when the session ends, so a run leaves nothing in the machine's temporary folder (.ci/run checks it)."""
    folder = tempfile.mkdtemp(prefix="kinelab-tests-")
    while "__" in Path(folder).name:  # tests write these paths into xacro $(eval ...), which refuses "__" in it
        os.rmdir(folder)
        folder = tempfile.mkdtemp(prefix="kinelab-tests-")
    saved = os.environ.get("TMPDIR"), tempfile.tempdir
    os.environ["TMPDIR"], tempfile.tempdir = folder, folder
    yield Path(folder)
    if saved[0] is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = saved[0]
    tempfile.tempdir = saved[1]
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session")
def robots():
    """Every robot the cross-checks run on, loaded once."""
    return {name: kinelab.load(name) for name in BUNDLED + ERD_ARMS}


@pytest.fixture
def no_tolerance_floor():
    """Tolerances below kinelab's floor (1e-12) accepted, for tests that need one no answer can meet: the
    budget or the restart count must then end the solve."""
    from kinelab.ik.request import unmeetable_tolerances

    with unmeetable_tolerances():
        yield


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


_SLOW = frozenset(line.strip() for line in (Path(__file__).parent / "slow.txt").read_text().splitlines()
                  if line.strip() and not line.startswith("#"))


def pytest_collection_modifyitems(config, items):
    """Markers by where a test lives: ``notebooks`` (the notebooks and their renderer), ``slow`` (tests/slow.txt);
    ``browser`` is set on the tests themselves."""
    for item in items:
        path = Path(str(item.fspath))
        if path.suffix == ".ipynb" or path.name == "test_notebooks.py":
            item.add_marker(pytest.mark.notebooks)
        if item.nodeid in _SLOW:
            item.add_marker(pytest.mark.slow)


def pytest_unconfigure(config):
    """Say last, in one line, when tests were skipped for want of Chromium (a green run that checked no page is
    not the same as one that did)."""
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if reporter is None:
        return
    skipped = [r for r in reporter.stats.get("skipped", []) if "chromium" in str(r.longrepr).lower()]
    if skipped:
        reporter.write_line(f"kinelab: {len(skipped)} browser test(s) skipped: Debian's chromium is not installed "
                            "here (apt install chromium; .ci/run installs it)", yellow=True)
