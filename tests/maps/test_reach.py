"""Reachability maps: reachable FK points, unreachable far voxels, the same map whatever the chunking or an
interruption, and clear errors for bad input."""

import numpy as np
import pytest
from helpers import interruptible

import kinelab
from kinelab import KinelabError, maps
from kinelab.maps import chunk as reach
from kinelab.maps import grid, store


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


def test_orientations_cover_so3_evenly():
    R = grid.rotations(64)
    assert np.allclose(np.einsum("kij,kil->kjl", R, R), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(R), 1.0)
    # every rotation of a dense random set lies near one of the 64 (no empty region of SO(3))
    rng = np.random.default_rng(0)
    from scipy.spatial.transform import Rotation

    probes = Rotation.random(500, random_state=rng).as_matrix()
    nearest = [min(np.arccos(np.clip((np.trace(P.T @ Q) - 1) / 2, -1, 1)) for Q in R) for P in probes]
    assert max(nearest) < 1.2  # radians; 64 evenly spread rotations leave no hole wider than this


def test_fk_points_are_reachable_and_points_beyond_the_reach_are_not(ur5):
    spec = reach.MapSpec(orientations=24, chunk_voxels=64, restarts=10)
    rng = np.random.default_rng(1)
    points = np.array([ur5.fk(ur5.random_q(rng)).translation for _ in range(40)])
    values = reach.compute_chunk(ur5, spec, points, 0)
    assert (values["reachability"] > 0).mean() >= 0.9  # measured: 40 of 40
    from kinelab.ik.targets import reach_bound

    anchor, radius = reach_bound(ur5)
    far = np.asarray(anchor) + 1.05 * radius * grid.axis_rotations(16)[:, :, 2]
    assert np.all(reach.compute_chunk(ur5, spec, far, 0)["reachability"] == 0)


def test_a_reached_target_is_pinocchio_checked(ur5):
    spec = reach.MapSpec(orientations=8, restarts=10, method="numeric")
    centre = ur5.fk(ur5.random_q(3)).translation[None]
    H = reach.targets_of(centre, grid.rotations(8))
    res = kinelab.solve_batch(ur5, H, seed=spec.seed, max_restarts=spec.restarts)
    for q, T, ok in zip(res.q, H, res.success, strict=True):
        if ok:
            dp, dr = ur5.tool_error(q, kinelab.target_from_xyz_quat_wxyz(T[:3, 3], _quat(T[:3, :3])))
            assert dp <= 1e-6 and dr <= 1e-6 and ur5.within_limits(q)
    assert reach.compute_chunk(ur5, spec, centre, 0)["reachability"][0] == res.success.mean()


def test_an_analytic_arm_s_map_counts_every_branch_and_reaches_all_the_numeric_map_reaches(ur5):
    """The closed-form map: a voxel's branch count is the mean of solve_all's counts over its orientations, each
    branch checked by Pinocchio; wherever the numeric batch reached a pose, the closed form reached it too."""
    rng = np.random.default_rng(2)
    centres = np.vstack([[ur5.fk(ur5.random_q(rng)).translation for _ in range(24)], [[2.0, 0.0, 0.0]]])
    closed = reach.compute_chunk(ur5, reach.MapSpec(orientations=8), centres, 0)
    numeric = reach.compute_chunk(ur5, reach.MapSpec(orientations=8, restarts=20, method="numeric"), centres, 0)
    assert np.isnan(numeric["branches"]).all() and closed["reachability"][-1] == 0 == closed["branches"][-1]
    assert (closed["reachability"] >= numeric["reachability"]).all() and closed["reachability"].mean() > 0.3
    H = reach.targets_of(centres[:6], grid.rotations(8))
    counts = [len(kinelab.solve_all(ur5, kinelab.target_from_xyz_quat_wxyz(T[:3, 3], _quat(T[:3, :3])),
                                    solver="analytic")) for T in H]
    assert np.allclose(closed["branches"][:6], np.reshape(counts, (6, 8)).mean(axis=1))
    assert reach.MapSpec().closed_form(ur5) and not reach.MapSpec().closed_form(kinelab.load("panda"))
    with pytest.raises(KinelabError, match="method is one of auto, numeric"):
        reach.MapSpec(method="fast").check()


def _quat(R):
    import pinocchio as pin

    q = pin.Quaternion(R)
    return [q.w, q.x, q.y, q.z]


def test_an_interrupted_map_resumes_to_the_same_arrays_as_one_run(ur5, tmp_path):
    pytest.importorskip("zarr")
    spec = reach.MapSpec(voxel=0.25, orientations=4, chunk_voxels=50, restarts=5)
    whole = maps.reachability(ur5, spec)
    centres = grid.voxel_centres(ur5, spec.voxel)
    partial = store.open_map(tmp_path / "m.zarr", ur5, spec, centres)
    for c in range(2):  # the run stopped after two chunks
        partial.write(c, reach.compute_chunk(ur5, spec, centres, c))
    resumed = maps.reachability(ur5, spec, out=str(tmp_path / "m.zarr"))
    assert all(resumed.done[:])
    for name in ("reachability", "manipulability", "sigma_ratio"):
        np.testing.assert_array_equal(resumed.array(name), whole.array(name))
    np.testing.assert_array_equal(maps.load(tmp_path / "m.zarr").array("reachability"), whole.array("reachability"))


def test_a_damaged_store_is_refused_on_load_and_recomputed_on_resume(ur5, tmp_path):
    """kinelab 0.1 resumed a map whose chunk file was deleted and reported NaN voxels with exit 0."""
    pytest.importorskip("zarr")
    spec = reach.MapSpec(voxel=0.25, orientations=4, chunk_voxels=50, restarts=5)
    out = tmp_path / "m.zarr"
    whole = maps.reachability(ur5, spec, out=str(out))
    (out / "reachability" / "1").unlink()  # a chunk file lost (a crash, a sync tool, a hand)
    with pytest.raises(KinelabError, match=r"1 chunk\(s\) no longer match their checksums \(first: 1\)"):
        maps.load(out)
    with pytest.warns(UserWarning, match="computed again"):
        again = maps.reachability(ur5, spec, out=str(out))
    np.testing.assert_array_equal(again.array("reachability"), whole.array("reachability"))
    assert not np.isnan(maps.load(out).array("reachability")).any()


def test_a_chunk_of_garbage_or_an_edited_shape_is_refused_on_open_and_garbage_recomputed_on_resume(ur5, tmp_path):
    """#31.5: a chunk of garbage gave a raw blosc RuntimeError; an edited array shape crashed the resume and left a
    store that loaded as a 5-voxel map."""
    import json

    pytest.importorskip("zarr")
    spec = reach.MapSpec(voxel=0.25, orientations=4, chunk_voxels=50, restarts=5)
    out = tmp_path / "m.zarr"
    whole = maps.reachability(ur5, spec, out=str(out))
    (out / "reachability" / "1").write_bytes(bytes(range(256)) * 4)  # not a blosc chunk
    with pytest.raises(KinelabError, match=r"1 chunk\(s\) no longer match their checksums \(first: 1\)"):
        maps.load(out)
    with pytest.warns(UserWarning, match="computed again"):
        again = maps.reachability(ur5, spec, out=str(out))
    np.testing.assert_array_equal(again.array("reachability"), whole.array("reachability"))
    (out / "done" / "0").write_bytes(b"garbage")
    with pytest.raises(KinelabError, match="the done array cannot be read"):
        maps.load(out)
    maps.reachability(ur5, spec, out=str(tmp_path / "n.zarr"))
    meta = json.loads((tmp_path / "n.zarr" / "reachability" / ".zarray").read_text())
    meta["shape"] = [5]
    (tmp_path / "n.zarr" / "reachability" / ".zarray").write_text(json.dumps(meta))
    for attempt in (lambda: maps.load(tmp_path / "n.zarr"),
                    lambda: maps.reachability(ur5, spec, out=str(tmp_path / "n.zarr"))):
        with pytest.raises(KinelabError, match=r"array 'reachability' has shape \(5,\)"):
            attempt()
    zarr = pytest.importorskip("zarr")  # the centres moved: their checksum says so
    maps.reachability(ur5, spec, out=str(tmp_path / "c.zarr"))
    group = zarr.open_group(str(tmp_path / "c.zarr"), mode="r+")
    group["centres"][0] = [9.0, 9.0, 9.0]
    with pytest.raises(KinelabError, match="voxel centres no longer match"):
        maps.load(tmp_path / "c.zarr")


def test_bad_maps_are_refused_with_the_reason(ur5, tmp_path, monkeypatch):
    pytest.importorskip("zarr")
    with pytest.raises(KinelabError, match="voxel side must be a positive"):
        maps.reachability(ur5, voxel=0.0)
    with pytest.raises(KinelabError, match="targets .* without force=True"):
        maps.reachability(ur5, voxel=0.01, orientations=50)
    with pytest.raises(KinelabError, match="task 'pose' or 'axis'"):
        maps.reachability(ur5, task="position")
    spec = reach.MapSpec(voxel=0.3, orientations=2, restarts=2)
    maps.reachability(ur5, spec, out=str(tmp_path / "a.zarr"))
    with pytest.raises(KinelabError, match="holds another map \\(robot"):
        maps.reachability(kinelab.load("panda"), spec, out=str(tmp_path / "a.zarr"))
    with pytest.raises(KinelabError, match="holds another map \\(spec"):
        maps.reachability(ur5, reach.MapSpec(voxel=0.3, orientations=3, restarts=2), out=str(tmp_path / "a.zarr"))
    monkeypatch.setattr(kinelab, "__version__", "0.0.0-other")
    with pytest.raises(KinelabError, match="written by kinelab"):
        maps.load(tmp_path / "a.zarr")
    with pytest.raises(KinelabError, match="not a kinelab reachability map"):
        maps.load(tmp_path / "nothing-here")


def test_kinelab_map_reach_writes_a_map_and_a_second_run_resumes_it_unchanged(tmp_path, capsys):
    pytest.importorskip("zarr")
    import json

    from kinelab import cli

    argv = ["map", "reach", "ur5", "--voxel", "0.3", "--orientations", "3", "--restarts", "3",
            "--out", str(tmp_path / "m.zarr"), "--json"]
    assert cli.main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    before = maps.load(tmp_path / "m.zarr").array("reachability")
    assert cli.main(argv) == 0  # every chunk already done: nothing recomputed, the same map
    again = json.loads(capsys.readouterr().out)
    np.testing.assert_array_equal(maps.load(tmp_path / "m.zarr").array("reachability"), before)
    assert again["mean_reachability"] == first["mean_reachability"] and first["voxels"] == len(before)
    assert cli.main(["map", "reach", "ur5", "--voxel", "0"]) == 2
    assert "positive length" in capsys.readouterr().err


def test_the_map_views_draw_the_reached_voxels(ur5):
    import browser

    from kinelab.view import maps as view_maps

    rmap = maps.reachability(ur5, reach.MapSpec(voxel=0.3, orientations=3, restarts=3))
    scene = view_maps.reachability_cloud(ur5, rmap)
    html = scene.static_html()
    scene.close()
    assert "/meshcat/reachability" in browser.scene_paths(html)
    assert "reached voxels of 0.3 m" in html
    ax = view_maps.reachability_slice(rmap)
    layer = ax.collections[0].get_offsets()
    assert len(layer) > 10 and ax.get_title().startswith("reachability index at z = ")
    np.testing.assert_array_equal(view_maps.colours(np.array([0.0, 1.0]))[:, 0], [1.0, 0.0, 0.0])


def test_an_interrupted_cli_run_resumes_to_the_identical_map(ur5, tmp_path):
    """kinelab map reach stopped by Ctrl-C after a few chunks, then run again: the same map as one run."""
    pytest.importorskip("zarr")
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "m.zarr"
    argv = [sys.executable, "-m", "kinelab.cli", "map", "reach", "ur5", "--voxel", "0.15", "--orientations", "4",
            "--restarts", "3", "--chunk", "16", "--out", str(out), "--json"]
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = interruptible(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.time() + 600  # a wait for three chunks, generous for a loaded machine: not a speed
    done = 0
    while time.time() < deadline and proc.poll() is None:
        time.sleep(0.01)  # the signal follows the third chunk within ~10 ms: the map's other chunks take far longer
        try:
            done = int(np.sum(maps.load(out).done[:]))
        except KinelabError:
            continue  # not created yet
        if done >= 3:
            proc.send_signal(signal.SIGINT)
            break
    _, err = proc.communicate(timeout=60)
    interrupted = maps.load(out)
    kept = int(np.sum(interrupted.done[:]))
    assert proc.returncode == 130 and 3 <= kept < interrupted.chunks
    # one line: what was kept, and the command that resumes (kinelab 0.2 said only "kinelab: interrupted")
    assert err.strip().splitlines()[-1] == (f"kinelab: interrupted; {kept} of {interrupted.chunks} chunks are saved "
                                            f"in {out}; the same command resumes: kinelab {' '.join(argv[3:])}")
    rerun = subprocess.run(argv[:-1], capture_output=True, text=True, env=env, timeout=600)  # the bar shows
    assert rerun.returncode == 0 and f"resumed: {kept} chunks already in {out}" in rerun.stderr
    whole = maps.reachability(ur5, reach.MapSpec(voxel=0.15, orientations=4, restarts=3, chunk_voxels=16))
    for name in ("reachability", "manipulability", "sigma_ratio"):
        np.testing.assert_array_equal(maps.load(out).array(name), whole.array(name))


def test_progress_shows_by_default_where_someone_watches_and_not_in_a_pipe(ur5, capsys, monkeypatch):
    """kinelab 0.2's maps.reachability printed nothing for 82 s by default (progress=False)."""
    import sys

    spec = reach.MapSpec(voxel=0.3, orientations=1, restarts=0, chunk_voxels=8)
    maps.reachability(ur5, spec)
    assert capsys.readouterr().err == ""  # a pipe or a log: quiet
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    maps.reachability(ur5, spec)
    err = capsys.readouterr().err
    assert "map: 100%" in err and "chunk" in err


def test_a_map_with_a_table_differs_from_one_without_exactly_where_the_exact_check_says(ur5):
    """The same voxels with and without the floor and a table: a pose is reached with them when one of its
    branches (solve_all, every branch) is clear by Pinocchio's exact test on every pair, checked here."""
    from kinelab.collision import Collisions, Environment, Obstacle, collision_model

    env = Environment((Obstacle("plane", name="floor"),
                       Obstacle("box", size=(0.6, 0.8, 0.05), xyz=(0.5, 0.0, 0.2), name="table")))
    rng = np.random.default_rng(5)
    centres = np.array([ur5.fk(ur5.random_q(rng)).translation for _ in range(16)])
    spec = reach.MapSpec(orientations=8, collisions=Collisions(environment=env))
    free = reach.compute_chunk(ur5, reach.MapSpec(orientations=8), centres, 0)
    walled = reach.compute_chunk(ur5, spec, centres, 0)
    exact = collision_model(ur5, Collisions(environment=env))
    expected = np.zeros((16, 8))
    for k, T in enumerate(reach.targets_of(centres, grid.rotations(8))):
        target = kinelab.target_from_xyz_quat_wxyz(T[:3, 3], _quat(T[:3, :3]))
        expected.flat[k] = any(exact.contact(s.q, first_test=False) is None
                               for s in kinelab.solve_all(ur5, target, solver="analytic"))
    assert np.array_equal(walled["reachability"], expected.mean(axis=1))
    assert (walled["reachability"] <= free["reachability"]).all()
    assert (walled["reachability"] < free["reachability"]).any()  # the table and floor take poses away
    assert spec.to_dict()["collisions"]["environment"]["obstacles"][1]["name"] == "table"


def _full_disk(*args, **kwargs):
    import errno

    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize("where", ["creating the store", "writing a chunk"])
def test_a_full_disk_gives_one_line_and_leaves_no_store_that_blocks_the_rerun(tmp_path, capsys, monkeypatch, where):
    """#67 item 7: `map reach --out` on a full disk printed a traceback and left a partial store that blocked the
    rerun. The disk's refusal is simulated (ENOSPC from the store); the command prints one line and exits 2, and the
    same command once there is room writes the whole map, equal to a map made in one go."""
    zarr = pytest.importorskip("zarr")
    from kinelab import cli

    out = tmp_path / "m.zarr"
    argv = ["map", "reach", "ur5", "--voxel", "0.4", "--orientations", "2", "--restarts", "2", "--chunk", "8",
            "--out", str(out), "--json"]
    with monkeypatch.context() as m:
        if where == "creating the store":
            m.setattr(zarr.hierarchy.Group, "create_dataset", _full_disk)
        else:
            real = zarr.core.Array.__setitem__

            def second_chunk_fails(self, key, value):  # the disk fills up as the second chunk's values go in
                if self.name.endswith("manipulability") and isinstance(key, slice) and key.start == 8:
                    _full_disk()
                real(self, key, value)

            m.setattr(zarr.core.Array, "__setitem__", second_chunk_fails)
        assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinelab: error: cannot write") and "No space left" in err[0]
    if where == "creating the store":
        assert not out.exists()
    else:
        assert "1 chunk(s) done are kept" in err[0] and maps.load(out).finished() == (1, maps.load(out).chunks)
    assert cli.main(argv) == 0
    capsys.readouterr()
    whole = maps.reachability(kinelab.load("ur5"), reach.MapSpec(voxel=0.4, orientations=2, restarts=2,
                                                                 chunk_voxels=8))
    np.testing.assert_array_equal(maps.load(out).array("reachability"), whole.array("reachability"))


def test_map_view_says_an_interrupted_map_is_unfinished(ur5, tmp_path, capsys):
    """#67 item 7: `map view` drew an interrupted map without saying so."""
    pytest.importorskip("zarr")
    from kinelab import cli

    spec = reach.MapSpec(voxel=0.4, orientations=2, chunk_voxels=8, restarts=2)
    centres = grid.voxel_centres(ur5, spec.voxel)
    partial = store.open_map(tmp_path / "m.zarr", ur5, spec, centres)
    partial.write(0, reach.compute_chunk(ur5, spec, centres, 0))
    page = tmp_path / "map.html"
    assert cli.main(["map", "view", str(tmp_path / "m.zarr"), "--html", str(page)]) == 0
    said = capsys.readouterr().out
    assert f"unfinished: 1 of {partial.chunks} chunks" in said
    assert f"unfinished: 1 of {partial.chunks} chunks" in page.read_text()
