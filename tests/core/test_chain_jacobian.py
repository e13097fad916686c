"""The compiled chain's tool Jacobian, path rotation steps and null-space drift (the self-motion check of a tracked
path, #58 goal 3) against Pinocchio's own calls and a NumPy reference, at seeded configurations."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import cosine_path, revolute, write_urdf

import kinelab
from kinelab.core._chain import rotation_steps, running_events
from kinelab.ik.frdm import tracking
from kinelab.robot import certificate

ARMS = ["ur5", "panda", "kinova", "youbot", "stanford", "era", "so101", "crx10ia"]


@pytest.mark.parametrize("name", ARMS)
def test_the_compiled_jacobian_is_pinocchio_s_at_random_configurations_and_at_the_limits(name):
    robot = kinelab.load(name)
    Q = robot.random_qs(100, np.random.default_rng(12))
    lower, upper = robot.sample_bounds
    Q[: robot.n] = np.where(np.eye(robot.n, dtype=bool), lower, Q[: robot.n])
    Q[robot.n: 2 * robot.n] = np.where(np.eye(robot.n, dtype=bool), upper, Q[robot.n: 2 * robot.n])
    J = robot.jacobian_batch(Q, frame="local_world_aligned")
    assert J.shape == (100, 6, robot.n)
    model, data, fid = robot.model, robot.model.createData(), robot.tool_frame_id
    for q, Jq in zip(Q, J, strict=True):
        expected = pin.computeFrameJacobian(model, data, robot.to_pin_q(q), fid, pin.LOCAL_WORLD_ALIGNED)
        assert np.abs(Jq - expected.reshape(6, robot.n)).max() <= 1e-12


def test_a_chain_pinocchio_judges_gets_pinocchio_s_jacobian_to_the_bit(tmp_path):
    links = "".join(f'<link name="{n}"/>' for n in ("base", "l1", "l2", "tool"))
    arm = kinelab.load(write_urdf(tmp_path, links + revolute("j1", "base", "l1") + revolute(
        "j2", "l1", "l2", axis="0 1 0", extra='<mimic joint="j1" multiplier="0.5"/>') + revolute(
        "j3", "l2", "tool", axis="1 0 0")))
    assert not arm.fk_certificate.certified
    Q = arm.random_qs(5, 2)
    np.testing.assert_array_equal(arm.jacobian_batch(Q, frame="local_world_aligned"),
                                  np.stack([arm.jacobian_local_world_aligned(q) for q in Q]))


def test_rotation_steps_are_pinocchio_s_log3_in_the_base_frame():
    rng = np.random.default_rng(3)
    R = np.stack([pin.exp3(v) for v in rng.normal(scale=1.2, size=(60, 3))])
    R[10] = R[9] @ pin.exp3(np.array([0.0, 0.0, np.pi - 1e-7]))  # near a half turn
    R[20] = R[19] @ pin.exp3(np.array([1e-9, 0.0, 0.0]))  # nearly none
    out = np.full((60, 3), np.nan)
    rotation_steps(R, out)
    assert np.all(out[0] == 0.0)
    for k in range(1, 60):
        expected = R[k - 1] @ pin.log3(R[k - 1].T @ R[k])
        assert np.abs(out[k] - expected).max() <= 1e-9, k


def reference_drift(robot, prev, Q, dx, rows):
    """The definition, one sample at a time with Pinocchio's Jacobian and NumPy's pseudo-inverse."""
    drift, own = np.zeros(Q.shape), np.zeros(Q.shape[0])
    for k in range(Q.shape[0]):
        if not np.isfinite(prev[k]).all():
            continue
        J = robot.jacobian_local_world_aligned(prev[k])[rows]
        pinv = J.T @ np.linalg.inv(J @ J.T + 1e-12 * np.eye(len(rows)))
        dq = np.nan_to_num(Q[k] - prev[k])
        own[k] = np.abs(pinv @ dx[k, rows]).max()
        drift[k] = dq - pinv @ (J @ dq)
    return drift, own


@pytest.mark.parametrize("name, rows", [("panda", [0, 1, 2, 3, 4, 5]), ("panda", [0, 1, 2]),
                                        ("era", [0, 1, 2, 3, 4, 5]), ("kinova", [0, 1, 2, 4, 5])])
def test_the_compiled_null_space_drift_is_the_definition(name, rows):
    robot = kinelab.load(name)
    rng = np.random.default_rng(7)
    path = cosine_path(robot, rng, samples=80)
    Q = path + rng.normal(scale=0.01, size=path.shape)
    Q[30] = np.nan  # an unsolved sample: its own step is 0, the next sample's start not finite
    prev = np.vstack([path[:1], Q[:-1]])
    dx = rng.normal(scale=1e-3, size=(80, 6))
    drift, own = certificate.chain_arrays(robot).null_drift(prev, Q, dx, tuple(rows))
    ref_drift, ref_own = reference_drift(robot, prev, Q, dx, rows)
    scale = np.abs(Q[np.isfinite(Q)]).max()
    assert np.abs(drift - ref_drift).max() <= 1e-9 * scale
    assert np.abs(own - ref_own).max() <= 1e-9 * max(ref_own.max(), 1.0)
    assert np.all(drift[31] == 0.0) and np.all(drift[30] == 0.0)
    py_drift, py_own = tracking.null_drift(robot, prev, Q, dx, rows)  # the route of a chain Pinocchio judges
    assert np.abs(py_drift - ref_drift).max() <= 1e-9 * scale
    assert np.abs(py_own - ref_own).max() <= 1e-9 * max(ref_own.max(), 1.0)


def test_running_events_keep_only_what_the_output_holds():
    drift = np.full((10, 2), 1.0)
    sample, moved = np.empty(3, dtype=np.int64), np.empty(3)
    assert running_events(drift, 1.5, sample, moved) == 3  # an event every second sample; room for three
    assert list(sample) == [1, 3, 5] and np.all(moved == 2.0)
