"""The judging of ``kinelab bench --paths`` and the tables of ``--paths``, ``--standing-solve`` and ``--first-call``
(#71 goals 2, 3 and 5): what counts as a jump, a drift and a met path, checked on results built here; the timed
runs themselves are the bench's."""

from types import SimpleNamespace

import numpy as np

import kinelab
from kinelab.report.bench import first_call, paths, standing_solve
from kinelab.report.bench.protocol import cosine_path, joint_line


def _panda_path():
    panda = kinelab.load("panda", prepare=False)
    return panda, joint_line(panda, np.random.default_rng(2), samples=50)


def test_a_path_followed_exactly_is_met_without_a_jump_or_a_drift():
    panda, path = _panda_path()
    met, step, closer = paths.verdict(panda, path, SimpleNamespace(q=path.copy(), success=np.ones(len(path), bool)))
    assert met and step <= 1.0 + 1e-12 and closer <= 1e-12


def test_a_jump_a_drift_and_a_missed_sample_are_each_seen():
    panda, path = _panda_path()
    own = np.abs(np.diff(path, axis=0)).max()
    jumped = path.copy()
    jumped[20:, 0] += 10 * own  # one sample turns joint 1 by ten of the path's largest steps, and stays there
    _, step, _ = paths.verdict(panda, path, SimpleNamespace(q=jumped, success=np.ones(len(path), bool)))
    assert 9.0 <= step <= 11.0 + 1e-9
    drifted = path.copy()
    drifted[:, 3] = panda.lower[3] + 0.01  # joint 4 a hundredth of a radian from its stop all along
    _, _, closer = paths.verdict(panda, path, SimpleNamespace(q=drifted, success=np.ones(len(path), bool)))
    margin = np.minimum(path - panda.lower, panda.upper - path).min(axis=1)
    assert abs(closer - np.max(margin - 0.01)) <= 1e-12
    missed = np.ones(len(path), bool)
    missed[7] = False
    met, _, _ = paths.verdict(panda, path, SimpleNamespace(q=path, success=missed))
    assert not met


def test_the_paths_are_inside_the_limits_and_as_smooth_as_said():
    panda = kinelab.load("panda", prepare=False)
    line = joint_line(panda, np.random.default_rng(0), samples=400, step=0.025)
    blend = cosine_path(panda, np.random.default_rng(1), samples=400)
    for path in (line, blend):
        assert np.all(path >= panda.lower) and np.all(path <= panda.upper)
    assert np.abs(np.diff(line, axis=0)).max() <= 0.025 + 1e-12
    steps = np.abs(np.diff(line, axis=0)).max(axis=1)
    assert np.ptp(steps) <= 1e-12  # a line: every step alike


def test_the_tables_say_each_goal():
    rows = [{"robot": "panda", "follower": "default", "paths": 50, "good": 41, "met": 49, "jumps": 1, "drifts": 9,
             "worst_step": 128.4, "worst_closer": 0.88, "us_per_sample": 7.0}]
    trust = {"default": {"met": 1999, "samples": 2000, "step": 1037.7, "closer": 1.04}}
    table = paths.markdown({"paths_per_arm": 50, "samples": 400, "rows": rows, "trust": trust})
    assert "| panda | default | 41/50 | 49 | 1 | 9 | 128.4× | 0.88 rad | 7 |" in table
    assert "1999/2000 samples met, largest step 1037.7× the path's, 1.04 rad nearer" in table
    standing = standing_solve.markdown({"budget_s": 1.0, "rows": [
        {"robot": "talos", "targets": 200, "met_pct": 97.5, "without_restart_pct": 45.0, "median_ms": 82.0,
         "p95_ms": 900.0, "misses": {"stalled": 5}}]})
    assert "| talos | 200 | 97.5 % | 45.0 % | 82 ms | 900 ms | stalled 5 |" in standing and "≥ 99.9 %" in standing
    first = first_call.markdown({"rounds": 5, "later_calls": 20, "rows": [
        {"robot": "ur5", "entry": "solve", "prepare": True, "first_ms": 0.2, "first_low": 0.1, "first_high": 0.3,
         "later_ms": 0.02, "load_ms": 232.0, "met": 5, "rounds": 5}]})
    assert "| ur5 | solve | kinelab.load | 232 ms | 0.2 ms (0.1–0.3) | 0.02 ms | 5/5 rounds |" in first


def test_a_first_call_row_counts_the_rounds_that_meet_the_goal():
    runs = [{"load": 0.2, "first": 0.004, "later": [0.001] * 20},  # 4 ms ≤ 2 × 1 + 5 ms: met
            {"load": 0.2, "first": 0.008, "later": [0.001] * 20}]  # 8 ms > 7 ms: missed
    row = first_call._row(("panda", "solve", True), runs)
    assert row["met"] == 1 and row["rounds"] == 2
    assert abs(row["first_ms"] - 6.0) < 1e-9 and abs(row["later_ms"] - 1.0) < 1e-9
