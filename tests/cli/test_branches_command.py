"""``kinelab branches``: every branch of a pose on the command line, checked against Pinocchio's FK."""

import json
import os

import numpy as np
import pytest
from browser import find_chromium, scene_paths, screenshot

import kinelab
from kinelab import cli

UR5_Q = ["0.3", "-1.2", "1.0", "-0.5", "0.8", "0.2"]
CRX_SIXTEEN = ["-2.57382778", "1.29186362", "-0.93753732", "-2.98766846", "-2.72802256", "-1.92793594"]


def run(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_every_branch_of_a_ur5_pose_is_printed_nearest_first_and_each_meets_the_pose(capsys):
    ur5 = kinelab.load("ur5")
    target = ur5.fk(np.array(UR5_Q, dtype=float))
    code, out, _ = run(capsys, "branches", "ur5", "--target-q", *UR5_Q, "--ref-q", *UR5_Q, "--json")
    found = json.loads(out)
    assert code == 0 and len(found["branches"]) == 8
    assert found["completeness"] == "every branch: closed form (complete: certified)"
    assert found["complete"] == "certified" and found["complete_reason"] == ""
    qs = np.array([b["q"] for b in found["branches"]])
    assert np.abs(qs[0] - np.array(UR5_Q, dtype=float)).max() <= 1e-9  # the reference itself is a branch: first
    for q in qs:
        assert max(ur5.tool_error(q, target)) <= 1e-9
    assert len({tuple(np.round(q, 6)) for q in qs}) == 8
    code, out, _ = run(capsys, "branches", "ur5", "--target-q", *UR5_Q, "--ref-q", *UR5_Q)
    lines = out.splitlines()
    assert code == 0 and lines[0].startswith("ur5: 8 branches, analytic") and "nearest --ref-q first" in out
    rows = [line.split() for line in lines if line.strip()[:2].strip().isdigit()]
    assert [int(r[0]) for r in rows] == list(range(1, 9))
    np.testing.assert_allclose([float(v) for v in rows[0][4:10]], np.array(UR5_Q, dtype=float), atol=1e-4)


def test_a_crx_pose_prints_its_sixteen_searched_branches(capsys):
    code, out, _ = run(capsys, "branches", "crx10ia", "--target-q", *CRX_SIXTEEN, "--json")
    found = json.loads(out)
    assert code == 0 and len(found["branches"]) == 16 and "1-D search over joint 6" in found["method"]
    assert "search" in found["completeness"]
    crx = kinelab.load("crx10ia")
    target = crx.fk(np.array(CRX_SIXTEEN, dtype=float))
    assert all(max(crx.tool_error(np.array(b["q"]), target)) <= 1e-9 for b in found["branches"])


PANDA_Q = ["0.4", "-0.6", "0.3", "-2.0", "0.5", "1.6", "0.7"]


def test_every_branch_at_a_panda_poses_own_sew_angle_includes_its_configuration(capsys):
    panda = kinelab.load("panda")
    q = np.array(PANDA_Q, dtype=float)
    psi = kinelab.sew_angle(panda, q)
    degrees = [f"{v:.12f}" for v in np.degrees(q)]
    code, out, _ = run(capsys, "branches", "panda", "--target-q", *degrees, "--sew", f"{np.degrees(psi):.12f}",
                       "--deg", "--json")
    found = json.loads(out)
    assert code == 0 and "SEW angle" in found["method"] and found["complete"] == "search"
    qs = np.array([b["q"] for b in found["branches"]])  # the JSON is in radians
    assert np.abs(qs - q).max(axis=1).min() < 1e-6
    for row in qs:
        assert max(panda.tool_error(row, panda.fk(q))) <= 1e-6
        assert abs(kinelab.sew_angle(panda, row) - psi) <= 1e-6


def test_an_unreachable_pose_exits_1_and_bad_input_exits_2_with_one_line(capsys):
    code, out, _ = run(capsys, "branches", "ur5", "--target-xyz", "5", "0", "0")
    assert code == 1 and out.startswith("ur5: 0 branches") and "no branch (unreachable)" in out \
        and "beyond the robot's reach" in out
    for argv in (("branches", "ur5"), ("branches", "ur5", "--target-q", "1", "2"),
                 ("branches", "ur5", "--target-q", *UR5_Q, "--redundancy", "8"),
                 ("branches", "ur5", "--target-q", *UR5_Q, "--sew", "0.5"),
                 ("branches", "panda", "--target-q", *PANDA_Q, "--sew", "0.5", "--redundancy", "8"),
                 ("branches", "panda", "--target-q", *PANDA_Q, "--sew", "nan"),
                 ("branches", "stanford", "--target-q", "0", "0", "0.3", "0", "0", "0", "--solver", "analytic")):
        code, out, err = run(capsys, *argv)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, argv


def test_the_page_draws_every_branch_and_names_the_nearest(capsys, tmp_path):
    page = tmp_path / "b.html"
    code, out, _ = run(capsys, "branches", "ur5", "--target-q", *UR5_Q, "--ref-q", *UR5_Q, "--html", str(page))
    assert code == 0 and f"wrote {page}" in out
    html = page.read_text()
    assert "orange joints: branch 1 (nearest --ref-q)" in html
    assert "<title>ur5 · branches — kinelab</title>" in html  # the tab names the robot and the view
    assert {f"/meshcat/branches/{k}/joint0" for k in range(1, 9)} <= scene_paths(html)


@pytest.mark.browser
@pytest.mark.skipif(find_chromium() is None and not os.environ.get("CI"),
                    reason="no chromium on PATH (Debian: apt-get install chromium)")
def test_the_nearest_branch_is_orange_in_the_browser(capsys, tmp_path):
    """The highlighted copy is drawn in orange: the page with --ref-q has orange pixels, the page without none."""
    with_ref, without = tmp_path / "ref.html", tmp_path / "plain.html"
    run(capsys, "branches", "ur5", "--target-q", *UR5_Q, "--ref-q", *UR5_Q, "--html", str(with_ref))
    run(capsys, "branches", "ur5", "--target-q", *UR5_Q, "--html", str(without))
    from PIL import Image

    a = screenshot(with_ref, tmp_path / "ref.png", size=(1200, 900))
    b = screenshot(without, tmp_path / "plain.png", size=(1200, 900))

    def orange(png):
        rgb = np.asarray(Image.open(png).convert("RGB"), dtype=int)
        return int(((rgb[..., 0] > 180) & (rgb[..., 1] > 80) & (rgb[..., 1] < 170) & (rgb[..., 2] < 90)).sum())

    # the gold target mark over a tool frame's red axis blends to a few orange pixels; a highlighted copy, hundreds
    assert orange(a) > 200 and orange(b) < 60


@pytest.mark.parametrize("name", ["baxter_left", "tiago_pro"])
def test_the_wording_of_no_branch_follows_the_status(capsys, name):
    """#39 item 6b: "out of reach" only where something proved it. A reachable pose of a multistart arm gets
    branches; starved of time it says the budget ran out, not that the pose is unreachable."""
    robot = kinelab.load(name)
    q = [f"{v:.9f}" for v in robot.random_q(np.random.default_rng(12))]
    code, out, _ = run(capsys, "branches", name, "--target-q", *q, "--seed", "0", "--json")
    found = json.loads(out)
    assert code == 0 and found["branches"]
    for b in found["branches"]:
        assert max(robot.tool_error(np.array(b["q"]), robot.fk(np.array(q, dtype=float)))) <= 1e-6
    code, out, _ = run(capsys, "branches", name, "--target-q", *q, "--seed", "0", "--time-budget", "0.0001")
    assert code == 1 and "no branch (time_budget)" in out and "unreachable" not in out


def test_the_page_numbers_each_branch_in_the_scene_marks_the_target_and_tables_the_joints(capsys, tmp_path):
    """#43 item 4: the page numbers each copy in the scene as the caption's table does (from 1), marks the
    target's point at every copy, spaces the copies so that no two footprints meet, and tables every branch's
    joints (degrees with --deg), the nearest --ref-q first and marked with its distance."""
    import html as markup
    import re

    page = tmp_path / "b.html"
    q_target = np.array(UR5_Q, dtype=float)
    deg = [f"{v:.12g}" for v in np.rad2deg(q_target)]
    code, _, _ = run(capsys, "branches", "ur5", "--target-q", *deg, "--ref-q", *deg, "--deg", "--html", str(page))
    text = page.read_text()
    paths = scene_paths(text)
    ur5 = kinelab.load("ur5")
    found = kinelab.solve_all(ur5, ur5.fk(q_target), q_ref=q_target)
    count = len(found)
    assert code == 0 and count >= 4
    numbered = {str(k) for k in range(1, count + 1)}
    assert {p.split("/")[3] for p in paths if p.startswith("/meshcat/numbers/")} == numbered
    assert {p.split("/")[3] for p in paths if p.startswith("/meshcat/targets/")} == numbered
    table = text[text.index('id="kinelab-table"'):text.index("</table>")]
    rows = [[markup.unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
            for row in re.findall(r"<tr[^>]*>(.*?)</tr>", table)[1:]]
    assert len(rows) == count and [r[0] for r in rows] == [str(k) for k in range(1, count + 1)]
    assert "q1 [deg]" in table and 'background:#fbd3b0' in table.split("</tr>")[1]  # row 1 marked
    for r, branch in zip(rows, found, strict=True):
        assert np.allclose([float(v) for v in r[1:7]], np.rad2deg(branch.q), atol=1e-4)
    assert float(rows[0][-1]) == pytest.approx(0.0, abs=1e-4) and all(float(r[-1]) > 0 for r in rows[1:])


def test_copies_side_by_side_never_overlap():
    """No joint of one copy comes near a joint of another (horizontally, as seen from above): read from the
    transforms the page itself carries."""
    import base64
    import re

    import umsgpack

    from kinelab.view import scene as viz

    ur5 = kinelab.load("ur5")
    found = kinelab.solve_all(ur5, ur5.fk(np.array([0.3, -1.0, 1.2, 0.2, 0.9, 0.1])))
    s = viz.side_by_side(ur5, [b.q for b in found])
    page = s.static_html()
    s.close()
    copies: dict[str, list] = {}
    for blob in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", page):
        cmd = umsgpack.unpackb(base64.b64decode(blob))
        if not isinstance(cmd, dict) or cmd.get("type") != "set_transform":
            continue
        match = re.fullmatch(r"/meshcat/branches/(\d+)/joint\d+", cmd.get("path", ""))
        if match:
            copies.setdefault(match.group(1), []).append(np.asarray(cmd["matrix"], dtype=float)[12:14])
    assert len(copies) == len(found) >= 4
    nearest = min(float(np.min(np.linalg.norm(np.array(a)[:, None] - np.array(b)[None], axis=2)))
                  for i, a in copies.items() for j, b in copies.items() if i < j)
    assert nearest > 0.1 * s._reach, (nearest, s._reach)


@pytest.mark.browser
@pytest.mark.skipif(find_chromium() is None and not os.environ.get("CI"),
                    reason="no chromium on PATH (Debian: apt-get install chromium)")
def test_the_caption_and_its_table_cover_no_copy(capsys, tmp_path):
    """The README's CRX-10iA pose, eight branches, at 1280 × 900: every drawn part of every copy lands on the scene's
    pane and outside the caption (its column held the table over copies 7 and 8)."""
    from devtools import open_page

    page = tmp_path / "b.html"
    crx = ["0.3", "0.5", "0.2", "0.4", "0.6", "0.1"]
    code, _, _ = run(capsys, "branches", "crx10ia", "--target-q", *crx, "--ref-q", *crx, "--html", str(page))
    assert code == 0
    where = """(() => {
      const cap = document.getElementById("kinelab-caption").getBoundingClientRect();
      const pane = viewer.renderer.domElement.getBoundingClientRect();
      viewer.render();
      const out = [];
      for (let k = 1; k <= 8; k++) {
        viewer.scene_tree.find(["meshcat", "branches", String(k)]).object.traverse((o) => {
          if (!o.isMesh) return;
          const p = o.getWorldPosition(new MeshCat.THREE.Vector3()).project(viewer.camera);
          const x = pane.left + (p.x + 1) / 2 * pane.width, y = pane.top + (1 - p.y) / 2 * pane.height;
          out.push([k, x >= pane.left && x <= pane.right && y >= pane.top && y <= pane.bottom,
                    x >= cap.left && x <= cap.right && y >= cap.top && y <= cap.bottom]);
        });
      }
      return out;
    })()"""
    with open_page(page.resolve().as_uri(), size=(1280, 900)) as p:
        p.wait_for("typeof viewer !== 'undefined' && viewer.scene_tree.find(['meshcat', 'branches', '8', 'joint0'])"
                   ".object.children.length > 0", 60)
        parts = p.eval(where)
    assert {k for k, _, _ in parts} == set(range(1, 9)) and len(parts) > 8 * 7
    assert [k for k, on_pane, _ in parts if not on_pane] == []
    assert [k for k, _, under_caption in parts if under_caption] == []
