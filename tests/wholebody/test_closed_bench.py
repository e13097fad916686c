"""#69: ``kinelab bench --closed``. MuJoCo's model must hold the same loops: at assemblies of the four-bar and the
ankle, its connect equalities' two sites coincide (1e-9 m), Cassie's own connects are closed (1e-9 m), so that
mink is asked what kinelab is; kinelab's steps
on the bench's path keep the loops closed. Times are the bench's business, not a test's."""

import numpy as np
import pytest
from helpers import assembled_draws

import kinelab
from kinelab import cli
from kinelab.report.bench import closed_step
from kinelab.report.bench.steppers import Maps


@pytest.mark.parametrize("name", ["fourbar", "ankle"])
def test_mujoco_s_loop_sites_meet_at_kinelab_s_assemblies(name):
    mujoco = pytest.importorskip("mujoco")
    robot = kinelab.load(name)
    model = closed_step.loop_model(robot)
    maps, data = Maps(robot, model), mujoco.MjData(model)
    met = 0
    for _, q in assembled_draws(robot, 10, np.random.default_rng(2), spread=0.3):
        if q is None:
            continue
        data.qpos[:] = maps.to_mujoco(q)
        mujoco.mj_kinematics(model, data)
        for k in range(len(robot.closures)):
            a, b = data.site(f"loop{k}a").xpos, data.site(f"loop{k}b").xpos
            assert np.linalg.norm(a - b) <= 1e-9
        met += 1
    assert met >= 5


def test_cassie_s_own_connects_are_closed_at_kinelab_s_assemblies():
    """Cassie's MuJoCo model is its file: at 10 of kinelab's assemblies (random motors, mapped through Maps, its
    ball joints' quaternions reordered) MuJoCo's four connect equalities have residuals ≤ 1e-9 m, and the map back
    gives the same q."""
    mujoco = pytest.importorskip("mujoco")
    robot = kinelab.load("cassie")
    model = closed_step.loop_model(robot)
    maps, data = Maps(robot, model), mujoco.MjData(model)
    met = 0
    for _, q in assembled_draws(robot, 12, np.random.default_rng(3)):
        if q is None:
            continue
        data.qpos[:] = maps.to_mujoco(q)
        mujoco.mj_forward(model, data)
        equality = data.efc_type[:data.nefc] == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        assert equality.sum() == 12 and np.abs(data.efc_pos[:data.nefc][equality]).max() <= 1e-9
        assert np.abs(robot.difference(q, maps.from_mujoco(data.qpos))).max() <= 1e-12
        met += 1
    assert met >= 8


def test_kinelab_keeps_the_loops_on_the_bench_path():
    rows = closed_step.run_robot("fourbar", steps=60, rounds=1)
    mine = next(r for r in rows if r["library"] == "kinelab")
    assert mine["steps"] == 60 and mine["max_loop_error"] <= 1e-9


def test_the_delta_is_named_as_the_robot_the_bench_cannot_pose(capsys):
    code = cli.main(["bench", "--closed", "--robots", "delta"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "orientation loop" in err[0]
