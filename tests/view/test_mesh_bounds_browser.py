"""#60 item 2: meshes as their files draw them. The UR5's COLLADA parts lost their places on the way to the page
(blue end caps floating beside the joints). In a real browser (headless Chromium over DevTools), each visual
mesh's bounding box on the page, in its own node's frame, must equal the file's scene bounds as trimesh reads them
(node transforms applied), to 1 mm, on ur5, panda, kinova and talos."""

import json
import os

import browser
import numpy as np
import pytest
import trimesh
from devtools import open_page

import kinelab
from kinelab.view import Scene

pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(browser.find_chromium() is None and not os.environ.get("CI"),
                                 reason="Debian's chromium is not installed here (.ci/run installs it)")]

# every mesh under a node: its box in that node's frame (the node's placement and scale undone: the file's units)
# and its colour (null for several materials on one mesh)
NODE_PARTS = """
(paths => paths.map(path => {
  const node = viewer.scene_tree.find(path.split('/').filter(s => s)).object;
  node.updateMatrixWorld(true);
  const inv = node.matrixWorld.clone().invert(), v = node.position.clone(), parts = [];  // THREE is no global
  node.traverse(o => {
    if (!o.isMesh || !o.geometry || !o.geometry.attributes.position) return;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    const m = inv.clone().multiply(o.matrixWorld), pos = o.geometry.attributes.position;
    for (let i = 0; i < pos.count; i++) {
      v.fromBufferAttribute(pos, i).applyMatrix4(m).toArray().forEach((x, k) => {
        lo[k] = Math.min(lo[k], x); hi[k] = Math.max(hi[k], x); });
    }
    parts.push([lo, hi, Array.isArray(o.material) ? null : o.material.color.getHex()]);
  });
  return parts;
}))(%s)
"""


def file_parts(path):
    """Each part of a mesh file as trimesh reads it: (bounds (2, 3) with its node transform applied, colour
    0xRRGGBB of its own material or None)."""
    scene = trimesh.load(path, force="scene")
    parts = []
    for node in scene.graph.nodes_geometry:
        oMpart, name = scene.graph[node]
        mesh = scene.geometry[name].copy()
        mesh.apply_transform(oMpart)
        rgba = getattr(getattr(mesh.visual, "material", None), "main_color", None)
        parts.append((mesh.bounds, None if rgba is None else (int(rgba[0]) << 16) | (int(rgba[1]) << 8)
                      | int(rgba[2])))
    return parts


def same_colour(a, b):
    return a is not None and all(abs(((a >> s) & 255) - ((b >> s) & 255)) <= 2 for s in (0, 8, 16))


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova", "talos_left"])
def test_each_part_of_each_visual_mesh_is_on_the_page_where_and_as_its_file_draws_it(name, tmp_path):
    robot = kinelab.load(name)
    scene = Scene(robot)
    try:
        page = tmp_path / f"{name}.html"
        scene.save_html(page)
        meshes = [(obj.meshPath, "/meshcat/" + path) for obj, path in zip(scene.geom.geometryObjects,
                                                                         scene.node_paths(), strict=True)
                  if os.path.isfile(obj.meshPath)]
    finally:
        scene.close()
    assert len(meshes) >= 7
    with open_page(page.as_uri()) as p:
        p.wait_for("typeof viewer !== 'undefined' && viewer.scene_tree !== undefined", 60)
        drawn = p.wait_for(f"(d => d.every(x => x.length > 0) && d)({NODE_PARTS % json.dumps([m[1] for m in meshes])})",
                           60)
    for (mesh_path, node), on_page in zip(meshes, drawn, strict=True):
        expected = file_parts(mesh_path)
        assert len(on_page) == len(expected), (node, mesh_path, len(on_page), len(expected))
        for bounds, colour in expected:
            assert any(np.abs(np.array([lo, hi]) - bounds).max() <= 1e-3
                       and (colour is None or same_colour(page_colour, colour))
                       for lo, hi, page_colour in on_page), (node, mesh_path, bounds.tolist(), colour, on_page)
