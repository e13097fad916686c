"""``kinelab map view``: a stored reachability map as a page (its voxels in 3-D, three slices)."""

import base64
import io
import os
import re

import numpy as np
import pytest
from browser import find_chromium, scene_paths, screenshot
from PIL import Image

import kinelab
from kinelab import cli, maps
from kinelab.maps import chunk as reach


def run(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    out = tmp_path_factory.mktemp("map") / "ur5.zarr"
    maps.reachability(kinelab.load("ur5"), reach.MapSpec(voxel=0.25, orientations=4), out=str(out))
    return out


def test_a_stored_map_is_a_page_with_its_reached_voxels_and_three_slices(capsys, stored, tmp_path):
    page = tmp_path / "map.html"
    code, out, _ = run(capsys, "map", "view", str(stored), "--html", str(page))
    rmap = maps.load(stored)
    reached = int((rmap.array("reachability") > 0).sum())
    assert code == 0 and out.startswith(f"wrote {page}: ur5, {reached} reached voxels of {rmap.meta['voxels']}")
    html = page.read_text()
    assert "/meshcat/reachability" in scene_paths(html) and "ur5: reachability map" in html
    assert f"the {reached} reached voxels of 0.25 m" in html
    slices = [Image.open(io.BytesIO(base64.b64decode(b))) for b in
              re.findall(r'alt="reachability slice across [xyz]"[^>]*base64,([A-Za-z0-9+/=]+)', html)]
    assert len(slices) == 3 and all(im.size[0] > 200 for im in slices)


def test_map_view_refuses_what_is_not_a_map_and_a_robot_that_is_not_the_map_s(capsys, stored, tmp_path):
    code, out, err = run(capsys, "map", "view", str(tmp_path), "--html", str(tmp_path / "p.html"))
    assert code == 2 and "is not a kinelab reachability map" in err and len(err.strip().splitlines()) == 1
    code, out, err = run(capsys, "map", "view", str(stored), "--html", str(tmp_path / "p.html"), "--robot", "ur10")
    assert code == 2 and "not the one the map" in err
    code, out, err = run(capsys, "map", "view", str(stored), "--html", str(tmp_path / "no" / "dir" / "p.html"))
    assert code == 2 and "cannot write the page" in err


@pytest.mark.browser
@pytest.mark.skipif(find_chromium() is None and not os.environ.get("CI"),
                    reason="no chromium on PATH (Debian: apt-get install chromium)")
def test_the_map_page_shows_voxels_and_slices_in_the_browser(capsys, stored, tmp_path):
    page = tmp_path / "map.html"
    run(capsys, "map", "view", str(stored), "--html", str(page))
    rgb = np.asarray(Image.open(screenshot(page, tmp_path / "map.png", size=(1300, 950))).convert("RGB"), dtype=int)
    green = (rgb[..., 1] > 150) & (rgb[..., 0] < 120) & (rgb[..., 2] < 120)  # reached voxels (and slice cells)
    white = (rgb > 240).all(axis=2)  # the slices' white plot area on the right
    assert green[:, :900].sum() > 500 and white[:, 980:].mean() > 0.2
