"""#57 item 7: calls on the newer routes that ended in a raw exception or accepted nonsense on aadeea0, each now a
KinelabError naming what is valid, or an honest answer judged by Pinocchio. The robot files are beside this module."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import maps
from kinelab.analysis import singular
from kinelab.ik.result import Status

HERE = Path(__file__).parent
Q_UR5 = np.array([0.3, -1.2, 1.4, -0.8, 1.2, 0.2])


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


@pytest.fixture(scope="module")
def panda():
    return kinelab.load("panda")


@pytest.fixture(scope="module")
def general6r():
    return kinelab.load("general6r")


def far(x):
    return pin.SE3(np.eye(3), np.array([x, 0.0, 0.0]))


@pytest.mark.parametrize("x", [1e155, 1e200, 1e308])
def test_the_general_6r_elimination_answers_unreachable_far_away(general6r, x):
    """These were LinAlgError ('SVD did not converge') from all three routes."""
    found = kinelab.solve_all(general6r, far(x))
    assert len(found) == 0 and found.status == Status.UNREACHABLE and "beyond" in found.message
    batch = kinelab.solve_all_batch(general6r, [far(x), general6r.fk(np.zeros(6) + 0.3)])
    assert batch.count[0] == 0 and batch.count[1] >= 1
    one = kinelab.solve(general6r, far(x), solver="analytic")
    assert not one.success and one.status == Status.UNREACHABLE


@pytest.mark.parametrize("x", [1e154, 1e200, 1e308])
def test_the_start_table_takes_a_target_far_away(ur5, x):
    """An IndexError (x >= 1e154) or SciPy's ValueError (1e308) on aadeea0."""
    T = ur5.fk(Q_UR5)
    res = kinelab.solve_batch(ur5, [T, far(x)], q0="table", seed=0)
    assert res.success[0] and not res.success[1] and res.status[1] == Status.UNREACHABLE


def test_a_start_that_is_a_strided_view_is_taken(ur5):
    """A regression on aadeea0: a non-contiguous start was a raw 'ndarray is not C-contiguous'."""
    T = ur5.fk(Q_UR5)
    start = np.repeat(Q_UR5 + 0.05, 2)[::2]
    assert not start.flags.c_contiguous
    for res in (kinelab.solve(ur5, T, solver="analytic", q0=start), kinelab.solve(ur5, T, q0=start, seed=0),
                kinelab.IK(ur5, solver="analytic").solve(T, q0=start)):
        assert res.success and max(ur5.tool_error(res.q, T)) <= 1e-6


def test_a_urdf_axis_of_1e308_is_refused_by_name():
    """It loaded on aadeea0, and FK returned 0.88·I for a 'rotation'."""
    with pytest.raises(kinelab.URDFError, match="axis"):
        kinelab.load(HERE / "huge_axis.urdf", tool="tool")


def test_an_mjcf_mesh_outside_its_folder_is_left_out_of_the_view(tmp_path):
    """Its path was handed to assimp and `kinelab view` printed a traceback; URDF meshes outside their folder were
    already skipped."""
    from kinelab.view.scene import Scene

    robot = kinelab.load(HERE / "mesh_outside.xml")
    with pytest.warns(UserWarning, match="outside"):
        scene = Scene(robot)
    assert scene.geom.ngeoms == 0 or all("passwd" not in g.meshPath for g in scene.geom.geometryObjects)
    page = scene.save_html(tmp_path / "view.html")
    assert page.stat().st_size > 0
    scene.close()


@pytest.mark.parametrize("call, needle", [
    (lambda p, u: kinelab.sew_angle(p, np.zeros(7), sew="x"), "sew"),
    (lambda p, u: u.within_limits_batch(np.zeros((5, 7))), "(B, 6)"),
    (lambda p, u: u.within_limits_batch(np.zeros(6)), "(B, 6)"),
    (lambda p, u: u.within_limits_batch("x"), "(B, 6)"),
    (lambda p, u: u.within_limits_batch(np.zeros((2, 3, 6))), "(B, 6)"),
    (lambda p, u: singular.analyze(u, Q_UR5, length=float("nan")), "length"),
    (lambda p, u: singular.analyze(u, Q_UR5, length="x"), "length"),
    (lambda p, u: singular.analyze(u, Q_UR5, length=float("inf")), "length"),
    (lambda p, u: singular.analyze(u, Q_UR5, length=1e-300), "length"),
    (lambda p, u: singular.analyze(u, Q_UR5, length=0), "length"),
    (lambda p, u: singular.analyze(u, Q_UR5, length=-1), "length"),
    (lambda p, u: maps.reachability(u, frobnicate=1), "frobnicate"),
    (lambda p, u: maps.reachability(u, spec="x"), "spec"),
    (lambda p, u: kinelab.solve_all(u, u.fk(Q_UR5), drop_colliding="x"), "drop_colliding"),
    (lambda p, u: kinelab.load("a" * 10000), "unknown robot"),
    (lambda p, u: kinelab.load("a/" * 3000 + "x.urdf"), "unknown robot"),
])
def test_nonsense_is_refused_by_name(panda, ur5, call, needle):
    with pytest.raises(kinelab.KinelabError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        call(panda, ur5)


def test_a_regular_q_has_full_rank_at_any_length_accepted(ur5):
    """length=inf reported rank 3 at a regular q on aadeea0 (also 1e-300; 0 was taken as the default, -1 as 1)."""
    for length in (None, 0.05, 0.4, 2.0):
        assert singular.analyze(ur5, Q_UR5, length=length).rank == 6


def test_maps_load_check_is_a_flag(tmp_path):
    pytest.importorskip("zarr")
    robot = kinelab.load("ur5")
    maps.reachability(robot, voxel=0.4, orientations=2, out=str(tmp_path / "m"))
    with pytest.raises(kinelab.KinelabError, match="check"):
        maps.load(tmp_path / "m", check="x")


BIG = [2**31, 2**63, 2**64]


@pytest.mark.parametrize("big", BIG)
@pytest.mark.parametrize("call", [
    lambda r, T, q, b: kinelab.solve(r, T, max_sweeps=b, seed=0),
    lambda r, T, q, b: kinelab.solve(r, T, stall_window=b, seed=0),
    lambda r, T, q, b: kinelab.solve(r, T, max_restarts=b, seed=0),
    lambda r, T, q, b: kinelab.solve_batch(r, [T], max_restarts=b, seed=0),
    lambda r, T, q, b: kinelab.solve(r, T, solver="biquat", max_steps=b, seed=0),
    lambda r, T, q, b: kinelab.solve(r, T, solver="dls", max_iterations=b, seed=0),
    lambda r, T, q, b: kinelab.solve_all(r, T, max_solutions=b),
    lambda r, T, q, b: kinelab.track(r, [T], q0=q, hold=b),
    lambda r, T, q, b: kinelab.track(r, [T], q0=q, max_sweeps=b),
    lambda r, T, q, b: r.random_qs(b, 0),
    lambda r, T, q, b: maps.reachability(r, voxel=0.3, orientations=b),
    lambda r, T, q, b: kinelab.IK(r, max_restarts=b),
])
def test_counts_beyond_what_a_c_int_holds_are_refused_or_served(ur5, call, big):
    """17 calls with counts >= 2**31 were OverflowError (or MemoryError, or numpy's ValueError) on aadeea0."""
    try:
        result = call(ur5, ur5.fk(Q_UR5), Q_UR5, big)
    except kinelab.KinelabError as err:
        assert "integer" in str(err) or "at most" in str(err) or "too" in str(err)
    else:
        assert result is not None


@pytest.mark.parametrize("seed", [np.uint64(2**64 - 1), np.uint64(2**63), 2**64 - 1, 2**70])
def test_a_numpy_seed_past_2_63_is_taken_by_the_table_start(ur5, seed):
    """#67 item 9 as written: a raw OverflowError from the batch's seed states (a regression)."""
    k, r = kinelab, ur5
    res = k.solve_batch(r, [r.fk(r.random_q(0))], q0="table", seed=seed)
    assert res.success[0] and max(r.tool_error(res.q[0], r.fk(r.random_q(0)))) <= 1e-6
    again = k.solve_batch(r, [r.fk(r.random_q(0))], q0="table", seed=int(seed))
    assert np.array_equal(again.q, res.q)  # a NumPy seed and the same Python int start alike
