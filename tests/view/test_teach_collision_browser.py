"""#70: the teach page of a whole robot with an obstacle, in a real browser (headless Chromium over DevTools).
Baxter's left gripper hangs 2.6 cm over a crate; a person drags its gold ball down into the crate; the page's robot
then stops with its nearest part at the margin from the crate (the readout's distance, and coal's own distance at
the readout's q), every other pair clear, the crate drawn."""

import os

import browser
import numpy as np
import pinocchio as pin
import pytest
from devtools import open_page
from test_teach_browser import drawn, settle

import kinelab
from kinelab import Collisions, Environment, Obstacle
from kinelab.view.teach import TeachOptions, teach
from kinelab.wholebody.clearance import step_collisions

pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                                 reason="Debian's chromium is not installed here (.ci/run installs it)")]

MARGIN = 0.02
CRATE = Environment((Obstacle("box", (0.3, 0.3, 0.1), xyz=(0.9, 1.1, 0.185), name="crate"),))  # top at 0.235 m


def test_a_hand_dragged_into_a_crate_stops_at_the_margin(tmp_path):
    baxter = kinelab.load("baxter")
    spec = Collisions(environment=CRATE, margin=MARGIN)
    found = step_collisions(baxter, spec)
    options = TeachOptions(time_budget=5.0, collisions=spec)
    with teach(baxter, options=options) as served, open_page(served.url) as p:
        p.wait_for("window.kinelab && window.kinelab.ready", 90)
        settle(p)
        before = drawn(p, "target_0")
        p.screenshot(tmp_path / "before.png")
        x, y = p.eval("window.kinelab.handleOnScreen(0)")
        p.drag((x, y), (x, y + 30))
        settle(p, drags=1)
        target = drawn(p, "target_0")
        assert before[2, 3] - target[2, 3] > 0.1  # the ball went down, into the crate
        q = np.array(p.eval("window.kinelab.readout.q"))
        nearest = p.eval("window.kinelab.readout.nearest")
        assert nearest["second"] == "crate" and abs(nearest["distance_m"] - MARGIN) <= 1e-3
        data = baxter.model.createData()
        pin.forwardKinematics(baxter.model, data, q)
        distances = [r.min_distance for r in found.distances(data, np.arange(len(found.pairs)))]
        assert min(distances) >= MARGIN - 1e-6  # every pair clear, by coal at the page's q
        assert baxter.within_limits(q)
        text = p.eval("document.body.innerText")
        assert "crate" in text and "held off" in text
        p.screenshot(tmp_path / "after.png")
        assert browser.changed_share(tmp_path / "before.png", tmp_path / "after.png") > 0.002
