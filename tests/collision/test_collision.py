"""Collisions: Pinocchio's collision model of the reduced chain, the sphere first test (never misses what the
exact test finds), and solves whose successes are clear of the robot itself and of the obstacles."""

import json
import os

import browser
import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.collision import CollisionError, Collisions, Environment, Obstacle, ObstacleError, collision_model

FLOOR_AND_TABLE = Environment((Obstacle("plane", name="floor"),
                               Obstacle("box", size=(0.6, 0.8, 0.05), xyz=(0.5, 0.0, 0.2), name="table")))


@pytest.fixture(scope="module", params=["ur5", "panda"])
def arm(request):
    return kinelab.load(request.param)


def test_a_wrist_driven_into_the_base_and_a_tool_under_the_floor_are_detected(arm):
    """Built here: the tool point placed (position task) inside the base's own geometry must make the arm hit
    itself; the tool 5 cm under the floor must hit the floor; a configuration above the floor, away from both,
    is clear."""
    model = collision_model(arm, Collisions())
    base_obj = next(o for o in model.geom.geometryObjects if o.parentJoint == 0)
    base_point = base_obj.placement.translation + np.array([0.08, 0.0, 0.05])
    into_base = kinelab.solve(arm, base_point, task="position", seed=0)
    assert into_base.success
    contact = model.contact(into_base.q)
    assert contact is not None and contact.distance <= 0.0
    floor = collision_model(arm, Collisions(self_collisions=False,
                                            environment=Environment((Obstacle("plane", name="floor"),))))
    under = kinelab.solve(arm, np.array([0.45, 0.3, -0.05]), task="position", seed=0)
    hit = floor.contact(under.q)
    assert under.success and hit is not None and "floor" in (hit.first, hit.second)
    up = np.zeros(arm.n) if arm.name == "ur5" else arm.neutral()
    clear = next(q for q in (up, arm.random_q(3), arm.random_q(4))
                 if arm.fk(q).translation[2] > 0.3 and model.contact(q, first_test=False) is None)
    assert model.contact(clear) is None


def test_the_sphere_test_never_misses_a_collision_the_exact_test_finds(arm):
    """10 000 random configurations per arm against the arm itself, the floor and the table (a 1 cm margin),
    and 2000 against the arm alone: wherever the exact test on every pair finds a collision, the sphere test
    leaves a pair for it to find."""
    rng = np.random.default_rng(11)
    for spec, count in ((Collisions(environment=FLOOR_AND_TABLE, margin=0.01), 10_000), (Collisions(), 2000)):
        model = collision_model(arm, spec)
        hits = 0
        for _ in range(count):
            q = arm.random_q(rng)
            exact = model.colliding_pair(q, first_test=False)
            hits += exact is not None
            assert (exact is None) == (model.colliding_pair(q) is None), q
        assert 0.05 < hits / count < 0.95  # both kinds of configuration were tried


def test_a_success_is_clear_of_the_arm_and_the_obstacles(arm):
    """Property: over random targets, a quarter to three quarters of them the FK of colliding configurations
    (measured: 16 of 60 on panda, 40 of 60 on ur5 with the table), every success of a solve
    with collisions= is clear by the exact test on every pair; an answer that collides is never a success."""
    model = collision_model(arm, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(12)
    successes = colliding_targets = 0
    for k in range(60):
        q = arm.random_q(rng)
        colliding_targets += model.colliding_pair(q, first_test=False) is not None
        res = kinelab.solve(arm, arm.fk(q), seed=k, collisions=FLOOR_AND_TABLE, time_budget=0.2)
        if res.success:
            successes += 1
            assert model.contact(res.q, first_test=False) is None
        else:
            assert res.status in (kinelab.Status.COLLISION, kinelab.Status.TIME_BUDGET)
            if res.status == kinelab.Status.COLLISION:
                assert res.diagnostics.contact is not None and "collides" in res.message
    assert successes >= 20 and colliding_targets >= 10


def test_a_colliding_answer_of_an_arm_with_a_closed_form_restarts_at_its_nearest_clear_branch():
    """ur5 (closed form): where the plain answer hits the floor or the table, the solve with collisions= runs
    once more from the clear branch nearest that answer and returns it; with a box through the shoulder every
    branch collides, which the solve says at once, counting the branches."""
    from kinelab.ik.limits import distance

    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(11)
    checked = 0
    for seed in range(200):
        q = ur5.random_q(rng)
        if model.colliding_pair(q) is not None:
            continue
        target = ur5.fk(q)
        plain = kinelab.solve(ur5, target, solver="frdm", seed=seed)
        if not plain.success or model.colliding_pair(plain.q) is None:
            continue
        res = kinelab.solve(ur5, target, solver="frdm", seed=seed, collisions=FLOOR_AND_TABLE)
        assert res.success and res.diagnostics.clear_after == 1 and model.colliding_pair(res.q) is None
        clear = [b.q for b in kinelab.solve_all(ur5, target) if model.colliding_pair(b.q) is None]
        gaps = [distance(ur5, b, plain.q) for b in clear]  # the distance the branches are sorted by
        assert min(distance(ur5, b, res.q) for b in clear) < 1e-6  # one of the clear branches
        assert distance(ur5, res.q, plain.q) <= min(gaps) + 1e-9  # a nearest one (ties happen: q1 ± π)
        checked += 1
        if checked == 10:
            break
    assert checked == 10
    shoulder = Environment((Obstacle("box", size=(0.3, 0.3, 0.3), xyz=(0.0, 0.0, 0.1), name="post"),))
    target = ur5.fk(ur5.random_q(2))
    res = kinelab.solve(ur5, target, seed=0, collisions=Collisions(self_collisions=False, environment=shoulder))
    assert res.status.value == "collision" and "each of its" in res.message and "post" in res.message
    assert res.diagnostics.clear_after == 1 and res.diagnostics.attempts <= 1  # at once: no restart was tried


def test_solve_all_marks_or_drops_the_branches_that_collide():
    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(13)
    for _ in range(20):
        target = ur5.fk(ur5.random_q(rng))
        every = kinelab.solve_all(ur5, target)
        marked = kinelab.solve_all(ur5, target, collisions=FLOOR_AND_TABLE)
        kept = kinelab.solve_all(ur5, target, collisions=FLOOR_AND_TABLE, drop_colliding=True)
        assert len(marked) == len(every)
        for m in marked:
            assert m.success == (model.contact(m.q, first_test=False) is None)
            assert m.success or (m.status == kinelab.Status.COLLISION and m.diagnostics.contact is not None)
        assert [k.q.tolist() for k in kept] == [m.q.tolist() for m in marked if m.success]


def test_obstacles_and_settings_are_checked_by_name(tmp_path):
    with pytest.raises(ObstacleError, match="unknown shape 'cone'"):
        Obstacle("cone", (1.0,))
    with pytest.raises(ObstacleError, match="sizes must be > 0"):
        Obstacle("box", (1.0, -1.0, 1.0))
    with pytest.raises(ObstacleError, match="finite"):
        Obstacle("sphere", (float("nan"),))
    with pytest.raises(ObstacleError, match="a box takes 3 size"):
        Obstacle("box", (1.0,))
    with pytest.raises(CollisionError, match="margin"):
        Collisions(margin=-0.1)
    with pytest.raises(CollisionError, match="'self', a kinelab.Environment"):
        kinelab.solve(kinelab.load("ur5"), kinelab.load("ur5").fk(np.zeros(6)), collisions="everything")
    path = tmp_path / "scene.json"
    path.write_text(json.dumps({"obstacles": [{"shape": "plane", "name": "floor"},
                                              {"shape": "box", "size": [0.6, 0.8, 0.05], "xyz": [0.5, 0, 0.2],
                                               "name": "table"}]}))
    assert Environment.from_file(path) == FLOOR_AND_TABLE
    path.write_text(json.dumps({"obstacles": [{"shape": "box", "size": [1, 1], "name": "bad"}]}))
    with pytest.raises(ObstacleError, match="'bad': a box takes 3"):
        Environment.from_file(path)
    path.write_text("{not json")
    with pytest.raises(ObstacleError, match="cannot read the obstacle file"):
        Environment.from_file(path)
    model_only = kinelab.Robot.from_model(kinelab.load("ur5").model, tool="tool0")
    with pytest.raises(CollisionError, match="no collision geometry"):
        collision_model(model_only, Collisions())


def test_missing_collision_meshes_are_named_and_the_robot_still_loads(tmp_path):
    from helpers import write_urdf

    body = ('<link name="base"/><link name="l1"><collision><geometry><mesh filename="package://nowhere/arm.stl"/>'
            '</geometry></collision></link><link name="l2"><collision><geometry><box size="0.1 0.1 0.1"/>'
            '</geometry></collision></link>'
            '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
            '<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/>'
            '<axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    robot = kinelab.load(write_urdf(tmp_path, body), tool="l2")
    assert robot.fk(np.zeros(2)).translation[2] == pytest.approx(0.3)  # the kinematics are intact
    with pytest.raises(CollisionError, match=r"1 collision mesh\(es\) not found \(first: package://nowhere/arm.stl; "
                                             "searched"):
        kinelab.solve(robot, robot.fk(np.zeros(2)), collisions="self")


def test_the_srdf_disables_pairs_and_a_pair_naming_a_missing_link_is_reported(tmp_path):
    srdf = tmp_path / "panda.srdf"
    srdf.write_text('<?xml version="1.0"?><robot name="panda">'
                    '<disable_collisions link1="panda_link5" link2="panda_link7" reason="Default"/>'
                    '<disable_collisions link1="panda_link5" link2="panda_hand" reason="Default"/>'
                    '<disable_collisions link1="panda_link0" link2="panda_link99" reason="Never"/></robot>')
    plain = collision_model(kinelab.load("panda"), Collisions())
    robot = kinelab.load("panda", srdf=srdf)
    with pytest.warns(UserWarning, match="names link\\(s\\) panda_link99"):
        pruned = collision_model(robot, Collisions())
    assert "2 disabled by the SRDF" in pruned.summary and len(pruned.pairs) == len(plain.pairs) - 2
    q = np.zeros(7)  # at zero, link 5 touches link 7 and the hand: only the SRDF's pairs say so
    assert plain.contact(q) is not None and pruned.contact(q) is None


def test_a_batch_and_a_path_never_count_a_colliding_answer():
    """solve_batch solves a colliding row again and fails it with status collision when no answer is clear;
    track marks the samples whose answer collides, by sample."""
    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(14)
    Q = [q for q in (ur5.random_q(rng) for _ in range(400)) if model.colliding_pair(q) is None][:40]
    targets = ur5.fk_batch(np.array(Q))  # reachable without a collision
    plain = kinelab.solve_batch(ur5, targets, seed=0)
    clear = kinelab.solve_batch(ur5, targets, seed=0, collisions=FLOOR_AND_TABLE, time_budget=5.0)
    assert any(model.colliding_pair(q) is not None for q in plain.q[plain.success])  # the plain batch collides
    for q, ok, status in zip(clear.q, clear.success, clear.status, strict=True):
        assert not ok or model.contact(q, first_test=False) is None
        assert ok or status in ("collision", "time_budget")
    assert clear.success.sum() >= 0.95 * len(targets)
    start = np.array([0.0, -1.0, 1.2, -0.2, 0.4, 0.0])
    line = [ur5.fk(start + np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]))]
    down = [pin_shift(line[0], dz) for dz in np.linspace(0.0, -1.2, 25)]  # the tool driven through the table
    path = kinelab.track(ur5, down, q0=start, collisions=FLOOR_AND_TABLE)
    hit = [k for k, s in enumerate(path.status) if s == "collision"]
    assert hit and [k for k, _ in path.contacts] == hit
    assert all(model.contact(path.q[k], first_test=False) is not None for k in hit)
    assert all(model.contact(path.q[k], first_test=False) is None for k in np.flatnonzero(path.reached))


def pin_shift(T, dz):
    import pinocchio as pin

    return pin.SE3(T.rotation, T.translation + np.array([0.0, 0.0, dz]))


def test_the_prepared_solver_checks_every_call_against_the_model_it_built_once():
    ur5 = kinelab.load("ur5")
    ik = kinelab.IK(ur5, collisions=FLOOR_AND_TABLE, time_budget=0.5)
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    assert ik.collisions is model  # built once, shared with the plain calls
    rng = np.random.default_rng(15)
    clear = [q for q in (ur5.random_q(rng) for _ in range(300)) if model.colliding_pair(q) is None][:20]
    for k, q in enumerate(clear):
        res = ik.solve(ur5.fk(q), seed=k)
        assert res.success and model.contact(res.q, first_test=False) is None
    batch = ik.solve_batch(ur5.fk_batch(np.array(clear)), seed=0)
    assert all(model.contact(q, first_test=False) is None for q in batch.q[batch.success])
    branches = ik.solve_all(ur5.fk(clear[0]), seed=0)
    assert all(b.success == (model.contact(b.q, first_test=False) is None) for b in branches)


def test_the_command_line_checks_collisions_with_an_obstacle_file(tmp_path, capsys):
    from kinelab import cli

    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"obstacles": [{"shape": "plane", "name": "floor"}]}))
    code = cli.main(["fk", "ur5", "0", "0", "0", "0", "0", "0", "--obstacles", str(scene), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["collision"]["second"] == "floor" and out["collision"]["distance"] < 0
    code = cli.main(["ik", "ur5", "--target-xyz", "0.4", "0.2", "0.5", "--target-rpy", "3.14", "0", "0",
                     "--obstacles", str(scene), "--json"])
    res = json.loads(capsys.readouterr().out)
    ur5 = kinelab.load("ur5")
    floor = collision_model(ur5, Collisions(environment=Environment.from_file(scene)))
    assert code == 0 and res["success"] and floor.contact(res["q"], first_test=False) is None
    assert res["info"]["clear_after"] is not None
    for argv, said in ((["fk", "ur5", "0", "0", "0", "0", "0", "0", "--margin", "0.1"], "--margin is a collision"),
                       (["fk", "ur5", "0", "0", "0", "0", "0", "0", "--obstacles", str(tmp_path / "none.json")],
                        "obstacle file not found")):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err
        assert said in err and err.count("\n") == 1


def test_a_scene_draws_the_obstacles_and_the_links_in_contact():
    from kinelab.view import scene as viz
    from kinelab.view.collisions import draw_collisions

    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    q = np.array([0.0, -0.3, 0.9, 0.0, 0.0, 0.0])  # the arm laid through the table onto the floor
    s = viz.Scene(ur5)
    try:
        contacts = draw_collisions(s, model, q)
        names = {n for c in contacts for n in (c.first, c.second)}
        assert {"floor", "table"} <= names and all(c.distance <= 0 for c in contacts)
        assert [str(c) for c in contacts] == [str(c) for c in model.contacts(q)]
        from browser import scene_paths

        paths = scene_paths(s.static_html())
        red = {p for p in paths if p.startswith("/meshcat/contacts/")}
        assert len(red) == len(names - {"floor", "table"}) and {"/meshcat/obstacles/0", "/meshcat/obstacles/1"} <= paths
        assert "red links: in contact" in s.legend["collisions"]
        assert "teal: floor (plane); brown: table (box)" in s.legend["obstacles"]
        clear = draw_collisions(s, model, np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0]))
        assert clear == [] and "no contact" in s.legend["collisions"]
        assert not {p for p in scene_paths(s.static_html()) if p.startswith("/meshcat/contacts/")}
    finally:
        s.close()


def test_a_mesh_obstacle_collides_where_the_same_box_does(tmp_path):
    """A 0.3 m cube written here as an STL file and the box of the same size and place give the same verdicts;
    an obstacle file may name a mesh beside it, not outside its folder."""
    import trimesh

    trimesh.creation.box(extents=(0.3, 0.3, 0.3)).export(tmp_path / "cube.stl")
    ur5 = kinelab.load("ur5")
    place = {"xyz": (0.4, 0.1, 0.3), "rpy": (0.0, 0.0, 0.4)}
    as_box = collision_model(ur5, Collisions(self_collisions=False,
                                             environment=Environment((Obstacle("box", (0.3, 0.3, 0.3), **place),))))
    as_mesh = collision_model(ur5, Collisions(self_collisions=False, environment=Environment(
        (Obstacle("mesh", mesh=str(tmp_path / "cube.stl"), **place),))))
    rng = np.random.default_rng(17)
    hits = 0
    for _ in range(400):
        q = ur5.random_q(rng)
        box_hit = as_box.colliding_pair(q, first_test=False) is not None
        hits += box_hit
        assert box_hit == (as_mesh.colliding_pair(q) is not None)
    assert hits > 20
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"obstacles": [{"shape": "mesh", "mesh": "cube.stl", "xyz": [0.4, 0.1, 0.3]}]}))
    assert Environment.from_file(scene).obstacles[0].mesh == str((tmp_path / "cube.stl").resolve())
    scene.write_text(json.dumps({"obstacles": [{"shape": "mesh", "mesh": "../elsewhere/cube.stl"}]}))
    with pytest.raises(ObstacleError, match="outside the file's folder"):
        Environment.from_file(scene)
    with pytest.raises(ObstacleError, match="names its file"):
        Obstacle("mesh")


def test_the_map_command_counts_only_clear_answers_with_an_obstacle_file(tmp_path, capsys):
    from kinelab import cli

    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"obstacles": [{"shape": "plane", "name": "floor"}]}))
    argv = ["map", "reach", "ur5", "--voxel", "0.3", "--orientations", "4", "--json"]
    assert cli.main(argv) == 0
    free = json.loads(capsys.readouterr().out)
    assert cli.main([*argv, "--obstacles", str(scene)]) == 0
    walled = json.loads(capsys.readouterr().out)
    assert walled["voxels"] == free["voxels"] and walled["reached_voxels"] < free["reached_voxels"]
    assert walled["mean_reachability"] < free["mean_reachability"]


def _nearest_distance(robot, geom, q):
    """The least distance [m] between the geometry's pairs at q, by Pinocchio on geometry data of its own."""
    data, gdata = robot.model.createData(), pin.GeometryData(geom)
    pin.computeDistances(robot.model, data, geom, gdata, robot.to_pin_q(q))
    return min(r.min_distance for r in gdata.distanceResults)


def _at_distance(robot, geom, clear, touching, wanted):
    """A configuration on the segment from ``clear`` to ``touching`` whose least pair distance is ``wanted`` [m]
    (to 5 %), by bisection on the segment's parameter."""
    lo, hi = 0.0, 1.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        d = _nearest_distance(robot, geom, clear + mid * (touching - clear))
        if abs(d - wanted) < 0.05 * wanted:
            return clear + mid * (touching - clear), d
        lo, hi = (mid, hi) if d > wanted else (lo, mid)
    raise AssertionError("no configuration at that distance on the segment")


def test_a_pair_within_a_micrometre_of_contact_counts_as_colliding_and_one_beyond_it_is_clear():
    """Two shapes touching are a collision or none by the exact test's starting guess: kinelab calls a pair
    colliding within TOUCH = 1e-6 m, so that an answer it calls clear is clear by Pinocchio at margin 0."""
    from kinelab.collision.model import TOUCH

    panda = kinelab.load("panda")
    model = collision_model(panda, Collisions())
    qs = panda.random_qs(400, np.random.default_rng(12))
    clear = next(q for q in qs if _nearest_distance(panda, model.geom, q) > 0.02)
    touching = next(q for q in qs if model.colliding_pair(q) is not None)
    assert model.checked_margin == TOUCH == 1e-6
    near, d = _at_distance(panda, model.geom, clear, touching, 0.4 * TOUCH)
    assert 0 < d < TOUCH and model.colliding_pair(near) is not None
    apart, d = _at_distance(panda, model.geom, clear, touching, 20 * TOUCH)
    assert d > TOUCH and model.colliding_pair(apart) is None


CONTACT_Q = [-0.256, 0.549, -1.908, 6.235, -3.227, -3.055]  # the UR5 through a table onto the floor: six pairs


def test_fk_names_every_pair_in_contact_as_pinocchio_finds_them(tmp_path, capsys):
    """#43 item 3: ``kinelab fk --obstacles`` named one pair of the six the view coloured. Every pair Pinocchio's
    computeCollisions finds (fresh geometry data, the model's own pairs) is named, and no other."""
    from kinelab import cli

    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"obstacles": [{"shape": "plane", "name": "floor"},
                                               {"shape": "box", "size": [0.6, 0.8, 0.05], "xyz": [0.5, 0, 0.2],
                                                "name": "table"}]}))
    code = cli.main(["fk", "ur5", *map(str, CONTACT_Q), "--obstacles", str(scene), "--json"])
    out = json.loads(capsys.readouterr().out)
    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=Environment.from_file(scene)))
    data, gdata = ur5.model.createData(), pin.GeometryData(model.geom)
    pin.computeCollisions(ur5.model, data, model.geom, gdata, ur5.to_pin_q(np.array(CONTACT_Q)), False)
    names = [o.name for o in model.geom.geometryObjects]
    pinocchio = {frozenset((names[p.first], names[p.second])) for k, p in enumerate(model.geom.collisionPairs)
                 if gdata.collisionResults[k].isCollision()}
    assert code == 0 and len(pinocchio) == 6
    assert {frozenset((c["first"], c["second"])) for c in out["contacts"]} == pinocchio
    assert cli.main(["fk", "ur5", *map(str, CONTACT_Q), "--obstacles", str(scene)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "collision" in x)
    assert "6 pairs in contact" in line and all(f"{a} and {b}" in line or f"{b} and {a}" in line
                                                for a, b in map(sorted, pinocchio))


@pytest.mark.browser
@pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                    reason="Debian's chromium is not installed here (.ci/run installs it)")
def test_the_links_in_contact_are_drawn_red_without_stripes_through_the_obstacles(tmp_path):
    """#43 item 3: the red copy of a link in contact fought for depth with the link's mesh (red and black stripes)
    and read teal or brown under the translucent floor and table. Against the same page without the red copies,
    the pixels that change are red, not dark."""
    from kinelab.view import scene as viz
    from kinelab.view.collisions import draw_collisions

    ur5 = kinelab.load("ur5")
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    pages = {}
    for red in (True, False):
        s = viz.Scene(ur5)
        draw_collisions(s, model, np.array(CONTACT_Q))
        if not red:
            s.viewer["contacts"].delete()
        (tmp_path / f"{red}.html").write_text(s.static_html())
        s.close()
        png = browser.screenshot(tmp_path / f"{red}.html", tmp_path / f"{red}.png", size=(1000, 750))
        pages[red] = np.asarray(browser.Image.open(png).convert("RGB"), dtype=int)
    changed = np.abs(pages[True] - pages[False]).max(axis=2) > 40
    r, g, b = (pages[True][..., k] for k in range(3))
    reddish = changed & (r > 150) & (r > g + 60) & (r > b + 40)
    assert changed.sum() > 5000 and reddish.sum() / changed.sum() >= 0.8, (int(changed.sum()), int(reddish.sum()))
