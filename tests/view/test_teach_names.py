"""#57 item 2: the teach page shows every name a robot file supplies as text, never as markup. The file
tests/hostile/markup_names.urdf names its robot, joints and links with markup whose handlers would set
``window.__pwned``; on aadeea0 the sliders' labels were built with innerHTML and the joint's handler ran."""

import os
from pathlib import Path

import browser
import pytest
from devtools import open_page

import kinelab
from kinelab.view.teach import TeachOptions, teach

HOSTILE = Path(__file__).parents[1] / "hostile" / "markup_names.urdf"

pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                                 reason="Debian's chromium is not installed here (.ci/run installs it)")]


def test_names_that_are_markup_are_shown_as_text_and_add_no_element():
    robot = kinelab.load(HOSTILE, tool="tool")
    # a box through both links: with collisions on, the contacts readout names the links
    wall = kinelab.Environment((kinelab.Obstacle("box", (0.5, 0.5, 0.1), xyz=(0.0, 0.0, 0.3), name="<u>wall</u>"),))
    with teach(robot, q=[0.1, 0.2], options=TeachOptions(collisions=kinelab.Collisions(environment=wall))) as served, \
            open_page(served.url) as page:
        page.wait_for("window.kinelab && window.kinelab.ready", 90)
        served.session.set_collisions(True)
        page.wait_for("document.getElementById('kinelab-readout').textContent.includes('wall')", 30)
        assert page.eval("window.__pwned === undefined")
        labels = page.eval("[...document.querySelectorAll('#kinelab-joints .joint > span:first-child')]"
                           ".map((s) => s.textContent)")
        assert labels == robot.joint_names
        assert page.eval("document.querySelectorAll('img, b, i, u').length") == 0
        assert page.eval("document.getElementById('kinelab-heading').textContent") == f"kinelab teach — {robot.name}"
        assert page.eval("document.title") == f"{robot.name} · teach — kinelab"
        contacts = page.eval("document.getElementById('kinelab-readout').textContent")
        assert "<u>wall</u>" in contacts and ("<b>l2</b>" in contacts or "onerror" in contacts)
        assert page.eval("document.querySelectorAll('script').length") == 3  # the config, meshcat's and teach.js
