"""#59: ``kinelab bench --whole-body``. What it measures must be the same problem in the three libraries: MuJoCo's
model compiled from the URDF places every task frame where Pinocchio does, the q maps go both ways, and kinelab's
steps on the bench's moving targets hold the limits and track. Times are the bench's business, not a test's."""

import numpy as np
import pinocchio as pin
import pytest

from kinelab import cli
from kinelab.report.bench import steppers
from kinelab.report.bench import wholebody as wb


@pytest.mark.parametrize("name", ["panda", "talos"])
def test_mujoco_places_every_task_frame_where_pinocchio_does(name):
    mujoco = pytest.importorskip("mujoco")
    scenario, robot = steppers.SCENARIOS[name], steppers.whole(steppers.SCENARIOS[name].robot)
    model = steppers.mujoco_model(robot)
    maps = steppers.Maps(robot, model)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    for _ in range(5):
        q = robot.random_q(rng)
        assert np.abs(pin.difference(robot.model, q, maps.from_mujoco(maps.to_mujoco(q)))).max() <= 1e-12
        data.qpos[:] = maps.to_mujoco(q)
        mujoco.mj_kinematics(model, data)
        frames = scenario.moving + scenario.held
        for frame, oMf in zip(frames, robot.frame_placements(q, frames), strict=True):
            body = model.body(frame).id
            assert np.abs(data.xpos[body] - oMf.translation).max() <= 1e-9
            assert np.abs(data.xmat[body].reshape(3, 3) - oMf.rotation).max() <= 1e-9


def test_kinelab_follows_the_bench_targets_within_its_limits():
    rows = wb.run_steps("panda", steps=60, rounds=1)
    mine = next(r for r in rows if r["library"] == "kinelab")
    assert mine["steps"] == 60 and mine["violations"] == 0
    assert mine["max_tracking_error_m"] <= 2e-3  # a 5 cm circle in 2 s, followed at dt = 5 ms


def test_a_robot_without_a_scenario_is_named_with_the_valid_ones(capsys):
    code = cli.main(["bench", "--whole-body", "--robots", "ur5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "'ur5'" in err[0] and "talos" in err[0]


def test_n_0_skips_the_converged_solves_and_other_protocols_refuse_it(capsys):
    """#72 item 8: ``--whole-body --n 0`` runs the steps alone; an arm protocol refuses 0 targets in one line."""
    import json

    assert cli.main(["bench", "--whole-body", "--robots", "panda", "--repeats", "1", "--n", "0", "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["whole_body"]
    assert found["solves"] == [] and {r["library"] for r in found["steps"]} >= {"kinelab"}
    code = cli.main(["bench", "--n", "0"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--whole-body" in err[0]


def test_standing_steps_start_where_the_robot_stands_and_say_so(capsys, monkeypatch):
    """``--standing``: every library's stepper is made at ``robot.standing()`` (TALOS: its SRDF's half-sitting
    joints), the JSON and the table say the start; without --whole-body it is refused in one line."""
    import json

    import kinelab

    seen = []
    made = wb.STEPPERS["kinelab"]
    monkeypatch.setattr(wb, "STEPPERS", {"kinelab": lambda r, s, q0: seen.append(q0.copy()) or made(r, s, q0)})
    assert cli.main(["bench", "--whole-body", "--standing", "--robots", "talos", "--repeats", "1", "--n", "0",
                     "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["whole_body"]
    assert found["protocol"]["start"] == "standing" and "standing start" in wb.markdown(found)
    half = kinelab.load("talos").named_q("half_sitting")
    assert seen and np.allclose(seen[0][7:], half[7:], atol=1e-12)
    assert cli.main(["bench", "--standing"]) == 2
    assert "--whole-body" in capsys.readouterr().err
