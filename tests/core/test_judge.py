"""The compiled chain FK (kinelab.core, built at install) against Pinocchio's, its certificate on each robot, the
judge a batch names, and a stale build refused (#32: the judge, compiled and certified)."""

import numpy as np
import pinocchio as pin
import pytest
from helpers import revolute, write_urdf

import kinelab
import kinelab.cli
from kinelab.robot import certificate

ARMS = ["ur5", "panda", "kinova", "youbot", "stanford", "era", "so101", "finger_edu"]


@pytest.mark.parametrize("name", ARMS)
def test_the_compiled_fk_is_pinocchio_s_at_random_configurations_and_at_the_limits(name):
    robot = kinelab.load(name)
    arrays = certificate.chain_arrays(robot)
    assert isinstance(arrays, certificate.ChainArrays)
    Q = robot.random_qs(200, np.random.default_rng(11))
    lower, upper = robot.sample_bounds
    Q[: robot.n] = np.where(np.eye(robot.n, dtype=bool), lower, Q[: robot.n])  # each joint at a limit
    Q[robot.n: 2 * robot.n] = np.where(np.eye(robot.n, dtype=bool), upper, Q[robot.n: 2 * robot.n])
    compiled = arrays.fk_batch(Q)
    model, data, fid = robot.model, robot.model.createData(), robot.tool_frame_id
    for q, H in zip(Q, compiled, strict=True):
        pin.framesForwardKinematics(model, data, robot.to_pin_q(q))  # Pinocchio's own FK, called here
        assert np.abs(H - data.oMf[fid].homogeneous).max() <= 1e-12
    assert robot.fk_certificate.certified and robot.fk_certificate.judge == "compiled FK (certified)"


def test_a_chain_the_compiled_fk_cannot_take_is_judged_by_pinocchio_and_says_so(tmp_path):
    """A mimic joint couples two joints, which the compiled FK does not model: the certificate says why, fk_batch
    and every batch verdict use Pinocchio's FK, and kinelab info says so."""
    links = "".join(f'<link name="{n}"/>' for n in ("base", "l1", "l2", "tool"))
    arm = kinelab.load(write_urdf(tmp_path, links + revolute("j1", "base", "l1") + revolute(
        "j2", "l1", "l2", axis="0 1 0", extra='<mimic joint="j1" multiplier="0.5"/>') + revolute(
        "j3", "l2", "tool", axis="1 0 0")))
    cert = arm.fk_certificate
    assert not cert.certified and "mimics" in cert.reason and cert.judge == "Pinocchio FK"
    Q = arm.random_qs(5, 2)
    expected = np.array([arm.fk(q).homogeneous for q in Q])
    np.testing.assert_array_equal(arm.fk_batch(Q), expected)  # Pinocchio's, to the bit
    res = kinelab.solve_batch(arm, expected, solver="dls", seed=0)
    assert res.judge == "Pinocchio FK" and res.success.all()


def test_a_compiled_fk_that_disagrees_with_pinocchio_is_not_certified(monkeypatch):
    """The certificate is a comparison, not a label: an arm whose packed chain is wrong (a joint placement off by
    1e-9 m) fails it, and its answers are judged by Pinocchio."""
    robot = kinelab.load("ur5")
    good = certificate.chain_arrays(robot)
    shifted = good.placement_t.copy()
    shifted[2, 0] += 1e-9
    monkeypatch.setattr(certificate, "chain_arrays", lambda r: certificate.ChainArrays(
        good.placement_R, shifted, good.axis, good.kind, good.tool_R, good.tool_t))
    cert = certificate.certify(robot)
    assert not cert.certified and "differs from Pinocchio's by 1.0e-09 m" in cert.reason


def test_a_batch_names_its_judge_and_kinelab_info_shows_the_certificate(capsys):
    ur5 = kinelab.load("ur5")
    targets = ur5.fk_batch(ur5.random_qs(4, 3))
    res = kinelab.solve_batch(ur5, targets, solver="frdm", seed=0)
    assert res.judge == "compiled FK (certified)" and res.success.all()
    for b in range(4):  # the certified judge's verdict is Pinocchio's
        dp, dr = ur5.tool_error(res.q[b], pin.SE3(targets[b]))
        assert dp <= 1e-6 and dr <= 1e-6
    assert kinelab.cli.main(["info", "ur5"]) == 0
    assert "answers judged by: compiled FK, certified against Pinocchio's at 76 configurations" in \
        capsys.readouterr().out


def test_a_stale_compiled_core_is_refused_with_the_rebuild_command(monkeypatch):
    import kinelab.core
    from kinelab.core import _built

    kinelab.core._check_fresh()  # the build matches its sources
    monkeypatch.setattr(_built, "SOURCE_CRC32", "0" * 8)  # as after an edit of a .pyx without a rebuild
    with pytest.raises(kinelab.KinelabError, match=r"older than its sources .*pip install -e \."):
        kinelab.core._check_fresh()
    monkeypatch.delattr(_built, "SOURCE_CRC32")  # a build recorded before the CRC was
    with pytest.raises(kinelab.KinelabError, match=r"older than its sources"):
        kinelab.core._check_fresh()


def test_both_fingerprints_change_with_one_byte_of_one_source(tmp_path):
    from kinelab.core import digest

    (tmp_path / "a.pyx").write_bytes(b"cdef int x = 1\n")
    (tmp_path / "b.pxd").write_bytes(b"cdef int y\n")
    (tmp_path / "notes.txt").write_bytes(b"not a source")
    before = digest.source_crc32(tmp_path), digest.source_sha256(tmp_path)
    (tmp_path / "notes.txt").write_bytes(b"still not a source")
    assert (digest.source_crc32(tmp_path), digest.source_sha256(tmp_path)) == before
    (tmp_path / "a.pyx").write_bytes(b"cdef int x = 2\n")
    after = digest.source_crc32(tmp_path), digest.source_sha256(tmp_path)
    assert after[0] != before[0] and after[1] != before[1]
    assert len(after[0]) == 8 and len(after[1]) == 64


def _general_fk(arrays, q):
    """oMtool by the general products, in plain Python floats (one IEEE operation each, in the compiled FK's order):
    Rodrigues' matrix of every axis, every joint origin multiplied in."""
    import math

    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    t = [0.0, 0.0, 0.0]

    def compose(dR, dt):
        nonlocal R, t
        t = [t[i] + R[i][0] * dt[0] + R[i][1] * dt[1] + R[i][2] * dt[2] for i in range(3)]
        R = [[R[i][0] * dR[0][j] + R[i][1] * dR[1][j] + R[i][2] * dR[2][j] for j in range(3)] for i in range(3)]

    for k in range(len(q)):
        compose(arrays.placement_R[k].tolist(), arrays.placement_t[k].tolist())
        x, y, z = arrays.axis[k].tolist()
        if arrays.kind[k] == 1:
            t = [t[j] + (R[j][0] * x + R[j][1] * y + R[j][2] * z) * q[k] for j in range(3)]
            continue
        c, s = math.cos(q[k]), math.sin(q[k])
        C = 1.0 - c
        compose([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                 [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                 [z * x * C - y * s, z * y * C + x * s, c + z * z * C]], [0.0, 0.0, 0.0])
    compose(arrays.tool_R.tolist(), arrays.tool_t.tolist())
    return np.array([[*R[i], t[i]] for i in range(3)])


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova", "youbot"])
def test_the_shortcuts_for_coordinate_axes_and_plain_origins_give_the_general_products(name):
    """The compiled FK skips an identity joint origin and the zero terms of a ±x, ±y or ±z axis's rotation; its
    values are those of the general products all the same (compared exactly, on the same machine)."""
    robot = kinelab.load(name)
    arrays = certificate.chain_arrays(robot)
    for q in robot.random_qs(20, np.random.default_rng(5)):
        np.testing.assert_array_equal(arrays.fk_batch(q[None])[0][:3], _general_fk(arrays, q.tolist()))


def test_the_build_loads_the_fingerprints_without_kinelab(tmp_path):
    """setup.py loads digest.py by path in an isolated build, where kinelab is not importable (-I -S: neither
    the working folder nor site-packages, where the editable install lives, is on the path)."""
    import subprocess
    import sys
    from pathlib import Path

    import kinelab.core
    from kinelab.core import digest

    source = Path(kinelab.core.__file__).with_name("digest.py")
    (tmp_path / "a.pyx").write_bytes(b"cdef int x = 1\n")
    code = ("import importlib.util, sys\n"
            f"spec = importlib.util.spec_from_file_location('d', {str(source)!r})\n"
            "m = importlib.util.module_from_spec(spec); spec.loader.exec_module(m)\n"
            f"print(m.source_crc32(__import__('pathlib').Path({str(tmp_path)!r})))\n"
            "assert 'kinelab' not in sys.modules\n")
    done = subprocess.run([sys.executable, "-I", "-S", "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == digest.source_crc32(tmp_path)
