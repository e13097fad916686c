"""One million Panda targets on a two-worker local Dask cluster, the run killed and resumed, the rows held against
the in-process batch (#42; figures in docs/bench/throughput-2026-12-04.md).

    python tools/million_on_cluster.py [STORE]

The targets are the tool poses of 1,000,000 configurations drawn within the limits (seed 2026). A child process
solves them with ``kinelab.solve_batch_on_cluster`` (seed 7, 10,000 targets a task) and is killed with its
workers after KILL_AFTER seconds; a second child resumes the same store; this process then solves the same
targets in one ``kinelab.solve_batch`` call and compares every row.
"""

import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np

N = 1_000_000
KILL_AFTER = 25.0  # [s]


def targets():
    import kinelab

    panda = kinelab.load("panda")
    return panda, panda.fk_batch(panda.random_qs(N, np.random.default_rng(2026)))


def child(store):
    from kinelab.maps.batch import BatchSpec, solve_batch_on_cluster

    panda, T = targets()
    run = solve_batch_on_cluster(panda, T, store, BatchSpec(seed=7), workers=2, progress=False)
    print(f"computed {len(run.computed)} chunks, {run.resumed} already done, {run.result.wall_time:.1f} s", flush=True)


def main(store):
    import zarr

    import kinelab

    shutil.rmtree(store, ignore_errors=True)
    first = subprocess.Popen([sys.executable, __file__, store, "child"], start_new_session=True)
    time.sleep(KILL_AFTER)
    os.killpg(first.pid, signal.SIGKILL)  # the client and its workers, as a power cut would
    first.wait()
    done = np.asarray(zarr.open_group(store, mode="r")["done"][:])
    print(f"killed after {KILL_AFTER:.0f} s: {int(done.sum())} of {len(done)} chunks written", flush=True)
    t0 = time.perf_counter()
    resumed = subprocess.run([sys.executable, __file__, store, "child"], capture_output=True, text=True, check=True)
    print(f"resumed: {resumed.stdout.strip().splitlines()[-1]} ({time.perf_counter() - t0:.1f} s with start-up)")
    panda, T = targets()
    t0 = time.perf_counter()
    here = kinelab.solve_batch(panda, T, seed=7)
    seconds = time.perf_counter() - t0
    print(f"in process: {seconds:.1f} s, {N / seconds:,.0f} targets/s, {100 * here.success.mean():.4f} % solved")
    group = zarr.open_group(store, mode="r")
    same = all(np.array_equal(np.asarray(group[k][:]), getattr(here, k))
               for k in ("q", "success", "status_code", "position_error", "rotation_error", "iterations", "restarts"))
    print(f"every row identical to the in-process batch: {same}")


if __name__ == "__main__":
    where = sys.argv[1] if len(sys.argv) > 1 else "million.zarr"
    child(where) if sys.argv[2:] == ["child"] else main(where)
