"""#70: ``kinelab bench --collisions-step``. The three libraries must hold the same problem: MuJoCo's model of the
Panda's collision meshes and obstacles gives each link's distance to the table that coal gives kinelab's hull of it;
kinelab's steps on the bench's scene keep every pair clear. Times are the bench's business, not a test's."""

import numpy as np
import pinocchio as pin
import pytest

from kinelab import cli
from kinelab.collision import Collisions
from kinelab.report.bench import collision_step as cs
from kinelab.report.bench.steppers import Maps, start_of, whole
from kinelab.wholebody.clearance import step_collisions


def test_mujoco_s_distances_to_the_table_are_coal_s_on_the_same_hulls():
    """At 5 seeded configurations near the start, each Panda link's distance to the table by MuJoCo (its geoms of
    the same meshes) and by coal (kinelab's hulls) agree to 1e-4 m (two convex-hull builds and two GJKs)."""
    mujoco = pytest.importorskip("mujoco")
    robot = whole("panda")
    q0 = start_of(robot)
    collisions = Collisions(environment=cs.obstacles(cs.SCENES["panda"], robot, q0), margin=cs.MARGIN)
    found = step_collisions(robot, collisions)
    model = cs.mujoco_collision_model(robot, collisions.environment)
    maps = Maps(robot, model)
    data, pdata = mujoco.MjData(model), robot.model.createData()
    table = model.geom("table").id
    objects = found.geom.geometryObjects
    rng = np.random.default_rng(4)
    compared = 0
    for _ in range(5):
        q = pin.integrate(robot.model, q0, rng.uniform(-0.3, 0.3, robot.nv))
        data.qpos[:] = maps.to_mujoco(q)
        mujoco.mj_kinematics(model, data)
        pin.forwardKinematics(robot.model, pdata, q)
        results = found.distances(pdata, np.arange(len(found.pairs)))
        for k, (a, b) in enumerate(found.pairs.tolist()):
            if objects[b].name != "table":
                continue
            link = robot.model.frames[objects[a].parentFrame].name
            geoms = [g for g in range(model.ngeom) if model.body(model.geom_bodyid[g]).name == link]
            if len(geoms) != 1 or sum(robot.model.frames[o.parentFrame].name == link for o in objects) != 1:
                continue  # a link of several objects: no one-to-one pair to compare
            fromto = np.zeros(6)
            theirs = mujoco.mj_geomDistance(model, data, geoms[0], table, 1.0, fromto)
            assert abs(theirs - results[k].min_distance) <= 1e-4, (link, theirs, results[k].min_distance)
            compared += 1
    assert compared >= 5 * 6


def test_kinelab_keeps_the_bench_scene_clear():
    rows = cs.run_scene("panda", steps=80, rounds=1)
    mine = next(r for r in rows if r["library"] == "kinelab")
    assert mine["steps"] == 80 and mine["penetrations"] == 0 and mine["least_slack_m"] >= -1e-6
    assert mine["unsolved"] == 0


def test_an_unknown_scene_is_named_with_the_valid_ones(capsys):
    code = cli.main(["bench", "--collisions-step", "--robots", "ur5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "'ur5'" in err[0] and "talos" in err[0]
