"""Robot: a robot's whole Pinocchio model as loaded — a fixed base, or a free-flyer where asked for (humanoids,
quadrupeds) — with every frame by name, the forward kinematics and the three Jacobians of any frame, the centre of
mass and its Jacobian, and the joint space (:mod:`kinelab.robot.space`).

Coordinates are Pinocchio's: q has nq numbers (a free-flyer as position [m] and unit quaternion (x, y, z, w), a
continuous joint as (cos, sin)), a velocity nv numbers. Frames: poses are ``pin.SE3`` in the world (the model's
universe) frame, ``oM<frame>``; Jacobians are 6 × nv with rows [linear; angular], in the frame the method names
(docs/jacobians.md). A chain between two frames is a view of the robot (:meth:`Robot.chain`,
:class:`~kinelab.robot.chain.Chain`), with its own one-number-per-joint q.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar, cast, overload

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.errors import ChainError, FrameNotFoundError, OptionError, SRDFError
from kinelab.robot import assembly
from kinelab.robot import space as sp
from kinelab.robot.chain import Chain
from kinelab.robot.closures import Closure, check_closures
from kinelab.robot.joints import Mimic
from kinelab.robot.reduce import build_model

if TYPE_CHECKING:
    from kinelab.robot.chain import Chain
    from kinelab.robot.srdf import Srdf

T = TypeVar("T")
REFERENCES = {"local": pin.LOCAL, "world": pin.WORLD, "local_world_aligned": pin.LOCAL_WORLD_ALIGNED}


_UNBUILT = object()  # derived(): no value kept yet under a key


class Robot:
    """A robot's whole kinematic model (see the module's docstring).

    Build with :func:`kinelab.load` (a whole robot's registered name such as ``"talos"``, or a file with
    ``whole=True`` or ``floating=True``) or :meth:`from_model`.

    Attributes:
        name: the robot's name; source: the file it was read from (None for an in-memory model).
        model, data: Pinocchio's model and a Data for it (the methods' scratch: not thread-safe).
        space: the joint space (limits, sizes, names); nq, nv: its sizes; floating: a free-flyer at the root.
        srdf: the SRDF read, or None.
    """

    def __init__(self, model: pin.Model, *, name: str | None = None, source: Path | None = None,
                 srdf: Srdf | None = None, chain_source: Callable[..., Chain] | None = None,
                 geometry: Callable[[str], pin.GeometryModel] | None = None):
        """A Robot over a Pinocchio model (:func:`kinelab.load` and :meth:`from_model` make one).

        Args:
            model: the whole model (kept as a copy whose joint limits cannot change: ``robot.model``).
            name: the robot's name (default: the model's).
            source: the file it was read from, or None.
            srdf: its SRDF, or None.
            chain_source: how :meth:`chain` builds a view (the loader's; None: from the model).
            geometry: how :meth:`visual_model` builds the geometry (None: none, a stick figure).
        """
        model = sp.fixed_limits(model)  # the limits the space reads now are the model's for as long as it lives
        self.model, self.name, self.source, self.srdf = model, name or model.name or "robot", source, srdf
        self.data = model.createData()
        self.space = sp.space_of(model)
        self.nq, self.nv, self.floating = self.space.nq, self.space.nv, self.space.floating
        self._chain_source, self._geometry = chain_source, geometry
        self._frames = {f.name: i for i, f in reversed(list(enumerate(model.frames)))}  # the first of a name wins
        self._bodies = {f.name: i for i, f in reversed(list(enumerate(model.frames))) if f.type == pin.FrameType.BODY}
        self._derived: dict[str, Any] = {}
        self.hands: tuple[str, ...] = ()  # the frames a user moves first (a registered robot's; teach's targets)
        self.feet: tuple[str, ...] = ()  # the frames standing on the floor (held where they are by teach)
        self.closures: tuple[Closure, ...] = ()  # the loops the robot closes (:meth:`declare_closures`)
        self.actuated: tuple[str, ...] = ()  # the joints a controller drives; the others move with the loops
        self.mimics: tuple[Mimic, ...] = ()  # mimic joints Pinocchio could not build: plain joints, held as couplings

    @overload
    @classmethod
    def from_model(cls, model: pin.Model, *, name: str | None = ..., floating: bool = ...) -> Robot: ...

    @overload
    @classmethod
    def from_model(cls, model: pin.Model, *, tool: str, base: str | None = ..., locked: dict[str, float] | None = ...,
                   name: str | None = ...) -> Chain: ...

    @classmethod
    def from_model(cls, model: pin.Model, *, tool: str | None = None, base: str | None = None,
                   locked: dict[str, float] | None = None, name: str | None = None,
                   floating: bool = False) -> Robot | Chain:
        """The whole robot of an in-memory Pinocchio model (what pink and mink take), or with ``tool`` the chain
        base → tool of it (:meth:`Chain.from_model <kinelab.robot.chain.Chain.from_model>`); a copy, yours left as
        it is.

        Args:
            model: the model.
            tool: the chain's tool frame (None: the whole robot).
            base: the chain's base frame (default: the model's root).
            locked: the chain's held joints, name → value [rad or m].
            name: its name (default: the model's).
            floating: put a free-flyer at the whole robot's root (a model built without one).

        Raises:
            ChainError: not a ``pin.Model``. OptionError: ``floating`` with a model whose root joint is one
                already, or chain settings with ``floating``.
            FrameNotFoundError, JointNotFoundError: the chain's, named.
        """
        if tool is not None or base is not None or locked is not None:
            if floating:
                raise OptionError("floating", floating, "False with tool=, base= or locked= (a chain is fixed)")
            return Chain.from_model(model, tool=tool, base=base, locked=locked, name=name)
        if not isinstance(model, pin.Model):
            raise ChainError(f"from_model takes a pinocchio.Model, got {type(model).__name__}")
        whole = pin.Model(model)
        if floating:
            whole = with_free_flyer(whole)
        return cls(whole, name=name)

    # -- frames ---------------------------------------------------------------------------------
    @property
    def frame_names(self) -> list[str]:
        """Every frame of the model, by name."""
        return [f.name for f in self.model.frames]

    @property
    def joint_names(self) -> list[str]:
        """The joints that move (with coordinates of their own), in Pinocchio's order."""
        return [self.model.names[j] for j in range(1, self.model.njoints) if self.model.joints[j].nq > 0]

    def frame_id(self, frame: str) -> int:
        """The id of frame ``frame`` (a link's BODY frame where a joint shares its name).

        Raises:
            FrameNotFoundError: no such frame (the frames listed).
        """
        found = self._bodies.get(frame) if isinstance(frame, str) else None
        if found is None:
            found = self._frames.get(frame) if isinstance(frame, str) else None
        if found is None:
            raise FrameNotFoundError(repr(frame) if not isinstance(frame, str) else frame, self.frame_names,
                                     self.name)
        return found

    # -- the joint space ------------------------------------------------------------------------
    @property
    def lower(self) -> np.ndarray:
        """(nq,) lower position limits [rad or m]; -inf where a joint has none."""
        return self.space.lower

    @property
    def upper(self) -> np.ndarray:
        """(nq,) upper position limits [rad or m]; inf where a joint has none."""
        return self.space.upper

    @property
    def velocity_limit(self) -> np.ndarray:
        """(nv,) velocity limits [rad/s or m/s] from the file; inf where it gives none."""
        return self.space.velocity

    def check_q(self, q: ArrayLike, *, limits: bool = False, what: str = "q") -> np.ndarray:
        """``q`` as nq finite floats (Pinocchio's q), unit quaternions, within the limits with ``limits``.

        Raises:
            ConfigurationError, JointLimitError: what is wrong, named.
        """
        return sp.check_q(self.space, self.model, q, limits=limits, what=what)

    def within_limits(self, q: ArrayLike, slack: float = sp.LIMIT_SLACK) -> bool:
        """True when every bounded joint of q lies within its limits (plus ``slack``).

        Raises:
            ConfigurationError: q is not a configuration of this robot.
        """
        return sp.within_limits(self.space, self.check_q(q), slack)

    def neutral(self) -> np.ndarray:
        """Pinocchio's neutral configuration with each bounded joint moved into its limits."""
        q = np.asarray(pin.neutral(self.model), dtype=float)
        return np.clip(q, self.space.lower, self.space.upper)

    def random_q(self, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """A random configuration: bounded joints uniform in their limits, a free-flyer at the origin turned at
        random (see :func:`kinelab.robot.space.random_q`)."""
        return sp.random_q(self.space, self.model, sp.generator(rng))

    def random_qs(self, count: int, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """``count`` random configurations (rows), as :meth:`random_q` draws them.

        Raises:
            OptionError: a count that is not a whole number ≥ 0, or whose rows would take more than 8 GiB.
        """
        if not isinstance(count, int | np.integer) or isinstance(count, bool) or count < 0 \
                or int(count) * self.nq * 8 > sp.MAX_SAMPLE_BYTES:
            raise OptionError("count", count, f"a whole number of configurations in [0, "
                              f"{sp.MAX_SAMPLE_BYTES // (8 * self.nq)}]")
        gen = sp.generator(rng)
        return np.array([sp.random_q(self.space, self.model, gen) for _ in range(int(count))]).reshape(-1, self.nq)

    def integrate(self, q: ArrayLike, v: ArrayLike, dt: float = 1.0) -> np.ndarray:
        """q ⊕ v·dt through ``pin.integrate`` (v: nv velocities, dt [s])."""
        return np.asarray(pin.integrate(self.model, self.check_q(q), sp.check_v(self.space, v) * dt), dtype=float)

    def difference(self, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
        """q1 ⊖ q0 through ``pin.difference``: the nv velocities that take q0 to q1 in 1 s."""
        return np.asarray(pin.difference(self.model, self.check_q(q0), self.check_q(q1, what="q1")), dtype=float)

    def named_q(self, name: str) -> np.ndarray:
        """The whole q of the SRDF's named configuration ``name``: its joints at their values, the others neutral;
        a free-flyer robot with feet stands on them (its base raised until the lowest foot is at z = 0).

        Raises:
            SRDFError: no SRDF, or an unknown name (the names listed).
        """
        if self.srdf is None:
            raise SRDFError(f"{self.name} was loaded without an SRDF: load(..., srdf=PATH) for named configurations")
        q = self.neutral()
        for joint, value in self.srdf.state(name).items():
            if self.model.existJointName(joint) and self.model.joints[self.model.getJointId(joint)].nq == 1:
                q[self.model.joints[self.model.getJointId(joint)].idx_q] = value
        return self._on_its_feet(q)

    def standing(self) -> np.ndarray:
        """Where the robot stands: its SRDF's "half_sitting", else an MJCF file's keyframe (``home``, else its
        first), else its neutral configuration with a free-flyer robot's feet on the floor (the lowest foot at
        z = 0); its loops closed [m, rad]."""
        try:
            q = self.named_q("half_sitting")
        except SRDFError:
            keyframe = self._keyframe()
            q = self._on_its_feet(self.neutral()) if keyframe is None else keyframe
        return self.assemble(q) if self.closures else q

    def _keyframe(self) -> np.ndarray | None:
        """The file's keyframe ``home`` (else its first one) as Pinocchio's parser read it, clipped into the
        limits; None for a file without keyframes."""
        entries = [(e.key(), np.array(e.data(), dtype=float)) for e in self.model.referenceConfigurations]
        frames = {name: q for name, q in entries if name != "qpos0" and q.shape == (self.nq,)}
        if not frames:
            return None
        q = frames.get("home", next(iter(frames.values())))
        return np.clip(q, self.space.lower, self.space.upper)

    def _on_its_feet(self, q: np.ndarray) -> np.ndarray:
        """q with a free-flyer's height set so that the lowest of the robot's feet is on the floor (z = 0)."""
        if self.floating and self.feet:
            q[2] -= min(M.translation[2] for M in self.frame_placements(q, self.feet))
        return q

    # -- kinematics -----------------------------------------------------------------------------
    def forward(self, q: ArrayLike) -> None:
        """Pinocchio's forward kinematics and every frame's placement at q, in ``self.data``."""
        pin.framesForwardKinematics(self.model, self.data, self.check_q(q))

    def frame_placement(self, q: ArrayLike, frame: str) -> pin.SE3:
        """oMframe: the pose of ``frame`` in the world frame at q (a new SE3)."""
        fid = self.frame_id(frame)
        self.forward(q)
        return pin.SE3(self.data.oMf[fid])

    def frame_placements(self, q: ArrayLike, frames: Sequence[str]) -> list[pin.SE3]:
        """oMframe of each of ``frames`` at q, from one forward pass."""
        ids = [self.frame_id(f) for f in frames]
        self.forward(q)
        return [pin.SE3(self.data.oMf[i]) for i in ids]

    def frame_jacobian(self, q: ArrayLike, frame: str, reference: str = "local") -> np.ndarray:
        """The 6 × nv Jacobian of ``frame`` at q, rows [linear; angular]: "local" (the frame's own axes, its
        origin's velocity), "world" (the world's axes, the velocity of the point at the world's origin) or
        "local_world_aligned" (the world's axes, the frame origin's velocity).

        Raises:
            OptionError: an unknown reference (the three named). FrameNotFoundError: an unknown frame.
        """
        if not isinstance(reference, str) or reference not in REFERENCES:
            raise OptionError("reference", reference, f"one of {', '.join(REFERENCES)}")
        J = pin.computeFrameJacobian(self.model, self.data, self.check_q(q), self.frame_id(frame),
                                     REFERENCES[reference])
        return np.asarray(J, dtype=float).reshape(6, self.nv)

    @property
    def mass(self) -> float:
        """The robot's total mass [kg] (0 for a model without inertias)."""
        return float(sum(inertia.mass for inertia in self.model.inertias))

    def com(self, q: ArrayLike) -> np.ndarray:
        """The centre of mass [m] in the world frame at q (``pin.centerOfMass``)."""
        return np.array(pin.centerOfMass(self.model, self.data, self.check_q(q)), dtype=float)

    def com_jacobian(self, q: ArrayLike) -> np.ndarray:
        """The 3 × nv Jacobian of the centre of mass at q, world axes (``pin.jacobianCenterOfMass``)."""
        return np.array(pin.jacobianCenterOfMass(self.model, self.data, self.check_q(q)), dtype=float)

    # -- views and the rest ---------------------------------------------------------------------
    # -- closed loops -------------------------------------------------------------------------------
    def declare_closures(self, closures: Sequence[Closure], actuated: Sequence[str] = ()) -> None:
        """Declare the loops the robot closes and its actuated joints (:mod:`kinelab.robot.closures`).

        Raises:
            OptionError: not a list of Closure, or of one-coordinate joints' names.
            FrameNotFoundError, JointNotFoundError: named.
        """
        self.closures, self.actuated = check_closures(self.model, closures, actuated)
        self._derived.clear()

    def closure_error(self, q: ArrayLike) -> np.ndarray:
        """Every closure's held error components at q, stacked in declaration order [m, rad] (frame_a's axes)."""
        return assembly.loop_state(self.model, self.data, self.check_q(q), self.closures, jacobian=False)[0]

    def closure_jacobian(self, q: ArrayLike) -> np.ndarray:
        """The closures' Jacobian at q: d(:meth:`closure_error`)/dv, rows × nv."""
        J = assembly.loop_state(self.model, self.data, self.check_q(q), self.closures)[1]
        assert J is not None
        return J

    def actuated_jacobian(self, q: ArrayLike, frame: str, reference: str = "local_world_aligned") -> np.ndarray:
        """How ``frame`` moves with the actuated joints when the passive ones follow the loops, at an assembled q:
        ``G = J_a − J_p J_cp⁺ J_ca`` (6 × the actuated joints, rows [linear; angular] in ``reference``'s axes as
        :meth:`frame_jacobian`), with J_c the closures' Jacobian split into actuated (a) and passive (p) columns. A
        free-flyer is held (its columns are neither). Where the motors do not decide the passive motion — J_cp short
        of rank at a type II singularity, or more passive joints than the loops hold (Cassie's springs) — the
        pseudo-inverse takes its least-norm part (a choice: how a spring gives is dynamics). Idle spins (a rod on
        two ball joints) move no frame and change nothing.

        Raises:
            OptionError: a robot without loops or actuated joints. FrameNotFoundError: an unknown frame (named).
        """
        if not self.closures or not self.actuated:
            raise OptionError("robot", self.name, "a robot with loops and actuated joints declared")
        J = self.frame_jacobian(q, frame, reference)
        Jc = self.closure_jacobian(q)
        va = assembly.actuated_indices(self)[1]
        vp = assembly.passive_indices(self, self.actuated)
        return J[:, va] - J[:, vp] @ np.linalg.pinv(Jc[:, vp], rcond=1e-10) @ Jc[:, va]

    def assemble(self, q: ArrayLike, *, actuated: Sequence[str] | None = None) -> np.ndarray:
        """q with the passive joints moved so that every loop closes to 1e-10 [m, rad], the actuated joints (and a
        free-flyer) held where q has them; usually the assembly nearest q, else one from seeded restarts.

        Args:
            q: a configuration (nq numbers) within the limits.
            actuated: the joints held (default: the declared ``robot.actuated``).

        Raises:
            ConfigurationError, JointLimitError: a bad q. OptionError: no closures declared, or unknown actuated
                joints. AssemblyError: no assembly within the limits (the residual reached named).
        """
        arr = self.check_q(q, limits=True)
        if not self.closures:
            raise OptionError("closures", (), "declared loops (load(..., closures=...) or robot.declare_closures)")
        held = self.actuated if actuated is None else check_closures(self.model, self.closures, actuated)[1]
        return assembly.assemble(self, arr, held)

    def chain(self, base: str | None, tool: str, *, locked: dict[str, float] | None = None) -> Chain:
        """The chain from frame ``base`` (None: the root) to frame ``tool``: a view of this robot with its own
        one-number-per-joint q (:class:`~kinelab.robot.chain.Chain`), everything kinelab does on an arm.

        Args:
            base: the chain's first frame (poses are in it); it must lie on the root → tool path.
            tool: the chain's last frame.
            locked: joints held fixed, name → value [rad or m] (the others off the chain at the neutral pose, or
                the SRDF's reference).

        Raises:
            ChainError, FrameNotFoundError, JointNotFoundError: named.
        """
        if self._chain_source is not None:
            made = self._chain_source(tool=tool, base=base, locked=locked)
        else:
            plain = without_free_flyer(self.model) if self.floating else self.model
            made = Chain(build_model(plain, tool=tool, base=base, locked=locked, name=self.name))
        made.attach(self)
        return made

    def visual_model(self, kind: str = "visual") -> pin.GeometryModel:
        """The whole robot's visual (or ``kind="collision"``) geometry, meshes resolved (empty without a file).

        Raises:
            OptionError: a kind other than "visual" or "collision".
        """
        if not isinstance(kind, str) or kind not in ("visual", "collision"):
            raise OptionError("kind", kind, '"visual" or "collision"')
        return pin.GeometryModel() if self._geometry is None else self._geometry(kind)

    def characteristic_length(self) -> float:
        """The mean distance between consecutive joint origins at the neutral pose [m], over every joint: a length
        scale to weigh linear against angular quantities."""
        if "length" not in self._derived:
            pin.forwardKinematics(self.model, self.data, self.neutral())
            steps = [np.linalg.norm(self.data.oMi[j].translation - self.data.oMi[self.model.parents[j]].translation)
                     for j in range(1, self.model.njoints)]
            positive = [s for s in steps if s > 1e-9]
            self._derived["length"] = float(np.mean(positive)) if positive else 1.0
        return cast(float, self._derived["length"])

    def derived(self, key: str, build: Callable[[Robot], T]) -> T:
        """Data derived from this robot (a step's packed model, say), built on first use and kept here."""
        found = self._derived.get(key, _UNBUILT)
        if found is _UNBUILT:  # a builder may answer None (nothing to build): that is kept too
            found = self._derived[key] = build(self)
        return found

    def __repr__(self) -> str:
        base = "free-flyer" if self.floating else "fixed base"
        return f"Robot({self.name!r}, nq={self.nq}, nv={self.nv}, {base}, {self.model.nframes} frames)"


def with_free_flyer(model: pin.Model) -> pin.Model:
    """The model with a free-flyer joint between the universe and its root body (the model's first joint becomes
    its child).

    Raises:
        OptionError: the model's root joint is a free-flyer already.
    """
    if model.njoints > 1 and model.joints[1].shortname() == "JointModelFreeFlyer":
        raise OptionError("floating", True, "False: the model's root joint is a free-flyer already")
    flyer = pin.Model()
    flyer.name = model.name
    root = flyer.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    flyer.appendBodyToJoint(root, pin.Inertia.Zero(), pin.SE3.Identity())
    frame = flyer.addFrame(pin.Frame("root_joint", root, 0, pin.SE3.Identity(), pin.FrameType.JOINT))
    return pin.appendModel(flyer, model, frame, pin.SE3.Identity())


def without_free_flyer(model: pin.Model) -> pin.Model:
    """The model with its root free-flyer locked at the neutral pose (the frames' placements relative to the root
    body kept)."""
    return pin.buildReducedModel(model, [1], pin.neutral(model))
