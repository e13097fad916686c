"""#69 and #72: ``kinelab view`` of a whole robot. TALOS stands on the floor (its soles at z = 0, every joint and
visual above it) and fills the picture without leaving it; a robot with loops is drawn with them closed, each
loop's two ends drawn; a chain's flags are refused in one line."""

import os

import browser
import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import cli
from kinelab.view.whole_scene import WholeScene

CHROMIUM = browser.find_chromium()


def test_a_humanoid_stands_on_the_floor_and_every_part_is_above_it():
    talos = kinelab.load("talos")
    scene = WholeScene(talos)
    try:
        soles = [M.translation[2] for M in talos.frame_placements(scene.q, talos.feet)]
        assert abs(min(soles)) <= 1e-9 and scene.floor() == pytest.approx(min(soles), abs=1e-12)
        assert scene.points()[:, 2].min() >= -0.02  # a sole's own mesh may reach 2 cm under its frame, no more
        assert "floor grid" in " ".join(scene.legend.values())
    finally:
        scene.close()


@pytest.mark.parametrize("name", ["delta", "fourbar", "cassie"])
def test_a_robot_with_loops_is_drawn_with_every_loop_closed_and_its_ends_drawn(name):
    robot = kinelab.load(name)
    scene = WholeScene(robot)
    try:
        model, data = robot.model, robot.model.createData()
        pin.framesForwardKinematics(model, data, scene.q)
        for c in robot.closures:  # closed by Pinocchio's own placements
            aMb = data.oMf[model.getFrameId(c.frame_a)].actInv(data.oMf[model.getFrameId(c.frame_b)])
            error = np.concatenate([aMb.translation, pin.log3(aMb.rotation)])[np.flatnonzero(c.mask)]
            assert np.abs(error).max() <= 1e-9
        paths = browser.scene_paths(scene.static_html())
        for k in range(len(robot.closures)):
            assert {f"/meshcat/loops/loop_{k}/a", f"/meshcat/loops/loop_{k}/b"} <= paths
        assert not any(p.endswith("/gap") for p in paths)  # no loop drawn open
    finally:
        scene.close()


def test_a_file_without_visual_geometry_is_drawn_with_its_collision_geometry():
    """kinelab's Cassie has capsules for collision and no visual geometry: the scene draws its 23 capsules and
    spheres instead of nothing."""
    robot = kinelab.load("cassie")
    assert robot.visual_model().ngeoms == 0 and robot.visual_model("collision").ngeoms == 23
    scene = WholeScene(robot)
    try:
        assert scene.pinviz.visual_model.ngeoms == 23
        paths = browser.scene_paths(scene.static_html())
        assert sum(p.startswith("/meshcat/cassie/") for p in paths) >= 23
    finally:
        scene.close()


def test_the_command_draws_a_whole_robot_and_refuses_a_chain_s_flags(capsys, tmp_path):
    page = tmp_path / "delta.html"
    assert cli.main(["view", "delta", "--html", str(page)]) == 0
    out = capsys.readouterr().out
    assert page.stat().st_size > 10_000 and "3 loops" in out
    for flags, words in ((["--collisions"], "--collisions is a chain's"), (["--singular"], "--singular is a chain's"),
                         (["0.1", "x"], "'x' is not a number")):
        code = cli.main(["view", "talos", *flags, "--html", str(tmp_path / "t.html")])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1 and words in err[0], (flags, err)


@pytest.mark.browser
@pytest.mark.skipif(CHROMIUM is None and not os.environ.get("CI"),
                    reason="Debian's chromium is not installed here (.ci/run installs it)")
def test_the_whole_humanoid_is_in_the_picture(tmp_path):
    """The page's picture: the robot (what differs from the page without it) inside the frame, top to bottom with
    room left at both edges, and tall (a standing humanoid, not a speck)."""
    talos = kinelab.load("talos")
    scene = WholeScene(talos)
    try:
        page = tmp_path / "talos.html"
        scene.save_html(page)
        empty = tmp_path / "empty.html"
        empty.write_text(browser.without_robot_html(scene))
        with_robot = browser.screenshot(page, tmp_path / "with.png", size=(1280, 960))
        without = browser.screenshot(empty, tmp_path / "without.png", size=(1280, 960))
    finally:
        scene.close()
    box = browser.changed_box(with_robot, without)
    assert box is not None
    top, bottom, left, right = box
    assert top > 5 and bottom < 955 and left > 5 and right < 1275, box
    assert bottom - top > 0.5 * 960, box
