"""meshcat scenes: a robot at q, tool and target frames, joint-trajectory animations with the tool path,
singularity overlays, and self-contained static HTML.

A :class:`Scene` owns a meshcat viewer (its zmq and web servers listen on 127.0.0.1 only) and draws
through Pinocchio's MeshcatVisualizer, so meshes resolve with the loader's ``package://`` logic and the
bundled robots draw their primitive shapes. Nothing opens a browser unless asked (``open=False``).
"""

from __future__ import annotations

import contextlib
import html
import io
from pathlib import Path
from typing import Any

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin
from meshcat.animation import Animation
from pinocchio.visualize import MeshcatVisualizer

from kinelab.analysis.singular import analyze
from kinelab.analysis.singular import sigma_words as sigma_words  # the page's words are `kinelab singular`'s
from kinelab.errors import ConfigurationError
from kinelab.files import write_output
from kinelab.robot import Chain
from kinelab.robot.poses import NEAR_SINGULAR
from kinelab.typing import Configuration
from kinelab.view.caption import Table, tab_title, titled, with_caption
from kinelab.view.framing import FILL, frame_points
from kinelab.view.labels import draw_number
from kinelab.view.meshes import load_robot
from kinelab.view.server import Server

SPREAD_FILL = 1.1  # side-by-side copies stand on a wide flat patch: its sphere may overfill the frame's height
PAGE_ASPECT = 4 / 3  # width / height of the scene on a page (a window of 1280 × 960, say)
BESIDE_TABLE_ASPECT = 0.9  # the same with 36 % of the width given to the caption's column

AXIS_COLORS = (0xE6194B, 0x3CB44B, 0x4363D8)  # x red, y green, z blue


class Scene:
    """A meshcat scene for one robot. ``scene.url`` is the live viewer; ``save_html`` writes a static copy."""

    def __init__(self, robot: Chain, viewer=None, open: bool = False, name: str | None = None,
                 frame_length: float | None = None):
        self.robot = robot
        self.server: Server | None = None
        if viewer is None:
            self.server = Server(tab_title(robot.name, "live view"))  # on 127.0.0.1, ending with this process
            viewer_url = self.server.zmq_url
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL; we expose it as .url
            self.viewer = viewer if viewer is not None else meshcat.Visualizer(zmq_url=viewer_url)
        self.geom, missing = robot.visual_model(), robot.missing_meshes()  # missing: named in the caption
        self.stick = self.geom.ngeoms == 0  # nothing to draw from the file: the chain as a stick figure
        self._lengths: list[float] = []
        self.pinviz = MeshcatVisualizer(robot.model, pin.GeometryModel(), self.geom)
        self.pinviz.initViewer(viewer=self.viewer)
        self.root = name or robot.name
        load_robot(self.pinviz, self.root)
        self.frame_length = frame_length or 0.5 * robot.characteristic_length()
        self._reach = self._arm_reach()
        self.title = robot.name
        self.view = "view"  # what the page shows, for its tab's title: "branches", "animation", "map", ...
        self.legend: dict[str, str] = {}  # what each mark means, by mark (the caption's lines)
        self.table: Table | None = None  # a table under the caption's lines (the branches' joints, say)
        self.aspect = PAGE_ASPECT  # the scene's share of the page, width / height, the camera is set for
        self._framed: tuple[np.ndarray, float] | None = None  # what the camera was last set to hold
        if missing or self.stick:
            self.legend["figure"] = _figure_note(robot, missing, self.stick)
        self.viewer["/Axes"].set_property("visible", False)  # an unlabelled world triad; the tool frame is drawn
        self.show(robot.display_q())
        if open:
            self.viewer.open()

    @property
    def url(self) -> str:
        """The address of the live meshcat page (127.0.0.1)."""
        return self.viewer.url()

    def node_paths(self) -> list[str]:
        """The meshcat paths of the robot's visual geometries (one per URDF visual)."""
        return [self.pinviz.getViewerNodeName(g, pin.GeometryType.VISUAL) for g in self.geom.geometryObjects]

    def _rails(self) -> int:
        """How many joints lead the chain as a mobile base's rails (prismatic, over 2 m of travel)."""
        count = 0
        for j in self.robot.joints:
            if j.kind != "prismatic" or j.upper - j.lower <= 2:
                break
            count += 1
        return count

    def _arm_reach(self) -> float:
        q = self.robot.neutral()
        points = chain_points(self.robot, q)
        reach = sum(float(np.linalg.norm(b - a)) for a, b in zip(points, points[1:], strict=False))
        # an arm's slide adds its stroke; a mobile base's long rails (over 2 m) would only shrink the arm
        reach += sum(j.upper - j.lower for j in self.robot.joints if j.kind == "prismatic" and j.upper - j.lower < 2)
        return max(reach, 0.3)

    def look_at_robot(self, q=None) -> Scene:
        """Frame the robot as it stands at q (default: its display pose): the floor under its base, the
        camera far enough for the robot to fill most of the page's height."""
        return self._aim(self._points(self.robot.display_q() if q is None else q))

    def _points(self, q) -> np.ndarray:
        """Points the robot occupies at q: its joint origins, its tool point and its visuals' origins [m]; a
        mobile base's rails (prismatic joints over 2 m ahead of the arm) are where the robot can go, not where it
        is, so their joint origins are left out (a youBot at x = 7, y = −9 m is framed where it stands)."""
        chain = chain_points(self.robot, q)[self._rails():]  # leaves the robot's own Data at q
        gdata = pin.GeometryData(self.geom)
        pin.updateGeometryPlacements(self.robot.model, self.robot.data, self.geom, gdata)
        return np.array([*chain, *(M.translation for M in gdata.oMg)])

    def _aim(self, points: np.ndarray, fill: float = FILL) -> Scene:
        """Frame ``points`` (base frame): meshcat turns its camera about the viewer's origin, so the scene
        moves to put their centre there, the grid under the base, the camera at the framing distance."""
        self._framed = (points, fill)
        view = aim_camera(self.viewer, points, 0.05 * self.robot.characteristic_length(), fill, self.aspect)
        self.legend["floor"] = f"floor grid: {view.cell:g} m cells, at the base's height"
        return self

    # -- static scene ---------------------------------------------------------------------------
    def show(self, q) -> Scene:
        """Draw the robot at q (one number per joint) with its tool frame."""
        q = self.robot.check_q(q)
        self.pinviz.display(self.robot.to_pin_q(q))
        if self.stick:
            self._lengths = _stick_figure(self.viewer["stick"], chain_points(self.robot, q), self.frame_length)
        self.frame("tool", self.robot.fk(q))
        self.title = f"{self.robot.name} at q = [{', '.join(f'{v:.4g}' for v in q)}] (rad, m)"
        self.legend["tool"] = f"tool frame {self.robot.tool!r}: x red, y green, z blue"
        return self.look_at_robot(q)

    def move(self, q) -> Scene:
        """Move the drawn robot and its tool frame (drawn by :meth:`show` first) to q, the camera left where the
        user put it: a live page's next frame.

        Raises:
            ConfigurationError: q of the wrong length or not finite.
        """
        q = self.robot.check_q(q)
        self.pinviz.display(self.robot.to_pin_q(q))
        if self.stick:
            _move_stick(self.viewer["stick"], chain_points(self.robot, q), self._lengths)
        self.viewer["frames"]["tool"].set_transform(self.robot.fk(q).homogeneous)
        return self

    def put_table(self, table: Table) -> Scene:
        """A table on the saved page (every branch's joints, say): the caption, table included, becomes a column on
        the left 36 % of the page, and the camera is set again to hold the same points in the narrower rest."""
        self.table = table
        self.aspect = BESIDE_TABLE_ASPECT
        if self._framed is not None:
            points, fill = self._framed
            self._aim(points, min(fill, 1.0))  # held across the width now: a spread may not overfill it
        return self

    def drop_robot(self) -> None:
        """Remove the robot as :meth:`show` draws it — its meshes, or its stick figure where the file has none to
        draw — for a page that draws the robot its own way (side by side, over a map)."""
        self.viewer[self.root].delete()
        self.viewer["stick"].delete()

    def frame(self, name: str, oMframe: pin.SE3, length: float | None = None) -> Scene:
        """A triad (x red, y green, z blue) at a pose in the base frame, under ``frames/<name>``."""
        length = length or self.frame_length
        for axis, color in enumerate(AXIS_COLORS):
            end = np.zeros((3, 2))
            end[axis, 1] = length
            self.viewer["frames"][name][f"axis{axis}"].set_object(
                g.Line(g.PointsGeometry(end), g.MeshBasicMaterial(color=color, linewidth=4)))
        self.viewer["frames"][name].set_transform(oMframe.homogeneous)
        return self

    def target(self, oMtarget: pin.SE3) -> Scene:
        """The target frame of an IK problem."""
        return self.frame("target", oMtarget, 1.3 * self.frame_length)

    def path(self, points: np.ndarray, name: str = "tool_path", color: int = 0xF58231) -> Scene:
        """A polyline through points (rows, base frame) — e.g. the tool path of a trajectory."""
        pts = np.asarray(points, dtype=float).T
        self.viewer["paths"][name].set_object(g.Line(g.PointsGeometry(pts), g.MeshBasicMaterial(color=color)))
        return self

    # -- animation ------------------------------------------------------------------------------
    def animate(self, qs, dt: float = 0.05, draw_path: bool = True, play: bool = True) -> Scene:
        """An animation of a joint trajectory (rows of q) with the tool path drawn as a line."""
        self.view = "animation"
        qs = np.asarray(qs, dtype=float)
        anim = Animation(default_framerate=max(1, int(round(1.0 / dt))))
        model, data = self.robot.model, self.robot.model.createData()
        gdata = pin.GeometryData(self.geom)
        tool_points = []
        for k, q in enumerate(qs):
            q_pin = self.robot.to_pin_q(q)
            pin.forwardKinematics(model, data, q_pin)
            pin.updateGeometryPlacements(model, data, self.geom, gdata)
            with anim.at_frame(self.viewer, k) as frame:
                for obj, path in zip(self.geom.geometryObjects, self.node_paths(), strict=True):
                    T = gdata.oMg[self.geom.getGeometryId(obj.name)].homogeneous.copy()
                    T[:3, :3] = T[:3, :3] * np.asarray(obj.meshScale)
                    frame[path].set_transform(T)
                if self.stick:
                    _move_stick(frame["stick"], chain_points(self.robot, q), self._lengths)
                oMtool = self.robot.fk(q)
                frame["frames"]["tool"].set_transform(oMtool.homogeneous)
            tool_points.append(oMtool.translation)
        if draw_path:
            self.path(np.array(tool_points))
            self.legend["path"] = "orange line: the tool's path"
        self.viewer.set_animation(anim, play=play)
        every = max(1, len(qs) // 24)
        self.title = f"{self.robot.name}: {len(qs)} configurations, {dt:g} s apart"
        return self._aim(np.vstack([self._points(q) for q in qs[::every]] + [np.array(tool_points)]))

    # -- singularities --------------------------------------------------------------------------
    def singular_directions(self, q, scale: float | None = None) -> Scene:
        """At q: the lost tool directions as arrows from the tool (translation magenta, rotation axis cyan) and a
        sphere at the tool coloured by σ_min/σ_max (red: singular, green: far from it). The marks are drawn over
        the robot (no depth test): a wrist's mesh or a joint's ball would otherwise hide them."""
        a = analyze(self.robot, q)
        self.view = "singularity"
        oMtool = self.robot.fk(q)
        scale = scale or 2 * self.frame_length
        self.viewer["singular"].delete()
        kinds = set()
        for k, d in enumerate(a.lost_directions):
            for kind, axis, share, color in (("translation", d.translation_axis, d.translation_share, LOST_MOVE),
                                             ("rotation", d.rotation_axis, d.rotation_share, LOST_TURN)):
                if axis is not None and share >= 1e-3:
                    kinds.add(kind)
                    _arrow(self.viewer["singular"][f"lost{k}_{kind}"], oMtool.translation, np.array(axis),
                           scale * share, 0.04 * self.frame_length, color)
        ratio = a.sigma_ratio
        self.viewer["singular"]["sigma"].set_object(g.Sphere(0.3 * self.frame_length),
                                                    on_top(sigma_colour(ratio), 0.75))
        self.viewer["singular"]["sigma"].set_transform(pin.SE3(np.eye(3), oMtool.translation).homogeneous)
        self.legend["sigma"] = (f"sphere at the tool: σ_min/σ_max = {ratio:.3g} — {sigma_words(ratio)} (red to "
                                f"orange below {NEAR_SINGULAR:g}, near-singular as `kinelab singular` says; "
                                f"yellow-green to green above); rank {a.rank} of {a.full_rank}")
        if "translation" in kinds:
            self.legend["lost_translation"] = ("magenta arrow: a tool direction the arm cannot move in "
                                               "(length: its share)")
        if "rotation" in kinds:
            self.legend["lost_rotation"] = "cyan arrow: an axis the tool cannot turn about (length: its share)"
        if not a.lost_directions:
            self.legend["lost"] = "no direction is lost at this q (full rank)"
        return self

    # -- export ---------------------------------------------------------------------------------
    def static_html(self) -> str:
        """The whole scene (and its animation) as one self-contained HTML page (works offline)."""
        page = titled(self.viewer.static_html(), tab_title(self.robot.name, self.view))
        return with_caption(page, self.title, list(self.legend.values()), self.table)

    def notebook_html(self, height: int = 420) -> Any:
        """The static page (caption included) as an IPython HTML object for a notebook cell: it stays visible
        in a saved or exported notebook, where the live viewer's frame would be dead."""
        from IPython.display import HTML

        page = html.escape(self.static_html(), quote=True)
        # in a <div>: IPython warns (on stderr, into the saved notebook) about markup that starts with <iframe>
        return HTML(f'<div><iframe srcdoc="{page}" style="width:100%;height:{height}px;border:0"></iframe></div>')

    def save_html(self, path: str | Path) -> Path:
        """Write the scene as one self-contained HTML page (its caption included); returns the path.

        The page goes through kinelab's one writer (:func:`kinelab.files.write_output`): a new file, or a regular
        file replaced whole with its mode kept; never a folder, device, FIFO or socket.

        Raises:
            KinelabError: ``path`` is anything but a new or regular file, or its folder is missing or not writable.
        """
        return write_output(path, self.static_html(), "page")

    def close(self) -> None:
        """Stop the server this scene started (a viewer passed in is left alone)."""
        if self.server is not None:
            self.server.stop()



def sigma_colour(ratio: float) -> int:
    """The σ_min/σ_max sphere's colour (0xRRGGBB): red at 1e-6 and below to orange just under NEAR_SINGULAR (the
    one near-singular threshold), yellow-green at it to green at 0.1 and above."""
    if ratio < NEAR_SINGULAR:
        level = min(1.0, max(0.0, (np.log10(max(ratio, 1e-12)) + 6) / (np.log10(NEAR_SINGULAR) + 6)))
        return 0xFF << 16 | int(0x99 * level) << 8  # red → orange
    level = min(1.0, (np.log10(ratio) - np.log10(NEAR_SINGULAR)) / (-1 - np.log10(NEAR_SINGULAR)))
    return int(0xB0 * (1 - level)) << 16 | int(0xC0 + 0x30 * level) << 8  # yellow-green → green



def aim_camera(viewer: meshcat.Visualizer, points: np.ndarray, margin: float, fill: float = FILL,
               aspect: float = PAGE_ASPECT,
               floor_z: float = 0.0) -> Any:
    """Frame ``points`` (rows [m], base frame) in a meshcat viewer: meshcat turns its camera about the viewer's
    origin, so the scene moves to put their centre there, a floor grid at ``floor_z``, the camera at the framing
    distance for a page of ``aspect`` (width / height).

    Returns:
        The :class:`~kinelab.view.framing.Framing` used (its ``cell``: the grid's cell [m]).
    """
    view = frame_points(points, floor_z=floor_z, margin=margin, fill=fill)
    viewer.set_transform(view.scene_shift())
    viewer["/Grid"].set_property("visible", False)
    viewer["floor"].set_object(g.LineSegments(g.PointsGeometry(view.floor_segments()),
                                              g.LineBasicMaterial(color=0x9A9A9A)))
    viewer["/Cameras/default/rotated/<object>"].set_property("position", view.camera_position(aspect))
    return view


def side_by_side(robot: Chain, qs: list, spacing: float | None = None, viewer: meshcat.Visualizer | None = None,
                 labels: list[str] | None = None, highlight: int | None = None, target: pin.SE3 | None = None) -> Scene:
    """One scene with the robot drawn once per configuration as a stick figure (joints as spheres, the
    segments between joint origins and the tool point as cylinders), side by side on a grid, each copy numbered
    in the scene (1, 2, ...: scene nodes ``branches/1``, ...), with its tool frame: the branches of one IK target,
    say. Stick figures keep the page small (a meshed copy repeats the robot's mesh files: 9 MB per copy of a
    UR5) and the joints visible.

    Args:
        robot: the robot.
        qs: the configurations (one number per joint each, rad or m), at least one.
        spacing: distance between neighbouring copies [m]; default: the widest copy's footprint (twice its
            farthest point from its base, horizontally) and a quarter of the arm's reach between copies.
        viewer: a meshcat viewer to draw in (default: a new one on 127.0.0.1).
        labels: one label per configuration, listed in the caption by number (default "copy k").
        highlight: the index of a copy drawn with orange joints (the nearest branch, say), named in the caption.
        target: a pose (base frame) marked at every copy by a gold sphere at its point (each copy's tool on it).

    Returns:
        A :class:`Scene` whose viewer holds the copies (``save_html`` writes it; ``close`` stops its server).

    Raises:
        ConfigurationError: a q of the wrong length, non-finite, or no q at all.
        ValueError: labels of another length than qs.
    """
    checked = _copies(robot, qs, labels)
    scene = Scene(robot, viewer=viewer)
    scene.view = "side by side"
    scene.drop_robot()
    scene.viewer["frames"].delete()
    figures = [chain_points(robot, q) for q in checked]
    spacing = spacing or _spacing(figures, scene._reach)
    columns = int(np.ceil(np.sqrt(len(checked))))
    rows = -(-len(checked) // columns)
    occupied = []
    for k, points in enumerate(figures):
        # copy 1 nearest the camera, on the left: the first row is the front one, read left to right (+y)
        row, column = divmod(k, columns)
        offset = pin.SE3(np.eye(3), np.array([(rows - 1 - row) * spacing, column * spacing, 0.0]))
        occupied += _draw_copy(scene, robot, k, checked[k], points, offset, k == highlight, target)
    _side_by_side_legend(scene, robot, labels or [f"copy {k + 1}" for k in range(len(checked))], highlight, target)
    return scene._aim(np.array(occupied), fill=SPREAD_FILL if len(checked) > 1 else FILL)


def _copies(robot: Chain, qs: list, labels: list[str] | None) -> list[np.ndarray]:
    """The configurations checked, at least one, and as many labels as configurations (or none).

    Raises:
        ConfigurationError: a bad q, or none.
        ValueError: labels of another length.
    """
    checked = [robot.check_q(q) for q in qs]
    if not checked:
        raise ConfigurationError("side_by_side needs at least one configuration; got none")
    if labels is not None and len(labels) != len(checked):
        raise ValueError(f"side_by_side: {len(labels)} labels for {len(checked)} configurations")
    return checked


def _draw_copy(scene: Scene, robot: Chain, k: int, q: np.ndarray, points: list[np.ndarray], offset: pin.SE3,
               highlighted: bool, target: pin.SE3 | None) -> list[np.ndarray]:
    """Copy k (numbered k + 1) of the robot at q, moved by ``offset``: its stick figure, tool frame, number and
    the target's mark; returns the points it occupies [m, scene frame]."""
    moved = [offset.act(p) for p in points]
    _stick_figure(scene.viewer["branches"][str(k + 1)], moved, scene.frame_length, HIGHLIGHT if highlighted else JOINTS)
    scene.frame(f"tool_{k + 1}", offset * robot.fk(q))
    top = offset.translation + np.array([0.0, 0.0, max(p[2] for p in points) + 0.8 * scene.frame_length])
    draw_number(scene.viewer["numbers"][str(k + 1)], str(k + 1), top, 0.6 * scene.frame_length, NUMBERS)
    if target is not None:
        _target_mark(scene.viewer["targets"][str(k + 1)], offset.act(target.translation), scene.frame_length)
    return [*moved, offset.translation, top]


def _spacing(figures: list[list[np.ndarray]], reach: float) -> float:
    """Grid spacing [m] at which no two copies' footprints meet: twice the farthest any point of any copy lies
    from its base horizontally, and a quarter of the reach between them."""
    widest = max(float(np.max(np.linalg.norm(np.array(points)[:, :2] - points[0][:2], axis=1))) for points in figures)
    return 2.0 * widest + 0.25 * reach


def _target_mark(node: Any, point: np.ndarray, size: float) -> None:
    """A gold translucent sphere at the target's point."""
    node.set_object(g.Sphere(0.35 * size), g.MeshLambertMaterial(color=TARGET, opacity=0.45, transparent=True))
    node.set_transform(pin.SE3(np.eye(3), np.asarray(point, dtype=float)).homogeneous)


def _side_by_side_legend(scene: Scene, robot: Chain, labels: list[str], highlight: int | None,
                         target: pin.SE3 | None) -> None:
    scene.title = f"{robot.name}: {len(labels)} configurations side by side"
    scene.legend = {"figures": "joints: blue spheres; links: grey cylinders; each copy's number above it",
                    "tool": "tool frames: x red, y green, z blue",
                    "copies": "; ".join(f"{k + 1}: {label}" for k, label in enumerate(labels))}
    if target is not None:
        scene.legend["target"] = "gold sphere: the target point, at every copy"
    if highlight is not None:
        scene.legend["highlight"] = f"orange joints: {labels[highlight]}"


def chain_points(robot: Chain, q: Configuration) -> list[np.ndarray]:
    """The joint origins and the tool point at q [m, base frame], base first."""
    return [m.translation for m in robot.joint_placements(q).values()] + [robot.fk(q).translation]


JOINTS, HIGHLIGHT, NUMBERS, TARGET = 0x4363D8, 0xF58231, 0x1A1A1A, 0xFFD700  # blue, orange, black, gold
LOST_MOVE, LOST_TURN = 0xF032E6, 0x42D4F4  # magenta, cyan: a lost tool direction, a lost turning axis


def on_top(color: int, opacity: float) -> Any:
    """A material drawn over everything else (no depth test; three.js draws transparent objects last)."""
    return g.MeshLambertMaterial(color=color, opacity=opacity, transparent=True, depthTest=False)


def _arrow(node: Any, origin: np.ndarray, axis: np.ndarray, length: float, radius: float, color: int) -> None:
    """An arrow of ``length`` [m] from ``origin`` along the unit ``axis`` (base frame): a shaft and a cone, drawn
    over the robot. WebGL draws lines one pixel wide whatever their width, so the marks are solids."""
    head = min(0.35 * length, 6 * radius)
    turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), axis).matrix()  # three.js cylinders lie along y
    for part, height, shape in (("shaft", length - head, g.Cylinder(length - head, radius)),
                                ("head", head, g.Cylinder(head, radiusTop=0.0, radiusBottom=2.5 * radius))):
        start = 0.0 if part == "shaft" else length - head
        node[part].set_object(shape, on_top(color, 0.9))
        node[part].set_transform(pin.SE3(turn, origin + (start + height / 2) * axis).homogeneous)


def _stick_figure(node, points: list[np.ndarray], size: float, colour: int = JOINTS) -> list[float]:
    """Spheres (``colour``) at the points and cylinders between consecutive ones, under the meshcat ``node``;
    returns each segment's length [m] as drawn (0: two points at one place, no cylinder)."""
    radius = 0.16 * size  # links as thick as an arm's: readable when a page holds a grid of copies
    lengths = []
    for k in range(len(points)):
        node[f"joint{k}"].set_object(g.Sphere(1.6 * radius), g.MeshLambertMaterial(color=colour))
    for k, (a, b) in enumerate(zip(points, points[1:], strict=False)):
        length = float(np.linalg.norm(b - a))
        lengths.append(length if length >= 1e-9 else 0.0)
        if length >= 1e-9:
            node[f"link{k}"].set_object(g.Cylinder(length, radius), g.MeshLambertMaterial(color=0xA9A9A9))
    _move_stick(node, points, lengths)
    return lengths


def _move_stick(node, points: list[np.ndarray], lengths: list[float]) -> None:
    """Place a stick figure drawn by :func:`_stick_figure` (segment lengths ``lengths``) at new points: a prismatic
    joint's segment is stretched to its new length."""
    for k, p in enumerate(points):
        node[f"joint{k}"].set_transform(pin.SE3(np.eye(3), p).homogeneous)
    for k, (a, b) in enumerate(zip(points, points[1:], strict=False)):
        length = float(np.linalg.norm(b - a))
        if lengths[k] == 0.0 or length < 1e-12:
            continue
        # meshcat's cylinder stands along its local y axis: turn y onto the segment
        T = pin.SE3(pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), (b - a) / length).matrix(),
                    (a + b) / 2).homogeneous
        T[:3, 1] *= length / lengths[k]
        node[f"link{k}"].set_transform(T)


def _figure_note(robot: Chain, missing: list[str], stick: bool) -> str:
    """The caption line that says what the file could not give the view, and how the robot is drawn instead."""
    lost = (f"{len(missing)} visual mesh(es) of the file not found (first: {missing[0]}; --package-dir or "
            "package_dirs= finds them)") if missing else ""
    if not stick:
        return lost + ": those parts are not drawn"
    why = lost or ("a model built in memory has no visual geometry" if robot.urdf_path is None
                   else "the file has no visual geometry")
    return why + ": drawn as a stick figure (joints blue spheres, links grey cylinders)"
