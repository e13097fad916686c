"""#69: the teach page of a robot with loops in a real browser (headless Chromium over DevTools). The delta robot
starts assembled; a person drags its platform's gold ball; the page's robot then has its platform at the drawn
target by Pinocchio's own FK, every loop closed (the readout's errors and Pinocchio's frame placements), and the
page shows each loop's two ends. Cassie's left foot is dragged the same way, its four loops kept closed."""

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


def test_dragging_the_platform_moves_it_with_every_loop_closed(tmp_path):
    delta = kinelab.load("delta")
    with teach(delta) as served, open_page(served.url) as p:
        p.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(p)
        before = drawn(p, "target_0")
        p.screenshot(tmp_path / "before.png")
        x, y = p.eval("window.kinelab.handleOnScreen(0)")
        p.drag((x, y), (x + 30, y + 20))
        settle(p, drags=1)
        target = drawn(p, "target_0")
        assert np.linalg.norm(target[:3, 3] - before[:3, 3]) > 0.01  # the ball moved with the mouse
        assert np.abs(served.session.targets[0].homogeneous - target).max() < 1e-12  # solved = drawn
        q = np.array(p.eval("window.kinelab.readout.q"))
        loops = p.eval("window.kinelab.readout.loops")
        assert len(loops) == 3 and all(loop["error"] <= 1e-9 for loop in loops)
        model, data = delta.model, delta.model.createData()
        pin.framesForwardKinematics(model, data, q)
        platform = data.oMf[model.getFrameId("platform_centre")]
        assert np.linalg.norm(platform.translation - target[:3, 3]) <= 1e-6
        for c in delta.closures:  # every loop closed by Pinocchio's own placements
            aMb = data.oMf[model.getFrameId(c.frame_a)].actInv(data.oMf[model.getFrameId(c.frame_b)])
            error = np.concatenate([aMb.translation, pin.log3(aMb.rotation)])[np.flatnonzero(c.mask)]
            assert np.abs(error).max() <= 1e-9
        assert delta.within_limits(q)
        p.screenshot(tmp_path / "after.png")
        assert browser.changed_share(tmp_path / "before.png", tmp_path / "after.png") > 0.002
        assert "loops" in p.eval("document.body.innerText")  # the legend names the loops' balls


def test_dragging_cassie_s_foot_keeps_its_four_loops_closed(tmp_path):
    """Cassie (its right foot held where it stands, the pelvis free): a person drags the left foot's ball; the page's
    robot has the left foot at the drawn target by Pinocchio's own FK (1e-6 m) and its four loops closed (1e-9)."""
    cassie = kinelab.load("cassie")
    with teach(cassie) as served, open_page(served.url) as p:
        p.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(p)
        before = drawn(p, "target_0")
        x, y = p.eval("window.kinelab.handleOnScreen(0)")
        p.drag((x, y), (x + 25, y - 15))
        settle(p, drags=1)
        target = drawn(p, "target_0")
        assert np.linalg.norm(target[:3, 3] - before[:3, 3]) > 0.01
        q = np.array(p.eval("window.kinelab.readout.q"))
        loops = p.eval("window.kinelab.readout.loops")
        assert len(loops) == 4 and all(loop["error"] <= 1e-9 for loop in loops)
        model, data = cassie.model, cassie.model.createData()
        pin.framesForwardKinematics(model, data, q)
        foot = data.oMf[model.getFrameId("left-foot", pin.FrameType.BODY)]
        assert np.linalg.norm(foot.translation - target[:3, 3]) <= 1e-6
        assert np.abs(cassie.closure_error(q)).max() <= 1e-9 and cassie.within_limits(q)
