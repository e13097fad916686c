"""The teach page in a real browser (headless Chromium over DevTools), used as a person would: move a joint's
slider with the mouse, drag the target's ball, Shift+drag it to turn it, click for the next branch; what the page
then draws is checked against Pinocchio's FK."""

import os

import browser
import numpy as np
import pinocchio as pin
import pytest
from devtools import open_page
from helpers import lowest_part, pinocchio_tool

import kinelab
from kinelab.view.teach import teach

START = [0.3, -1.2, 1.4, -0.8, 1.2, 0.2]
SHIFT = 8  # the DevTools protocol's modifier bit for Shift

pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                                 reason="Debian's chromium is not installed here (.ci/run installs it)")]


def drawn(page, name):
    """A frame's pose as the page draws it (base frame, 4 × 4)."""
    return np.array(page.eval(f"window.kinelab.drawnPose('{name}')")).reshape(4, 4)


def settle(page, drags=None):
    """Wait until the page has no request in flight (and has seen ``drags`` drags end)."""
    check = "window.kinelab.idle()" + ("" if drags is None else f" && window.kinelab.drags === {drags}")
    page.wait_for(check)
    page.eval("new Promise((done) => setTimeout(done, 300))")  # a poll or reply already on its way lands
    page.wait_for("window.kinelab.idle()")


def assert_drawn_tool_is_pinocchio_fk(page, robot):
    q = page.eval("window.kinelab.readout.q")
    assert np.abs(drawn(page, "tool") - pinocchio_tool(robot, q).homogeneous).max() < 1e-9
    return np.array(q)


def assert_meets(robot, q, target):
    oMtool = pinocchio_tool(robot, q)
    assert np.linalg.norm(oMtool.translation - target[:3, 3]) <= 1e-6
    assert np.linalg.norm(pin.log3(oMtool.rotation.T @ target[:3, :3])) <= 1e-6
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper)


@pytest.fixture(scope="module")
def page():
    robot = kinelab.load("ur5")
    with teach(robot, q=START) as served, open_page(served.url) as opened:
        opened.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(opened)
        yield robot, served, opened


def test_the_tab_names_the_robot_and_the_view(page):
    _, _, p = page
    assert p.eval("document.title") == "ur5 · teach — kinelab"


def test_moving_a_slider_moves_that_joint_and_the_drawn_tool_to_pinocchio_s_fk(page):
    robot, served, p = page
    before = np.array(p.eval("window.kinelab.readout.q"))
    left, top, width, height = p.eval("(() => { const r = document.getElementById('kinelab-joint-1')"
                                      ".getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()")
    frac = (before[1] - robot.lower[1]) / (robot.upper[1] - robot.lower[1])
    y = top + height / 2
    p.drag((left + 8 + frac * (width - 16), y), (left + 8 + (frac + 0.06) * (width - 16), y), steps=6)
    settle(p)
    q = assert_drawn_tool_is_pinocchio_fk(p, robot)
    assert q[1] == pytest.approx(float(p.eval("Number(document.getElementById('kinelab-joint-1').value)")), abs=1e-12)
    assert 0.3 < q[1] - before[1] < 1.5 and np.array_equal(np.delete(q, 1), np.delete(before, 1))
    assert np.array_equal(served.session.q, q)


def test_dragging_the_target_moves_it_and_the_robot_meets_it(page, tmp_path):
    robot, served, p = page
    p.eval("document.getElementById('kinelab-snap').click()")
    settle(p)
    before = drawn(p, "target")
    p.screenshot(tmp_path / "before.png")
    x, y = p.eval("window.kinelab.handleOnScreen()")
    p.drag((x, y), (x + 70, y - 50))
    settle(p, drags=1)
    target = drawn(p, "target")
    assert np.linalg.norm(target[:3, 3] - before[:3, 3]) > 0.02  # the ball moved with the mouse
    assert np.allclose(target[:3, :3], before[:3, :3], atol=1e-12)  # a plain drag does not turn it
    assert np.abs(served.session.target.homogeneous - target).max() < 1e-12  # what was solved is what is drawn
    q = assert_drawn_tool_is_pinocchio_fk(p, robot)
    assert_meets(robot, q, target)
    p.screenshot(tmp_path / "after.png")
    assert browser.changed_share(tmp_path / "before.png", tmp_path / "after.png") > 0.005


def test_shift_dragging_turns_the_target_and_the_robot_meets_it(page):
    robot, _, p = page
    before = drawn(p, "target")
    x, y = p.eval("window.kinelab.handleOnScreen()")
    p.drag((x, y), (x + 25, y + 15), modifiers=SHIFT)
    settle(p, drags=2)
    target = drawn(p, "target")
    turned = np.linalg.norm(pin.log3(before[:3, :3].T @ target[:3, :3]))
    assert 0.1 < turned < 1.0 and np.allclose(target[:3, 3], before[:3, 3], atol=1e-12)
    assert_meets(robot, assert_drawn_tool_is_pinocchio_fk(p, robot), target)


def test_a_reply_overtaken_by_a_newer_one_draws_nothing_old(page):
    """A poll sent before a drag's answer and answered after it carried the older state: drawn last, the tool
    stood where the arm had been while the readout gave the new q (seen once as a 1 cm gap under load)."""
    robot, _, p = page
    old_seq = p.eval("fetch('state?since=0').then((r) => r.json()).then((j) => { window.kinelab.old = j; "
                     "return j.seq; })")
    p.eval("(() => { const s = document.getElementById('kinelab-joint-2'); s.value = Number(s.value) - 0.3; "
           "s.dispatchEvent(new Event('input')); })()")
    settle(p)
    assert p.eval("window.kinelab.seq") > old_seq
    now = drawn(p, "tool")
    p.eval("window.kinelab.apply(window.kinelab.old)")
    assert np.abs(drawn(p, "tool") - now).max() == 0.0
    assert_drawn_tool_is_pinocchio_fk(p, robot)


def test_the_branch_button_goes_to_another_branch_of_the_same_target(page):
    robot, _, p = page
    target, before = drawn(p, "target"), np.array(p.eval("window.kinelab.readout.q"))
    for _ in range(2):  # the first branch is the one nearest where the robot stands: itself
        x, y = p.eval("(() => { const r = document.getElementById('kinelab-next').getBoundingClientRect(); "
                      "return [r.left + r.width / 2, r.top + r.height / 2]; })()")
        p.mouse("mousePressed", x, y)
        p.mouse("mouseReleased", x, y, buttons=0)
        settle(p)
    q = assert_drawn_tool_is_pinocchio_fk(p, robot)
    assert np.abs(q - before).max() > 1e-3
    assert_meets(robot, q, target)
    assert p.eval("window.kinelab.readout.status").startswith("branch 2 of ")


def test_without_a_start_the_page_opens_at_a_well_conditioned_pose_and_says_so():
    """#60 item 1: `kinelab teach ur5` opened at all zeros, "σ_min 1.473e-17 — singular: rank 5 of 6"."""
    ur5 = kinelab.load("ur5")
    with teach(ur5) as served, open_page(served.url) as p:
        p.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(p)
        r = p.eval("window.kinelab.readout")
        assert r["rank"] == r["full_rank"] == 6
        shown = p.eval("document.getElementById('kinelab-readout').textContent")
        assert "singular" not in shown
        assert "well-conditioned" in p.eval("document.getElementById('kinelab-legend').textContent")


def test_the_ur5_page_starts_with_every_link_above_the_floor():
    """#72 item 3: teach without a start. The page's robot (its readout's q, drawn: its tool where Pinocchio puts
    it) has every moving frame and link shape on or above the floor plane by Pinocchio's placements; on f5b077e its
    wrist was at z = −0.176 m, through the floor grid."""
    robot = kinelab.load("ur5")
    with teach(robot) as served, open_page(served.url) as p:
        p.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(p)
        q = assert_drawn_tool_is_pinocchio_fk(p, robot)
        assert np.array_equal(served.session.q, q)
        assert lowest_part(robot, q) >= -1e-9
