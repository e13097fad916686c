"""What the teach page shows and does, without the page: a robot at q, a target it follows by IK, its branches,
its collisions, and the numbers read live (tool pose, σ_min, manipulability, the velocity ellipsoid).

Each action changes the state and draws the change in a meshcat scene whose commands a
:class:`~kinelab.view.teach.recorder.RecordingWindow` keeps for the page; :meth:`TeachSession.readout` is what the
page prints. Units: SI and radians; poses in the robot's base frame.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin

from kinelab.analysis.singular import analyze
from kinelab.collision import Collisions, collision_model
from kinelab.collision.model import as_collisions
from kinelab.core._verdict import NOT_FINITE, NOT_HOMOGENEOUS, first_defect
from kinelab.errors import KinelabError, TargetError
from kinelab.ik import options as opt
from kinelab.ik import solve, solve_all
from kinelab.ik.turns import nearest_turns
from kinelab.robot import Chain
from kinelab.typing import Configuration
from kinelab.values import is_whole
from kinelab.view.collisions import draw_obstacles, overlay_contacts
from kinelab.view.scene import TARGET, Scene, on_top
from kinelab.view.teach.recorder import RecordingWindow

F = TypeVar("F", bound=Callable[..., Any])


def _locked(method: F) -> F:
    """One action at a time: the page's requests come on threads of their own, a notebook's calls on its own."""

    @functools.wraps(method)
    def run(self: TeachSession, *args: Any, **kwargs: object) -> Any:
        with self.lock:
            return method(self, *args, **kwargs)

    return run  # type: ignore[return-value]


ELLIPSOID = 0x4363D8


@dataclass(frozen=True)
class TeachOptions:
    """How the target is followed.

    Attributes:
        tol_pos: position tolerance [m] of every solve.
        tol_rot: rotation tolerance [rad].
        time_budget: wall-clock budget of one follow (FRDM from the current q, then restarts) [s].
        collisions: what the collision switch checks (a :class:`kinelab.Collisions`; None: the robot with itself).
    """

    tol_pos: float = 1e-6
    tol_rot: float = 1e-6
    time_budget: float = 0.05
    collisions: Any = None

    def __post_init__(self) -> None:
        for name in ("tol_pos", "tol_rot", "time_budget"):
            opt.positive(name, getattr(self, name))
        if self.collisions is not None:  # "self", an Environment or a Collisions (anything else named)
            as_collisions(self.collisions)


class Session:
    """What every teach page's session shares: the robot, q, a status line, the lock its actions hold, and
    setting q directly (``robot.check_q``'s q: a chain's joints, or a whole robot's Pinocchio q)."""

    robot: Any
    q: np.ndarray
    status: str
    lock: threading.RLock

    @_locked
    def set_q(self, q: Configuration) -> None:
        """Put the robot at q (within the limits, rad or m); the targets stay.

        Raises:
            ConfigurationError: q of the wrong length, not finite or outside the limits (named).
        """
        self.q = self.robot.check_q(q, limits=True)
        self.status = "joints set"
        self._draw()

    def _draw(self) -> None:
        raise NotImplementedError


class TeachSession(Session):
    """A robot to move by hand: joint values set directly, or a target pose the robot follows by IK."""

    def __init__(self, robot: Chain, q: Configuration | None = None, options: TeachOptions | None = None):
        self.robot, self.options = robot, options or TeachOptions()
        self.lock = threading.RLock()  # held by each action and reading (the server's threads, a notebook)
        if q is None:
            q, self.start = robot.reference_q()
        else:
            self.start = "given"
        self.q = robot.check_q(q, limits=True)
        self.window = RecordingWindow()
        self.scene = Scene(robot, viewer=meshcat.Visualizer(window=self.window)).show(self.q)
        self.target = robot.fk(self.q)
        self.status = f"at the start ({self.start}); drag the gold ball to move the target"
        self.branches: Any = None
        self.branch = -1
        self.collisions_on = False
        self._collision_model: Any = None
        self.contacts: list[Any] = []  # the pairs in contact at q while collisions are on
        self._drawn_contacts: set[str] = set()
        # the ellipsoid's scale [m drawn per m/rad], fixed at the start: its largest radius there 0.8 frame length
        self.scale = 0.8 * self.scene.frame_length / max(self._velocity_svd()[1].max(), 1e-9)
        self._draw_target_objects()
        environment = getattr(self.options.collisions, "environment", None)
        if environment is not None:
            draw_obstacles(self.scene, environment)
        self._draw()

    # -- actions --------------------------------------------------------------------------------
    @_locked
    def set_target(self, oMtarget: pin.SE3, index: int = 0) -> None:
        """Move the target to a pose (base frame) and follow it: FRDM from the current q (the answer's revolute
        angles the turns nearest it), with collisions when switched on; q stays where it was when no answer meets
        the target within the tolerances, and the status says why.

        Raises:
            TargetError: a pose that is not finite or whose rotation is not one. KinelabError: an index other than
                0 (a chain has one target).
        """
        if isinstance(index, bool) or index != 0:
            raise KinelabError(f"a chain's page has one target, index 0, not {_short(repr(index))}")
        self.target = _checked_pose(oMtarget)
        self.branches, self.branch = None, -1
        self._follow()
        self._draw()

    @_locked
    def snap_target(self) -> None:
        """Put the target on the tool as it is."""
        self.target = self.robot.fk(self.q)
        self.branches, self.branch = None, -1
        self.status = "target put on the tool"
        self._draw()

    @_locked
    def step_branch(self, step: int = 1) -> None:
        """Go to the target's next (``step`` 1) or previous (−1) branch: every branch in closed form or by the
        1-D search where the arm has one, else those a multistart finds; the first is the one nearest q. With
        collisions on, only the branches clear of them.

        Raises:
            KinelabError: a step other than the integers 1 and −1 (a float, a bool, anything else).
        """
        if not is_whole(step) or step not in (1, -1):
            raise KinelabError(f"a branch step is the integer 1 (next) or -1 (previous), not {_short(repr(step))}")
        step = int(step)
        if self.branches is None:
            self.branches = solve_all(self.robot, self.target, q_ref=self.q, seed=0, tol_pos=self.options.tol_pos,
                                      tol_rot=self.options.tol_rot, collisions=self._spec(),
                                      drop_colliding=self.collisions_on)
            self.branch = -step if len(self.branches) else -1
        found = self.branches
        if not len(found):
            self.status = f"no branch: {found.status} — {found.message}"
            return
        self.branch = (self.branch + step) % len(found)
        self.q = np.array(found.q[self.branch])
        self.status = f"branch {self.branch + 1} of {len(found)} ({found.method or 'multistart'})"
        self._draw()

    @_locked
    def set_collisions(self, on: object) -> None:
        """Switch the collision check on or off: with it on, no answer that collides is taken, and the contacts at
        q are listed.

        Raises:
            KinelabError: ``on`` is not True or False.
        """
        if not isinstance(on, bool | np.bool_):
            raise KinelabError(f"collisions are switched by on: true or false, not {_short(repr(on))}")
        self.collisions_on = bool(on)
        self.branches, self.branch = None, -1
        self.status = "collisions on" if on else "collisions off"
        self._draw()

    # -- what the page shows --------------------------------------------------------------------
    @_locked
    def readout(self) -> dict[str, Any]:
        """The numbers of the page: q, the tool and target poses, errors, σ_min, manipulability, the velocity
        ellipsoid's radii, the status, the branch, the contacts (each with its unit in its name)."""
        oMtool = self.robot.fk(self.q)
        a = analyze(self.robot, self.q)
        error = self.target.actInv(oMtool)
        return {"robot": self.robot.name, "q": self.q.tolist(), "tool": _pose(oMtool), "target": _pose(self.target),
                "position_error_m": float(np.linalg.norm(oMtool.translation - self.target.translation)),
                "rotation_error_rad": float(np.linalg.norm(pin.log3(error.rotation))),
                "sigma_min": float(a.singular_values[a.full_rank - 1]), "manipulability": a.manipulability,
                "rank": a.rank, "full_rank": a.full_rank, "ellipsoid_radii_m_per_rad": self._svd[1].tolist(),
                "status": self.status, "branch": self.branch + 1,
                "branches": None if self.branches is None else len(self.branches),
                "collisions": self.collisions_on, "contacts": [str(c) for c in self.contacts]}

    def page_config(self) -> dict[str, Any]:
        """What the page is built from: a slider per joint (its index in q), the target, the heading and the
        legend."""
        robot = self.robot
        joints = [{"name": j.name, "kind": j.kind, "iq": k, "lower": j.lower, "upper": j.upper}
                  for k, j in enumerate(robot.joints)]
        legend = (f"Tool frame: x red, y green, z blue; target: the longer triad with the gold ball. Blue ellipsoid: "
                  f"the tool point's velocities for unit joint speeds (J_v's singular values), 1 m/rad drawn as "
                  f"{self.scale:.3g} m (fixed at the start). "
                  f"σ_min and manipulability of the Jacobian with its linear rows divided by L = "
                  f"{robot.characteristic_length():.3g} m (dimensionless). Start: {self.start}."
                  + (f" Obstacles: {self.scene.legend['obstacles']}." if "obstacles" in self.scene.legend else ""))
        return {"q": self.q.tolist(), "joints": joints, "targets": ["target"], "heading": f"kinelab teach — "
                f"{robot.name}", "legend": legend, "whole": False}

    # -- internals ------------------------------------------------------------------------------
    def _follow(self) -> None:
        o = self.options
        res = solve(self.robot, self.target, q0=self.q, seed=0, tol_pos=o.tol_pos, tol_rot=o.tol_rot,
                    time_budget=o.time_budget, collisions=self._spec())
        res = nearest_turns(self.robot, res, self.q, self.target, tol_pos=o.tol_pos, tol_rot=o.tol_rot)
        if res.success:
            self.q = np.array(res.q)
            self.status = f"following: met by {res.solver} within {o.tol_pos:g} m, {o.tol_rot:g} rad"
        else:
            self.status = f"not reached ({res.status}): {res.message or 'no answer within the budget'}; q kept"

    def _spec(self) -> Any:
        if not self.collisions_on:
            return None

        return self.options.collisions or Collisions()

    def _model(self) -> Any:
        if self._collision_model is None:
            self._collision_model = collision_model(self.robot, self._spec())
        return self._collision_model

    def _velocity_svd(self) -> tuple[np.ndarray, np.ndarray]:
        """(U, s) of J_v, the tool point's linear velocity Jacobian at q in base axes: the ellipsoid's axes and radii
        [m/rad]; three radii whatever the joint count (an arm of fewer than three joints has zeros)."""
        U, s, _ = np.linalg.svd(self.robot.jacobian_local_world_aligned(self.q)[:3])
        return U, np.pad(s, (0, 3 - s.size))

    def _draw_target_objects(self) -> None:
        length = self.scene.frame_length
        self.scene.target(self.target)
        handle = self.scene.viewer["frames"]["target"]["handle"]
        handle.set_object(g.Sphere(0.15 * length), on_top(TARGET, 0.9))  # over the robot: grabbable behind a link
        self.scene.viewer["ellipsoid"].set_object(g.Sphere(1.0), g.MeshLambertMaterial(
            color=ELLIPSOID, opacity=0.3, transparent=True, depthWrite=False))

    def _draw(self) -> None:
        self.scene.move(self.q)
        self._svd = self._velocity_svd()  # the ellipsoid drawn now and the radii read until q changes again
        self.scene.viewer["frames"]["target"].set_transform(self.target.homogeneous)
        self.scene.viewer["ellipsoid"].set_transform(self._ellipsoid())
        self._draw_contacts()

    def _draw_contacts(self) -> None:
        """List the pairs in contact at q (collisions on) and draw their links' collision objects red; a page
        with no contact, now or before, sends nothing."""
        self.contacts = self._model().contacts(self.q) if self.collisions_on else []
        names = {n for c in self.contacts for n in (c.first, c.second)}
        if names or self._drawn_contacts:
            overlay_contacts(self.scene, self._model(), names)
        self._drawn_contacts = names

    def _ellipsoid(self) -> np.ndarray:
        """The tool point's velocity ellipsoid (J_v J_vᵀ, base axes) as a scaled sphere's transform: its axes the
        left singular vectors, its radii the singular values [m/rad] × the page's scale (a floor keeps a
        singular direction visible as a flat disc)."""
        U, s = self._svd[0].copy(), self._svd[1]
        if np.linalg.det(U) < 0:
            U[:, 2] *= -1
        T = np.eye(4)
        T[:3, :3] = U * np.maximum(s * self.scale, 0.01 * self.scene.frame_length)
        T[:3, 3] = self.robot.fk(self.q).translation
        return T


def _checked_pose(oMtarget: Any) -> pin.SE3:
    """A copy of the pose as given, refused when it is no ``pin.SE3`` or not a pose (:func:`_pose_of`)."""
    if not isinstance(oMtarget, pin.SE3):
        raise TargetError(f"a target is a pinocchio.SE3 (base frame), not {type(oMtarget).__name__}")
    return _pose_of(oMtarget.homogeneous)


def _pose_of(H: np.ndarray) -> pin.SE3:
    """The pose of a 4 × 4 homogeneous matrix, checked as batch targets are (the compiled ``first_defect``): finite,
    its rotation orthonormal within 1e-6 with det +1, its last row 0, 0, 0, 1."""
    H = np.ascontiguousarray(H, dtype=float)
    _, defect = first_defect(H[None])
    if defect == NOT_FINITE:
        raise TargetError("the target pose is not finite (NaN or inf)")
    if defect == NOT_HOMOGENEOUS:
        raise TargetError(f"a homogeneous matrix's last row is 0, 0, 0, 1; got {H[3].tolist()}")
    if defect:
        raise TargetError("the target's rotation is not a rotation matrix (orthonormal within 1e-6, det +1)")
    return pin.SE3(H[:3, :3].copy(), H[:3, 3].copy())


def _pose(oMframe: pin.SE3) -> dict[str, list[float]]:
    q = pin.Quaternion(oMframe.rotation)
    return {"position_m": oMframe.translation.tolist(), "rpy_rad": pin.rpy.matrixToRpy(oMframe.rotation).tolist(),
            "quat_wxyz": [q.w, q.x, q.y, q.z]}


def _short(text: str, most: int = 60) -> str:
    """``text`` cut to ``most`` characters (a value echoed in a message: a 4,000-digit number is not read)."""
    return text if len(text) <= most else text[: most - 1] + "…"


def pose_from_matrix(values: object) -> pin.SE3:
    """A pose from 16 numbers (a 4 × 4 homogeneous matrix, rows first), as the page sends it.

    Raises:
        TargetError: not 16 finite numbers, its last row not 0, 0, 0, 1, or its rotation not one.
    """
    try:
        H = np.asarray(values, dtype=float).reshape(4, 4)
    except (TypeError, ValueError):
        raise TargetError("a target is 16 numbers: a 4 × 4 homogeneous matrix, rows first") from None
    return _pose_of(H)


__all__ = ["TeachOptions", "TeachSession", "pose_from_matrix"]
