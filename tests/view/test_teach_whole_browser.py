"""#59: the teach page of a whole robot in a real browser (headless Chromium over DevTools). TALOS stands on its
feet; a person drags its left hand's gold ball, then its right hand's; the page's robot must then meet both drawn
targets by Pinocchio's own FK, its feet where they stood and its centre of mass over them."""

import os

import browser
import numpy as np
import pinocchio as pin
import pytest
from devtools import open_page
from test_teach_browser import drawn, settle

import kinelab
from kinelab.view.teach import teach

pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                                 reason="Debian's chromium is not installed here (.ci/run installs it)")]


@pytest.fixture(scope="module")
def page():
    talos = kinelab.load("talos")
    with teach(talos) as served, open_page(served.url) as opened:
        opened.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(opened)
        yield talos, served, opened


def pinocchio_frames(robot, q, names):
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q))
    return [data.oMf[model.getFrameId(n)] for n in names], pin.centerOfMass(model, data, np.asarray(q))


def test_dragging_both_hands_moves_them_and_the_robot_meets_both_by_pinocchio_s_fk(page, tmp_path):
    talos, served, p = page
    before = [drawn(p, f"target_{k}") for k in range(2)]
    start_q = np.array(p.eval("window.kinelab.readout.q"))
    feet_before, com_before = pinocchio_frames(talos, start_q, talos.feet)
    p.screenshot(tmp_path / "before.png")
    for k, (dx, dy) in enumerate(((-30, -25), (30, -20))):
        x, y = p.eval(f"window.kinelab.handleOnScreen({k})")
        p.drag((x, y), (x + dx, y + dy))
        settle(p, drags=k + 1)
    targets = [drawn(p, f"target_{k}") for k in range(2)]
    for k in range(2):
        assert np.linalg.norm(targets[k][:3, 3] - before[k][:3, 3]) > 0.02  # each ball moved with the mouse
        assert np.abs(served.session.targets[k].homogeneous - targets[k]).max() < 1e-12  # solved = drawn
    q = np.array(p.eval("window.kinelab.readout.q"))
    hands, com = pinocchio_frames(talos, q, talos.hands)
    for M, T in zip(hands, targets, strict=True):
        assert np.linalg.norm(M.translation - T[:3, 3]) <= 1e-6
        assert np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3])) <= 1e-6
    feet, _ = pinocchio_frames(talos, q, talos.feet)
    for M, F in zip(feet, feet_before, strict=True):
        assert np.linalg.norm(pin.log6(M.actInv(F)).vector) <= 1e-6  # the feet stayed where they stood
    assert np.linalg.norm(com[:2] - com_before[:2]) <= 1e-6 and p.eval("window.kinelab.readout.com_over_support")
    assert talos.within_limits(q)
    p.screenshot(tmp_path / "after.png")
    assert browser.changed_share(tmp_path / "before.png", tmp_path / "after.png") > 0.002


def test_a_whole_robot_page_hides_what_it_does_not_do(page):
    _, _, p = page
    for element in ("kinelab-prev", "kinelab-next", "kinelab-collisions-label"):
        assert p.eval(f"document.getElementById('{element}').hidden")
    assert p.eval("document.getElementById('kinelab-snap').textContent") == "targets to hands"
    assert p.eval("document.title") == "talos · teach — kinelab"
