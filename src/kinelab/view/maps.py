"""Maps drawn: a reachability map as a meshcat point cloud over the robot, and as a matplotlib slice."""

from __future__ import annotations

import base64
import io
from typing import TYPE_CHECKING, Any

import meshcat.geometry as g
import numpy as np

from kinelab.robot import Chain
from kinelab.typing import Configuration
from kinelab.view.caption import before_body
from kinelab.view.scene import Scene, _stick_figure, chain_points

if TYPE_CHECKING:
    import meshcat

    from kinelab.maps.store import ReachabilityMap


def colours(values: np.ndarray) -> np.ndarray:
    """(3, N) RGB in [0, 1] for values in [0, 1]: red at 0, yellow at 0.5, green at 1."""
    v = np.clip(np.nan_to_num(values), 0.0, 1.0)
    return np.vstack([np.clip(2 * (1 - v), 0, 1), np.clip(2 * v, 0, 1), np.zeros_like(v)])


def reachability_cloud(robot: Chain, rmap: ReachabilityMap, q: Configuration | None = None,
                       viewer: meshcat.Visualizer | None = None,
                       meshes: bool = True) -> Scene:
    """The robot at q (default: its display pose) with the map's reached voxels as points coloured by their
    reachability index; the caption says what the colours mean.

    Args:
        robot: the map's robot.
        rmap: a :class:`~kinelab.maps.store.ReachabilityMap`.
        q: the robot's configuration [rad or m].
        viewer: a meshcat viewer to draw in (default: a new one on 127.0.0.1).
        meshes: draw the robot's meshes (False: a stick figure, which keeps a saved page small).
    """
    q = robot.display_q() if q is None else q
    scene = Scene(robot, viewer=viewer).show(q)
    scene.view = "reachability map"
    if not meshes:
        scene.drop_robot()
        _stick_figure(scene.viewer["robot"], chain_points(robot, q), scene.frame_length)
    reach = rmap.array("reachability")
    keep = reach > 0
    points = rmap.array("centres")[keep].T
    voxel = rmap.meta["spec"]["voxel"]
    scene.viewer["reachability"].set_object(g.PointCloud(points, colours(reach[keep]), size=0.25 * voxel))
    scene._aim(np.vstack([points.T, scene._points(q)]))
    scene.legend["map"] = (f"points: the {int(keep.sum())} reached voxels of {voxel:g} m, red = 1 of "
                           f"{rmap.meta['spec']['orientations']} orientations reached, green = all")
    return scene


def reachability_slice(rmap: ReachabilityMap, axis: int = 2, value: float | None = None, ax: Any = None) -> Any:
    """The reachability index on the voxel layer nearest ``value`` [m] along base axis ``axis`` (default: the
    layer through the map's centre), as a matplotlib image; returns the axes."""
    import matplotlib.pyplot as plt

    centres, reach = rmap.array("centres"), rmap.array("reachability")
    levels = np.unique(np.round(centres[:, axis], 9))
    level = levels[np.argmin(np.abs(levels - (np.median(levels) if value is None else value)))]
    layer = np.isclose(centres[:, axis], level)
    u, v = [k for k in range(3) if k != axis]
    ax = ax or plt.figure(figsize=(5, 4.2)).subplots()
    art = ax.scatter(centres[layer, u], centres[layer, v], c=reach[layer], cmap="RdYlGn", vmin=0, vmax=1,
                     marker="s", s=18)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[u]} [m]")
    ax.set_ylabel(f"{'xyz'[v]} [m]")
    ax.set_title(f"reachability index at {'xyz'[axis]} = {level:.3g} m")
    ax.figure.colorbar(art, ax=ax, label="share of orientations reached")
    return ax


SLICES_STYLE = ("position:fixed;right:10px;top:40px;width:300px;padding:6px;border-radius:6px;"
                "background:rgba(255,255,255,0.92);box-shadow:0 1px 4px rgba(0,0,0,0.3);z-index:10")


def map_page(robot: Chain, rmap: ReachabilityMap) -> str:
    """A reachability map as one self-contained page: the reached voxels in 3-D over the robot's stick figure
    (the caption says what the colours mean) and the three slices through the map's centre (x, y and z layers)
    as images in a box on the right."""
    from matplotlib.figure import Figure

    scene = reachability_cloud(robot, rmap, meshes=False)
    spec = rmap.meta["spec"]
    done, chunks = rmap.finished()
    scene.title = (f"{robot.name}: reachability map, {rmap.meta['voxels']} voxels of {spec['voxel']:g} m, "
                   f"{spec['orientations']} orientations each ({rmap.meta['solver']})"
                   + (f" — unfinished: {done} of {chunks} chunks" if done < chunks else ""))
    scene.legend["slices"] = ("right: the reachability index on the voxel layers through the map's centre, across z, "
                              "y and x (dark red: no orientation reached)")
    try:
        page = scene.static_html()
    finally:
        scene.close()
    images = []
    for axis in (2, 1, 0):
        fig = Figure(figsize=(4.2, 3.6))
        reachability_slice(rmap, axis=axis, ax=fig.subplots())
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        images.append(f'<img alt="reachability slice across {"xyz"[axis]}" style="width:100%" '
                      f'src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">')
    return before_body(page, f'<div id="kinelab-slices" style="{SLICES_STYLE}">{"".join(images)}</div>')
