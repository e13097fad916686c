"""rd:NAME sources: robot_descriptions' cache only, never a download; a clear error when it is missing."""

import shutil
import subprocess
import sys

import numpy as np
import pytest

import kinelab
from kinelab import DescriptionError
from kinelab.robot import catalog

# a description of example-robot-data in robot_descriptions 2.x and 3.x alike
NAME = "finger_edu_description"


def test_an_unknown_description_is_named_with_close_names():
    with pytest.raises(DescriptionError, match=f"rd:{NAME}"):
        kinelab.load("rd:finger_edu_descripton")


def test_a_description_missing_from_the_cache_says_it_needs_the_network(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOT_DESCRIPTIONS_CACHE", str(tmp_path / "cache"))
    with pytest.raises(DescriptionError, match="not in robot_descriptions' cache .*needs the network"):
        kinelab.load(f"rd:{NAME}")
    assert not (tmp_path / "cache").exists()  # nothing was cloned or created


def _fake_cache(tmp_path, monkeypatch):
    """robot_descriptions' cache holding an example-robot-data clone with only the finger's description, at a
    commit named by ROBOT_DESCRIPTION_COMMIT (so robot_descriptions checks it out without fetching)."""
    work = tmp_path / "work" / "example-robot-data"
    shutil.copytree(catalog.erd_robots_dir() / NAME, work / "robots" / NAME)
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"]
    subprocess.run([*git, "init", "-q"], cwd=work, check=True)
    subprocess.run([*git, "add", "."], cwd=work, check=True)
    subprocess.run([*git, "commit", "-qm", "ur"], cwd=work, check=True)
    sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=work, check=True, capture_output=True,
                         text=True).stdout.strip()
    cache = tmp_path / "cache"
    shutil.move(str(work), str(cache / f"example-robot-data-{sha}" / "example-robot-data"))
    monkeypatch.setenv("ROBOT_DESCRIPTIONS_CACHE", str(cache))
    monkeypatch.setenv("ROBOT_DESCRIPTION_COMMIT", sha)
    for name in [m for m in sys.modules if m.startswith(f"robot_descriptions.{NAME}")]:
        monkeypatch.delitem(sys.modules, name)  # its paths are computed at import
    return cache


@pytest.mark.skipif(shutil.which("git") is None, reason="robot_descriptions' cache is a git clone")
def test_a_cached_description_loads_and_its_meshes_resolve_from_the_cache(tmp_path, monkeypatch):
    cache = _fake_cache(tmp_path, monkeypatch)
    robot = kinelab.load(f"rd:{NAME}", tool="finger_tip_link")
    reference = kinelab.load("finger_edu")
    rng = np.random.default_rng(0)
    for _ in range(20):
        q = reference.random_q(rng)
        assert np.allclose(robot.fk(q).homogeneous, reference.fk(q).homogeneous, atol=1e-12)
    meshes = [g.meshPath for g in robot.visual_model().geometryObjects if g.meshPath]
    assert meshes and all(str(cache) in m for m in meshes)
