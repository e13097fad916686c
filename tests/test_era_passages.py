"""Seed 000: the ERA elbow passage with and without the paper's bypass (FRDM tracking)."""

import numpy as np
import pytest

from kinelab.studies import era_passages as ep

STEP_BOUND = 0.25  # [rad] largest joint change between samples allowed with the bypass


@pytest.fixture(scope="module")
def elbow():
    passage = ep.elbow_passage()
    return passage, ep.run(passage)


def test_path_goes_exactly_through_the_aligned_elbow(elbow):
    passage, run = elbow
    top = int(np.argmax([t.translation[2] for t in passage.targets]))
    assert passage.unreachable[top] and passage.unreachable.sum() <= 2
    np.testing.assert_allclose(run.with_bypass.q[top, 2:5], 0.0, atol=1e-9)  # links in line: q3 = q4 = q5 = 0


def test_with_the_bypass_every_reachable_sample_is_reached_smoothly(elbow):
    passage, run = elbow
    res, reachable = run.with_bypass, ~passage.unreachable
    assert res.reached[reachable].all()
    assert res.position_error[reachable].max() <= 1e-6 and res.rotation_error[reachable].max() <= 1e-6
    assert res.max_joint_step < STEP_BOUND
    assert ep.quadrant_violations(res, passage) == 0
    assert any(b["bypass"] == "kicks" for b in res.bypasses)
    np.testing.assert_allclose(res.q[-1], passage.q0, atol=1e-5)  # back where it started, same fold


def test_without_bypass_the_monitor_fires_and_the_arm_fails_the_paper_way(elbow):
    passage, run = elbow
    res, reachable = run.without, ~passage.unreachable
    singular = [e for e in res.events if e.get("diagnosis") == "singular" and e["trigger"] == "step"]
    assert len(singular) >= 10  # Σ|Δq| = 0 sample after sample while the arm is straight
    assert res.reached[reachable].sum() < 0.7 * reachable.sum()
    assert res.position_error[reachable].max() > 0.5  # the tool left behind by the target
    assert res.max_joint_step > 4 * STEP_BOUND  # and the jump when it finally folds
