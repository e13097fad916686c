"""Mimic joints on the chain: Pinocchio's model couples them; FK against yourdfpy, Jacobians against
central differences, IK with DLS; the kernels that step one joint at a time refuse, naming the joint."""

import numpy as np
import pytest
from helpers import write_urdf

import kinelab
from kinelab import ChainError
from kinelab.analysis import oracles, singular

LINKS = "".join(f'<link name="{n}"/>' for n in ("base", "l1", "l2", "l3", "l4", "tool"))


def joint(name, parent, child, xyz, axis, lower="-2", upper="2", extra=""):
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="{lower}" upper="{upper}" effort="1" '
            f'velocity="1"/>{extra}</joint>')


FOLLOW = '<mimic joint="j2" multiplier="-1.5" offset="0.2"/>'
TOOL = '<joint name="jt" type="fixed"><parent link="l4"/><child link="tool"/><origin xyz="0.1 0 0.05"/></joint>'
MIMIC_ARM = (LINKS + joint("j1", "base", "l1", "0 0 0.3", "0 0 1") + joint("j2", "l1", "l2", "0 0 0.2", "0 1 0")
             + joint("j3", "l2", "l3", "0.3 0 0", "0 1 0", "-3", "3", FOLLOW)
             + joint("j4", "l3", "l4", "0.25 0 0", "1 0 0") + TOOL)


@pytest.fixture
def arm(tmp_path):
    return kinelab.load(write_urdf(tmp_path, MIMIC_ARM))


def test_a_mimic_follower_is_no_coordinate_and_narrows_its_leaders_limits(arm):
    assert arm.joint_names == ["j1", "j2", "j4"] and arm.n == 3
    follower = arm.mimics["j3"]
    assert (follower.leader, follower.multiplier, follower.offset) == ("j2", -1.5, 0.2)
    # j3 = −1.5 j2 + 0.2 within [−3, 3] needs j2 ≥ −1.8667: the leader's range narrows to keep it there
    assert arm.lower[1] == pytest.approx((3 - 0.2) / -1.5) and arm.upper[1] == 2.0


def test_fk_agrees_with_yourdfpy_and_jacobians_with_central_differences(arm):
    reference = oracles.YourdfpyFK(arm)
    rng = np.random.default_rng(0)
    for _ in range(100):
        q = arm.random_q(rng)
        assert np.abs(arm.fk(q).homogeneous - reference.fk(q).homogeneous).max() <= 1e-9
    assert oracles.jacobians_vs_fd(arm, count=100, seed=0).max_rotation <= 1e-6


def test_dls_solves_and_the_singularity_analysis_reads_the_coupled_jacobian(arm):
    rng = np.random.default_rng(1)
    for k in range(20):
        target = arm.fk(arm.random_q(rng))
        res = kinelab.solve(arm, target, solver="dls", task="position", seed=k, time_budget=0.5)
        assert res.success and np.linalg.norm(arm.fk(res.q).translation - target.translation) <= 1e-6
        assert arm.within_limits(res.q)
    q = arm.random_q(rng)
    J_fd = oracles.jacobian_local_fd(arm, q)  # the coupled Jacobian, by differences of Pinocchio's FK
    R = arm.fk(q).rotation
    J_fd = np.vstack([R @ J_fd[:3] / arm.characteristic_length(), R @ J_fd[3:]])
    np.testing.assert_allclose(singular.analyze(arm, q).singular_values, np.linalg.svd(J_fd, compute_uv=False),
                               atol=1e-6)


def test_frdm_and_the_biquaternion_solver_refuse_a_mimic_chain_naming_the_joint(arm):
    target = arm.fk(np.zeros(3))
    for solver in ("frdm", "biquat"):
        with pytest.raises(ChainError, match="joint 'j3' mimics 'j2'.*solver='dls'"):
            kinelab.solve(arm, target, solver=solver)


def test_a_follower_whose_leader_is_off_the_chain_is_named_and_can_be_held(tmp_path):
    branch = (LINKS + '<link name="side"/>' + joint("j1", "base", "l1", "0 0 0.3", "0 0 1")
              + joint("s", "base", "side", "0.1 0 0", "0 0 1")
              + joint("j2", "l1", "l2", "0 0 0.2", "0 1 0", extra='<mimic joint="s" multiplier="1" offset="0"/>')
              + joint("j3", "l2", "tool", "0.3 0 0", "0 1 0"))
    path = write_urdf(tmp_path, branch.replace('<link name="l3"/><link name="l4"/>', ""))
    with pytest.raises(ChainError, match="joint 'j2' mimics 's', which is off the base-tool chain"):
        kinelab.load(path, tool="tool")
    held = kinelab.load(path, tool="tool", locked={"j2": 0.5})
    assert held.joint_names == ["j1", "j3"]
