"""solve_batch over a local two-worker Dask cluster (kinelab.maps.batch): the rows are the in-process batch's,
a stopped run resumes computing only what it had not written, and a store of another run is refused."""

import numpy as np
import pytest

import kinelab
from kinelab import KinelabError, OptionError

pytest.importorskip("dask.distributed")
from kinelab.maps import cluster  # noqa: E402
from kinelab.maps.batch import BatchSpec, solve_batch_on_cluster  # noqa: E402

FIELDS = ("q", "success", "status_code", "position_error", "rotation_error", "iterations", "restarts")


@pytest.fixture(scope="module")
def client():
    made = cluster.client_for(None, 2)
    yield made
    made.close()
    made.cluster.close()


def test_two_workers_give_the_in_process_rows_and_a_stopped_run_resumes_what_is_left(client, tmp_path):
    panda = kinelab.load("panda")
    targets = panda.fk_batch(panda.random_qs(1200, np.random.default_rng(3)))
    targets[5, :3, 3] = [3.0, 0.0, 0.0]  # beyond reach: a failed row is a row too
    spec = BatchSpec(seed=11, chunk=250)
    run = solve_batch_on_cluster(panda, targets, tmp_path / "b.zarr", spec, client=client, progress=False)
    here = kinelab.solve_batch(panda, targets, seed=11)
    assert run.computed == (0, 1, 2, 3, 4) and run.resumed == 0
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(run.result, name), getattr(here, name))
    assert run.result.success.sum() == 1199 and not run.result.success[5]

    import zarr  # a run stopped after chunks 0, 2 and 4: the others' flags unset and rows unwritten

    group = zarr.open_group(str(tmp_path / "b.zarr"), mode="r+")
    for c in (1, 3):
        group["done"][c] = False
        group["q"][c * 250:(c + 1) * 250] = np.nan
    again = solve_batch_on_cluster(panda, targets, tmp_path / "b.zarr", spec, client=client, progress=False)
    assert again.computed == (1, 3) and again.resumed == 3
    np.testing.assert_array_equal(again.result.q, here.q)
    done = solve_batch_on_cluster(panda, targets, tmp_path / "b.zarr", spec, progress=False)  # no client needed
    assert done.computed == () and done.resumed == 5


def test_a_store_of_another_run_or_bad_settings_are_refused_by_name(client, tmp_path):
    ur5 = kinelab.load("ur5")
    targets = ur5.fk_batch(ur5.random_qs(40, np.random.default_rng(1)))
    solve_batch_on_cluster(ur5, targets, tmp_path / "s.zarr", BatchSpec(chunk=20), client=client, progress=False)
    with pytest.raises(KinelabError, match="holds another batch .seed: 0, this one 1"):
        solve_batch_on_cluster(ur5, targets, tmp_path / "s.zarr", BatchSpec(seed=1, chunk=20), client=client)
    with pytest.raises(KinelabError, match="targets_sha256"):
        solve_batch_on_cluster(ur5, targets[::-1], tmp_path / "s.zarr", BatchSpec(chunk=20), client=client)
    (tmp_path / "plain").write_text("not a store")
    with pytest.raises(KinelabError, match="not a kinelab batch store"):
        solve_batch_on_cluster(ur5, targets, tmp_path / "plain", client=client)
    for bad in ({"chunk": 0}, {"seed": -1}, {"tol_pos": 0.0}, {"max_restarts": 1.5}):
        with pytest.raises(OptionError):
            BatchSpec(**bad)
