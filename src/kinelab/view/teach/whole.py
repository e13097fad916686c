"""The teach page of a whole robot: a target per hand to drag, the feet held where they stand, the centre of mass
held over them and drawn with its support polygon; every drag is met by the whole-body solve from where the robot
stands (:func:`kinelab.wholebody.solve.solve`, no restart: the robot moves, it does not jump to another posture).
With collisions (``TeachOptions(collisions=...)``, or the switch), every step of that solve keeps each pair apart by
the margin (:mod:`kinelab.wholebody.clearance`): a hand dragged into an obstacle or the robot's own body stops at
the margin, and the readout names the nearest pair and its distance.

The support polygon is the convex hull of a ``SOLE`` rectangle under each foot frame (its x along the foot), on the
floor; the centre of mass is held at its start's horizontal place (``ComTask`` on x and y), drawn as a red ball with
its shadow on the floor, green inside the polygon, red outside.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin
from pinocchio.visualize import MeshcatVisualizer
from scipy.spatial import ConvexHull

from kinelab.collision.model import Collisions, Contact, as_collisions
from kinelab.errors import AssemblyError, KinelabError, OptionError
from kinelab.robot.tree import Robot
from kinelab.values import is_whole
from kinelab.view.collisions import draw_obstacle_nodes
from kinelab.view.meshes import load_robot
from kinelab.view.scene import AXIS_COLORS, aim_camera, on_top
from kinelab.view.teach.recorder import RecordingWindow
from kinelab.view.teach.session import Session, TeachOptions, _checked_pose, _locked, _pose, _short
from kinelab.view.whole_scene import robot_points
from kinelab.wholebody.clearance import step_collisions
from kinelab.wholebody.limits import Limits
from kinelab.wholebody.solve import solve
from kinelab.wholebody.tasks import ComTask, FrameTask, PostureTask

if TYPE_CHECKING:
    from kinelab.typing import Configuration

HELD_AT = 1e-3  # [m] an answer short of its target whose nearest pair is this near the margin was held off by it
SOLE = (0.20, 0.10)  # [m] the sole drawn under each foot frame for the support polygon: length (x), width (y)
GOLD, COM, INSIDE, OUTSIDE, LOOP = 0xF2B01E, 0xD62728, 0x2CA02C, 0xD62728, 0x17BECF


class WholeTeachSession(Session):
    """A whole robot to move by hand: its hands' targets dragged, its feet and centre of mass held."""

    def __init__(self, robot: Robot, q: Configuration | None = None, options: TeachOptions | None = None,
                 hands: tuple[str, ...] | None = None, feet: tuple[str, ...] | None = None):
        """Draw the robot standing at q and its targets on its hands.

        Raises:
            OptionError: no hand to drag (name them), or a frame that is not the robot's.
            ConfigurationError: a q that is not the robot's, or outside its limits.
        """
        self.robot, self.options = robot, options or TeachOptions(time_budget=0.5)
        self.lock = threading.RLock()
        self.hands = tuple(robot.hands if hands is None else hands)
        self.feet = tuple(robot.feet if feet is None else feet)
        if not self.hands:
            raise OptionError("hands", hands, f"the frames to drag: {robot.name} names none (teach(robot, "
                              "hands=[frame, ...]))")
        for name in self.hands + self.feet:
            robot.frame_id(name)
        self.q, self.start = standing(robot, self.feet) if q is None else (robot.check_q(q, limits=True), "given")
        if robot.closures:  # a robot with loops starts with them closed
            self.q, self.start = robot.assemble(self.q), f"{self.start}, its loops closed"
        self.rest = self.q.copy()
        self.collisions: Collisions | None = as_collisions(self.options.collisions)
        self.closest: Contact | None = self._nearest()
        self.targets = list(robot.frame_placements(self.q, self.hands))
        self.pins = robot.frame_placements(self.q, self.feet)
        self.com_target = robot.com(self.q) if robot.floating and self.feet else None
        self.support = support_polygon(self.pins)
        self.window = RecordingWindow()
        self.viewer = meshcat.Visualizer(window=self.window)
        self.frame_length = 0.25 * robot.characteristic_length()
        self.status = f"standing ({self.start}); drag a gold ball to move that hand"
        self._draw_robot()
        self._draw()

    # -- actions --------------------------------------------------------------------------------
    @_locked
    def set_q(self, q: Configuration) -> None:
        """Put the robot at q (within the limits, rad or m); the targets stay. A robot with loops keeps its motors
        where q has them and moves its passive joints to close the loops (its sliders are its motors'); where they
        cannot close, the robot stays and the status says so.

        Raises:
            ConfigurationError: q of the wrong length, not finite or outside the limits (named).
        """
        checked = self.robot.check_q(q, limits=True)
        if self.robot.closures:
            try:
                checked = self.robot.assemble(checked)
            except AssemblyError as exc:
                self.status = f"no assembly at these motor values (the loops stay {exc.residual:.2g} open): not moved"
                self._draw()
                return
        self.q, self.status = checked, "joints set" + (", the loops closed" if self.robot.closures else "")
        self._draw()

    @_locked
    def set_target(self, oMtarget: pin.SE3, index: int = 0) -> None:
        """Move hand ``index``'s target (base frame) and meet every task from where the robot stands; q stays where
        it was when the solve does not meet them all, and the status says which.

        Raises:
            TargetError: a pose that is not finite or whose rotation is not one. KinelabError: no such hand.
        """
        self.targets[_index(index, len(self.hands))] = _checked_pose(oMtarget)
        self._follow()
        self._draw()

    @_locked
    def snap_target(self) -> None:
        """Put every target on its hand as it is."""
        self.targets = list(self.robot.frame_placements(self.q, self.hands))
        self.status = "targets put on the hands"
        self._draw()

    def step_branch(self, step: int = 1) -> None:
        """A whole robot has no branches to step through.

        Raises:
            KinelabError: always, saying what to do instead.
        """
        raise KinelabError("a whole robot's page has no branches: drag a hand's gold ball")

    @_locked
    def set_collisions(self, on: object) -> None:
        """Switch collisions on (the options' value, else the robot with itself) or off.

        Raises:
            KinelabError: ``on`` not true or false. CollisionError: the robot has no collision geometry.
        """
        if not isinstance(on, bool):
            raise KinelabError(f"collisions are switched by on: true or false, not {_short(repr(on))}")
        self.collisions = (as_collisions(self.options.collisions) or Collisions()) if on else None
        self.closest = self._nearest()
        self.status = "collisions on" if on else "collisions off"
        self._draw()

    # -- what the page shows --------------------------------------------------------------------
    @_locked
    def readout(self) -> dict[str, Any]:
        """The numbers of the page: q, each hand's pose and error against its target (Pinocchio's FK), the centre of
        mass and whether it is over the support polygon, the status."""
        placed = self.robot.frame_placements(self.q, self.hands)
        hands = [{"frame": name, "pose": _pose(M), "target": _pose(T),
                  "position_error_m": float(np.linalg.norm(M.translation - T.translation)),
                  "rotation_error_rad": float(np.linalg.norm(pin.log3(M.rotation.T @ T.rotation)))}
                 for name, M, T in zip(self.hands, placed, self.targets, strict=True)]
        com = self.robot.com(self.q)
        inside = None if self.support is None else bool(inside_polygon(com[:2], self.support))
        rows = [[f"{h['frame']} error", f"{h['position_error_m']:.2e} m, {h['rotation_error_rad']:.2e} rad"]
                for h in hands]
        rows.append(["centre of mass", ", ".join(f"{x:.4f}" for x in com) + " m"
                     + ("" if inside is None else (" — over the feet" if inside else " — NOT over the feet"))])
        loops = [{"loop": c.label, "error": float(np.abs(e).max(initial=0.0))}
                 for c, e in zip(self.robot.closures, self._loop_errors(), strict=True)]
        rows += [[c["loop"], f"{c['error']:.2e} m, rad"] for c in loops]
        nearest = None if self.closest is None else {"first": self.closest.first, "second": self.closest.second,
                                                     "distance_m": self.closest.distance}
        if nearest is not None and self.collisions is not None:
            rows.append(["nearest pair", f"{self.closest} (margin {self.collisions.margin * 1e3:g} mm)"])
        return {"robot": self.robot.name, "q": self.q.tolist(), "hands": hands, "com_m": com.tolist(),
                "com_over_support": inside, "loops": loops, "nearest": nearest, "rows": rows, "status": self.status}

    def _nearest(self) -> Contact | None:
        """The nearest pair at q with collisions on (None: off)."""
        if self.collisions is None:
            return None
        return step_collisions(self.robot, self.collisions).closest(self.q)[0]

    def _loop_errors(self) -> list[np.ndarray]:
        """Each closure's held error components at q [m, rad]."""
        sizes = np.cumsum([len(c.rows) for c in self.robot.closures])[:-1]
        return np.split(self.robot.closure_error(self.q), sizes) if self.robot.closures else []

    def page_config(self) -> dict[str, Any]:
        """What the page is built from: the sliders (bounded one-coordinate joints, their index in q; a robot with
        loops: its motors), the targets, the heading and the legend."""
        model, space = self.robot.model, self.robot.space
        joints = []
        moved = set(self.robot.actuated) if self.robot.closures else None  # a robot with loops: its motors
        for jid in range(1, model.njoints):
            joint = model.joints[jid]
            if moved is not None and model.names[jid] not in moved:
                continue
            if joint.nq == 1 and np.isfinite(space.lower[joint.idx_q]) and np.isfinite(space.upper[joint.idx_q]):
                kind = "prismatic" if "JointModelP" in joint.shortname() else "revolute"
                joints.append({"name": model.names[jid], "kind": kind, "iq": joint.idx_q,
                               "lower": float(space.lower[joint.idx_q]), "upper": float(space.upper[joint.idx_q])})
        legend = (f"Gold balls: the targets of {', '.join(self.hands)} (drag one; Shift+drag turns it); the triads "
                  f"on the hands: their frames. "
                  + (f"Held: {', '.join(self.feet)} where they stand; support polygon: the hull of a "
                     f"{SOLE[0]:g} × {SOLE[1]:g} m sole under each. " if self.feet else "")
                  + ("Red ball: the centre of mass (held over the floor at its start); its shadow green over the "
                     "polygon, red off it. " if self.com_target is not None else "")
                  + (f"Cyan balls: the two ends of each of its {len(self.robot.closures)} loops (one ball where a "
                     "loop is closed); the readout gives each loop's error. " if self.robot.closures else "")
                  + (f"Obstacles, translucent: {'; '.join(self._obstacles)}. " if self._obstacles else "")
                  + ("Collisions held: every pair at least the margin apart (the readout names the nearest). "
                     if self.collisions is not None else "")
                  + f"Start: {self.start}.")
        return {"q": self.q.tolist(), "joints": joints, "targets": [f"target_{k}" for k in range(len(self.hands))],
                "heading": f"kinelab teach — {self.robot.name} (whole robot)", "legend": legend, "whole": True}

    # -- internals ------------------------------------------------------------------------------
    def tasks(self) -> list[Any]:
        """Every hand at its target, every foot where it stands, the centre of mass over its start, a posture."""
        task = "position" if self.robot.closures else "pose"  # a loop decides how a closed chain's hand turns
        tasks: list[Any] = [FrameTask(h, T.translation if task == "position" else T, task=task)
                            for h, T in zip(self.hands, self.targets, strict=True)]
        tasks += [FrameTask(f, M) for f, M in zip(self.feet, self.pins, strict=True)]
        if self.com_target is not None:
            tasks.append(ComTask(self.com_target, axes="xy"))
        return [*tasks, PostureTask(self.rest, weight=1e-3)]

    def _follow(self) -> None:
        o = self.options
        res = solve(self.robot, self.tasks(), q0=self.q, seed=0, tol_pos=o.tol_pos, tol_rot=o.tol_rot,
                    max_restarts=0, time_budget=o.time_budget,
                    limits=Limits(velocity=None, collisions=self.collisions))
        missed = [v.label for v in res.tasks if not v.met]
        if res.success:
            self.q = np.array(res.q)
            self.status = f"following: every task met within {o.tol_pos:g} m, {o.tol_rot:g} rad"
        elif self._held_off(res):
            self.q = np.array(res.q)
            self.status = f"held off by {res.closest}: {_short(', '.join(missed), 120)} not met"
        elif self._as_near(res):
            self.q = np.array(res.q)
            off = max(v.position_error for v in res.tasks[:len(self.hands)])
            self.status = f"as near as its loops let it: {off * 1e3:.1f} mm from the target"
        else:
            self.status = f"not reached ({res.status}): {_short(', '.join(missed), 120)}; q kept"
        self.closest = res.closest if self.collisions is not None else None

    def _as_near(self, res: Any) -> bool:
        """Whether an answer short of its targets is as near as a robot with loops gets (a four-bar's hand moves on
        a curve): the loops and every foot held, within the limits, the hands nearer their targets than before."""
        if not self.robot.closures or not self.robot.within_limits(res.q):
            return False
        if not all(v.met for v in res.tasks[len(self.hands):]):
            return False
        before = [np.linalg.norm(M.translation - T.translation)
                  for M, T in zip(self.robot.frame_placements(self.q, self.hands), self.targets, strict=True)]
        return sum(v.position_error for v in res.tasks[:len(self.hands)]) < sum(before)

    def _held_off(self, res: Any) -> bool:
        """Whether an answer short of its targets is where the collisions stop the robot: its nearest pair at the
        margin (within HELD_AT), within the limits, every foot and loop held — the robot goes as far as it can."""
        if self.collisions is None or res.closest is None:
            return False
        if not 0.0 <= res.closest.distance - self.collisions.margin <= HELD_AT:
            return False
        held = res.tasks[len(self.hands):]  # the feet, the centre of mass, the loops (the hands' come first)
        return self.robot.within_limits(res.q) and all(v.met for v in held)

    def _draw_robot(self) -> None:
        self.viz = MeshcatVisualizer(self.robot.model, pin.GeometryModel(), self.robot.visual_model())
        self.viz.initViewer(viewer=self.viewer)
        load_robot(self.viz, self.robot.name)
        self.viewer["/Axes"].set_property("visible", False)
        for k in range(len(self.hands)):
            for name, length in ((f"target_{k}", 1.3 * self.frame_length), (f"hand_{k}", self.frame_length)):
                for axis, color in enumerate(AXIS_COLORS):
                    end = np.zeros((3, 2))
                    end[axis, 1] = length
                    self.viewer["frames"][name][f"axis{axis}"].set_object(
                        g.Line(g.PointsGeometry(end), g.MeshBasicMaterial(color=color, linewidth=4)))
            self.viewer["frames"][f"target_{k}"]["handle"].set_object(g.Sphere(0.3 * self.frame_length),
                                                                      on_top(GOLD, 0.9))
        if self.support is not None:
            loop = np.vstack([self.support, self.support[:1]])
            points = np.vstack([loop.T, np.full(loop.shape[0], self.floor + 0.002)])  # just above the floor grid
            self.viewer["support"].set_object(g.Line(g.PointsGeometry(points), _over(INSIDE)))
        if self.com_target is not None:
            self.viewer["com"].set_object(g.Sphere(0.12 * self.frame_length), on_top(COM, 0.9))
        for k in range(len(self.robot.closures)):
            for tip in ("a", "b"):
                self.viewer["loops"][f"loop_{k}"][tip].set_object(g.Sphere(0.06 * self.frame_length),
                                                                  on_top(LOOP, 0.8))
        given = as_collisions(self.options.collisions)
        environment = None if given is None else given.environment
        self._obstacles = [] if environment is None else draw_obstacle_nodes(self.viewer, environment)
        self.viz.display(self.q)
        aim_camera(self.viewer, self._points(), 0.1 * self.robot.characteristic_length(), floor_z=self.floor)

    def _points(self) -> np.ndarray:
        """Where the robot is at q: its joints' origins and its visuals' [m], for the camera."""
        return robot_points(self.robot.model, self.viz.visual_model, self.q)

    @property
    def floor(self) -> float:
        """The floor's height [m]: the lowest foot's (0 without feet)."""
        return min((M.translation[2] for M in self.pins), default=0.0)

    def _draw_loops(self) -> None:
        """Each loop's two ends, and a line between them where the loop is open."""
        for k, (a, b) in enumerate(_loop_ends(self.robot, self.q)):
            node = self.viewer["loops"][f"loop_{k}"]
            node["a"].set_transform(pin.SE3(np.eye(3), a).homogeneous)
            node["b"].set_transform(pin.SE3(np.eye(3), b).homogeneous)
            node["gap"].set_object(g.Line(g.PointsGeometry(np.array([a, b]).T), _over(OUTSIDE)))

    def _draw(self) -> None:
        self.viz.display(self.q)
        for k, (M, T) in enumerate(zip(self.robot.frame_placements(self.q, self.hands), self.targets, strict=True)):
            self.viewer["frames"][f"hand_{k}"].set_transform(M.homogeneous)
            self.viewer["frames"][f"target_{k}"].set_transform(T.homogeneous)
        self._draw_loops()
        if self.com_target is not None:
            com = self.robot.com(self.q)
            self.viewer["com"].set_transform(pin.SE3(np.eye(3), com).homogeneous)
            over = self.support is not None and inside_polygon(com[:2], self.support)
            shadow = np.array([[com[0], com[0]], [com[1], com[1]], [com[2], self.floor]])
            self.viewer["com_shadow"].set_object(g.Line(g.PointsGeometry(shadow), _over(INSIDE if over else OUTSIDE)))


def _loop_ends(robot: Robot, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each closure's two frames' origins at q [m]."""
    return [(robot.frame_placement(q, c.frame_a).translation, robot.frame_placement(q, c.frame_b).translation)
            for c in robot.closures]


def _over(color: int) -> Any:
    """A line's material drawn over the robot (no depth test), 3 px wide."""
    return g.MeshBasicMaterial(color=color, linewidth=3, depthTest=False)


def standing(robot: Robot, feet: tuple[str, ...]) -> tuple[np.ndarray, str]:
    """Where a whole robot starts: its SRDF's "half_sitting" (else its neutral configuration) with, on a free-flyer,
    its lowest foot on the floor (z = 0).

    Returns:
        (q, how it was chosen, in words).
    """
    named = robot.srdf is not None and "half_sitting" in robot.srdf.states
    q = robot.standing()
    if robot.floating and feet and feet != robot.feet:  # other feet than the robot's own: those on the floor
        q[2] -= min(M.translation[2] for M in robot.frame_placements(q, feet))
    return q, "the SRDF's half_sitting" if named else "the neutral configuration"


def support_polygon(feet: list[pin.SE3]) -> np.ndarray | None:
    """The convex hull (counter-clockwise (x, y) rows [m]) of a SOLE rectangle under each foot, or None without
    feet."""
    if not feet:
        return None

    half = np.array([SOLE[0], SOLE[1]]) / 2
    corners = np.array([[sx * half[0], sy * half[1], 0.0] for sx in (-1, 1) for sy in (-1, 1)])
    points = np.vstack([(M.rotation @ corners.T).T + M.translation for M in feet])[:, :2]
    hull = ConvexHull(points)
    return np.asarray(points[hull.vertices], dtype=float)


def inside_polygon(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Whether a point (x, y) lies inside a convex polygon given counter-clockwise."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = point - polygon
    return bool(np.all(edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0] >= 0.0))


def _index(index: Any, count: int) -> int:
    """A hand's index, checked.

    Raises:
        KinelabError: not an integer in [0, count).
    """
    if not is_whole(index, 0, count - 1):
        raise KinelabError(f"a target index is an integer from 0 to {count - 1}, not {_short(repr(index))}")
    return int(index)
