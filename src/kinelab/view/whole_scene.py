"""A whole robot in meshcat (``kinelab view talos``, ``kinelab view delta``): standing on the floor at its start
(the SRDF's half-sitting or its neutral configuration, its lowest foot at z = 0), or at a given q; a robot that
closes loops drawn with them closed, each loop's two ends as cyan balls and a red line between them where a loop is
open; the floor grid under its feet and the camera framing the whole robot.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin
from pinocchio.visualize import MeshcatVisualizer

from kinelab.files import write_output
from kinelab.robot.tree import Robot
from kinelab.typing import Configuration
from kinelab.view.caption import tab_title, titled, with_caption
from kinelab.view.meshes import load_robot
from kinelab.view.scene import PAGE_ASPECT, aim_camera, on_top
from kinelab.view.server import Server

LOOP, OPEN = 0x17BECF, 0xD62728  # a loop's ends; the gap of an open loop
CLOSED = 1e-6  # [m, rad] a loop whose held components are this near is drawn as closed


class WholeScene:
    """A whole robot's scene (see the module's docstring). ``url``: the live page; ``save_html``: a static copy.

    Args:
        robot: the whole robot (:func:`kinelab.load`).
        q: its configuration (Pinocchio's q); None: standing at its start, its loops closed.
        viewer: a meshcat viewer to draw in (None: one served on 127.0.0.1 by this scene).

    Raises:
        ConfigurationError: a q that is not the robot's.
        AssemblyError: a robot with loops whose start cannot be assembled.
    """

    def __init__(self, robot: Robot, q: Configuration | None = None, viewer: Any = None):
        self.robot = robot
        self.server: Server | None = None
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL; the scene exposes it as .url
            if viewer is None:
                self.server = Server(tab_title(robot.name, "live view"))
                viewer = meshcat.Visualizer(zmq_url=self.server.zmq_url)
            self.viewer = viewer
        self.pinviz = MeshcatVisualizer(robot.model, pin.GeometryModel(), drawn_geometry(robot))
        self.pinviz.initViewer(viewer=self.viewer)
        self.root = robot.name  # the robot's node in the viewer
        load_robot(self.pinviz, self.root)
        self.viewer["/Axes"].set_property("visible", False)
        self.view, self.table = "view", None
        self.legend: dict[str, str] = {}
        self.q = start(robot) if q is None else robot.check_q(q)
        self.show(self.q)

    @property
    def url(self) -> str:
        """The live page's address (127.0.0.1)."""
        return str(self.viewer.url())

    def show(self, q: Configuration) -> WholeScene:
        """Draw the robot at q, its loops, the floor under its lowest foot, the camera on the whole robot."""
        robot = self.robot
        self.q = robot.check_q(q)
        self.pinviz.display(self.q)
        gaps = self._draw_loops()
        points = self.points()
        extent = float(np.ptp(points, axis=0).max()) if len(points) > 1 else robot.characteristic_length()
        aim_camera(self.viewer, points, 0.08 * extent, aspect=PAGE_ASPECT, floor_z=self.floor())
        self.title = f"{robot.name} (whole robot, nq = {robot.nq})"
        if robot.closures:
            open_ = [c.label for c, gap in zip(robot.closures, gaps, strict=True) if gap > CLOSED]
            count = f"{len(gaps)} loop" + ("s" if len(gaps) > 1 else "")
            self.legend["loops"] = (f"cyan balls: the two ends of each of its {count} (one ball where a loop joins "
                                    f"two points); largest error of a loop's held components {max(gaps):.1e} m, rad"
                                    + (f"; open: {', '.join(open_)} (red lines)" if open_ else ""))
        if robot.feet:
            self.legend["floor"] = f"floor grid at the lowest of {', '.join(robot.feet)}"
        return self

    def floor(self) -> float:
        """The floor's height [m]: the lowest foot's, else the lowest point drawn."""
        if self.robot.feet:
            return min(M.translation[2] for M in self.robot.frame_placements(self.q, self.robot.feet))
        return float(self.points()[:, 2].min())

    def points(self) -> np.ndarray:
        """(k, 3) where the robot is at q: its joints' origins and its visuals' [m]."""
        return robot_points(self.robot.model, self.pinviz.visual_model, self.q)

    def _draw_loops(self) -> list[float]:
        """Each loop's two ends (and a line between them where it is open); returns each loop's largest held error
        [m, rad] (the components its closure holds: an orientation loop's ends may stand apart)."""
        robot = self.robot
        if not robot.closures:
            return []
        sizes = np.cumsum([len(c.rows) for c in robot.closures])[:-1]
        errors = [float(np.abs(e).max(initial=0.0)) for e in np.split(robot.closure_error(self.q), sizes)]
        size = 0.03 * robot.characteristic_length()
        for k, closure in enumerate(robot.closures):
            a = self.robot.frame_placement(self.q, closure.frame_a).translation
            b = self.robot.frame_placement(self.q, closure.frame_b).translation
            node = self.viewer["loops"][f"loop_{k}"]
            for name, point in (("a", a), ("b", b)):
                node[name].set_object(g.Sphere(size), on_top(LOOP, 0.8))
                node[name].set_transform(pin.SE3(np.eye(3), point).homogeneous)
            if errors[k] > CLOSED:
                node["gap"].set_object(g.Line(g.PointsGeometry(np.array([a, b]).T),
                                              g.MeshBasicMaterial(color=OPEN, linewidth=3, depthTest=False)))
        return errors

    def static_html(self) -> str:
        """The scene as one self-contained HTML page, its caption included."""
        page = titled(self.viewer.static_html(), tab_title(self.robot.name, self.view))
        return with_caption(page, self.title, list(self.legend.values()), self.table)

    def save_html(self, path: str | Path) -> Path:
        """Write :meth:`static_html` (kinelab's one writer: a new or regular file, never anything else).

        Raises:
            KinelabError: a path that is not a new or regular file, or an unwritable folder.
        """
        return write_output(path, self.static_html(), "page")

    def close(self) -> None:
        """Stop the server this scene started."""
        if self.server is not None:
            self.server.stop()


def drawn_geometry(robot: Robot) -> pin.GeometryModel:
    """What draws the robot: its visual geometry, else (a file that has none, as kinelab's reduced Cassie) its
    collision geometry."""
    visual = robot.visual_model()
    return visual if visual.ngeoms else robot.visual_model("collision")


def robot_points(model: pin.Model, visual_model: pin.GeometryModel, q: np.ndarray) -> np.ndarray:
    """(k, 3) where a robot is at q: its joints' origins and its visuals' [m] (what a camera frames)."""
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    gdata = pin.GeometryData(visual_model)
    pin.updateGeometryPlacements(model, data, visual_model, gdata)
    return np.array([*(M.translation for M in data.oMi[1:]), *(M.translation for M in gdata.oMg)])


def start(robot: Robot) -> np.ndarray:
    """A whole robot's start: standing (:func:`kinelab.standing`), its loops closed."""
    q = robot.standing()
    return robot.assemble(q) if robot.closures else q
