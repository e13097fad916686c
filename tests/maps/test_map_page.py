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


def _edited(stored, tmp_path, change_attrs=None, change_arrays=None):
    """A copy of the stored map with its metadata (and optionally its arrays' declared shapes) edited."""
    import json
    import shutil

    copy = tmp_path / "edited.zarr"
    shutil.copytree(stored, copy)
    attrs = json.loads((copy / ".zattrs").read_text())
    if change_attrs:
        change_attrs(attrs)
    (copy / ".zattrs").write_text(json.dumps(attrs))
    if change_arrays:
        change_arrays(copy)
    return copy


@pytest.mark.parametrize("change, needle", [
    (lambda a: a.pop("source_sha256"), "source_sha256 is None"),
    (lambda a: a["spec"].update(voxel="0.25"), "spec.voxel is '0.25'"),
    (lambda a: a["spec"].pop("orientations"), "spec.orientations is None"),
    (lambda a: a.update(spec=[1, 2]), "'spec' is [1, 2]"),
])
def test_a_store_with_edited_metadata_is_refused_by_name(capsys, stored, tmp_path, change, needle):
    """#39 item 8: these were KeyError and TypeError tracebacks."""
    edited = _edited(stored, tmp_path, change)
    with pytest.raises(kinelab.KinelabError, match=re.escape(needle)):
        maps.load(edited)
    code, out, err = run(capsys, "map", "view", str(edited), "--html", str(tmp_path / "p.html"))
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and needle in err


def test_a_store_declaring_more_voxels_than_it_holds_is_refused_at_once(stored, tmp_path):
    """#39 item 8: a 2 kB store declaring 2e8 voxels ran for more than 90 s (its centres' fill values read and
    hashed): a map writes its centres whole, so missing centre chunks are an altered file."""
    import json

    from helpers import no_hang

    voxels = 200_000_000

    def grow(copy):
        for name in ("centres", "reachability", "manipulability", "sigma_ratio", "branches", "done", "checksums"):
            meta = json.loads((copy / name / ".zarray").read_text())
            chunks = -(-voxels // 64)
            meta["shape"] = {"centres": [voxels, 3], "done": [chunks], "checksums": [chunks, 32]}.get(name, [voxels])
            (copy / name / ".zarray").write_text(json.dumps(meta))
            for f in (copy / name).iterdir():
                if f.name != ".zarray":
                    f.unlink()

    edited = _edited(stored, tmp_path, lambda a: a.update(voxels=voxels), grow)
    with no_hang(30), pytest.raises(kinelab.KinelabError, match="centres were not all written"):
        maps.load(edited)


def test_the_page_never_overwrites_the_store_and_the_store_names_no_file(capsys, stored, tmp_path):
    """#39 item 8: --html STORE/.zattrs overwrote the store and exited 0; the store's robot field could name any
    file, which was then loaded."""
    before = (stored / ".zattrs").read_bytes()
    code, out, err = run(capsys, "map", "view", str(stored), "--html", str(stored / ".zattrs"))
    assert code == 2 and "inside the map" in err and (stored / ".zattrs").read_bytes() == before
    elsewhere = _edited(stored, tmp_path, lambda a: a.update(robot=str(tmp_path / "robot.urdf")))
    code, out, err = run(capsys, "map", "view", str(elsewhere), "--html", str(tmp_path / "p.html"))
    assert code == 2 and "not a registered robot" in err and "--robot" in err
    maps.load(stored)  # still a whole map


def test_a_map_that_cannot_be_written_is_one_line(capsys):
    """#39 item 8: map reach --out /proc/x was zarr's KeyError traceback."""
    pytest.importorskip("zarr")
    code, out, err = run(capsys, "map", "reach", "ur5", "--voxel", "0.3", "--orientations", "2", "--out", "/proc/x")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "cannot write the map to /proc/x" in err
