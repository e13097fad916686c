"""Chain: a robot's serial chain from a base to a tool frame — a view of the whole robot
(:class:`~kinelab.robot.tree.Robot`, ``chain.robot``) with a model reduced to the chain, everything off it held.

Coordinates. kinelab speaks "one number per joint" (``q``, length ``robot.n``): an angle in rad for
revolute and continuous joints, a displacement in m for prismatic ones, in chain order base → tool.
Pinocchio stores a continuous joint as (cos, sin), so its configuration ``q_pin`` has ``robot.nq``
entries; ``to_pin_q``/``from_pin_q`` convert. Velocities and Jacobian columns need no conversion:
``nv == n`` for every joint kinelab accepts.

Frames. Poses are ``pin.SE3`` of a frame in the robot's base (root link) frame, named ``oM<frame>``.
Jacobians are 6 × n with rows [linear; angular] (Pinocchio's order); the method name states the frame.
"""

from __future__ import annotations

import functools
import itertools
import operator
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar, cast

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab import lazy
from kinelab.core._joints import PinForm, plain_q
from kinelab.errors import (
    ChainError,
    ConfigurationError,
    JointNotFoundError,
    OptionError,
    count_of,
)
from kinelab.geometry import pose_error, wrap_to_pi
from kinelab.robot import xacro
from kinelab.robot.build import Built, frame_id
from kinelab.robot.certificate import ChainArrays, FKCertificate, certify, chain_arrays
from kinelab.robot.checks import checked_q, checked_rows, named_configuration, outside_lines, real_values, rows_within
from kinelab.robot.joints import Joint, Mimic
from kinelab.robot.meshes import geometry_model, missing_meshes, search_dirs
from kinelab.robot.mjcf import is_mjcf
from kinelab.robot.poses import NEAR_SINGULAR as NEAR_SINGULAR  # the threshold, defined here before
from kinelab.robot.poses import best_conditioned, reference_of
from kinelab.robot.reduce import build_model
from kinelab.robot.space import LIMIT_SLACK, MAX_SAMPLE_BYTES, SAMPLE_TURNS, fixed_limits, generator, uniform
from kinelab.scratch import own

if TYPE_CHECKING:
    from kinelab.core import _verdict
    from kinelab.robot import Robot  # the package: tree.py imports this module
else:
    _verdict = lazy.module("kinelab.core._verdict", globals())

T = TypeVar("T")
__all__ = ["LIMIT_SLACK", "Chain", "Joint", "Mimic"]


_UNBUILT = object()  # derived(): no value kept yet under a key


class Chain:
    """A serial chain base → tool, with Pinocchio as the kinematic reference: a model, its joint space, its
    kinematics. It is a view of the whole robot (``robot``, built on first use where the chain came from a file;
    ``q_index`` places its joints in the whole robot's q).

    Build with :func:`kinelab.load` (a file or a registered name) or :meth:`Chain.from_model` (an in-memory
    ``pin.Model``); :mod:`kinelab.robot.build` makes every decision of the build, this class uses the result.
    Attributes: ``name``, ``source`` and ``urdf_path`` (None for an in-memory model), ``model``, ``data``,
    ``tool`` (frame name), ``tool_frame_id``, ``base``, ``joints``, ``joint_names``, ``lower``, ``upper``
    (one number per joint, rad or m), ``n``, ``nq``, ``nv``, ``locked``, ``mimics``, ``srdf``.
    """

    def __init__(self, built: Built):
        """A Chain over a build's result (:func:`kinelab.load` and :meth:`from_model` make one).

        Args:
            built: the frozen result of :mod:`kinelab.robot.build`.
        """
        self.name, self.source, self.urdf_path = built.name, built.source, built.urdf_path
        self.model, self.tool, self.base = fixed_limits(built.model), built.tool, built.base
        self.joints, self.mimics, self.locked = list(built.joints), built.mimics, built.locked
        self.srdf, self.package_dirs = built.srdf, built.package_dirs
        self.xacro_args, self.trust_xacro = built.xacro_args, built.trust_xacro
        self._built = built
        if built.source is not None and built.urdf_path is not None and built.urdf_path != built.source:
            own(self, built.urdf_path.parent)  # a xacro expansion: it lives as long as this robot
        self.data = self.model.createData()
        self.tool_frame_id = frame_id(self.model, self.tool, self.name)
        self._index_joints()
        self._length: float | None = None
        self._derived: dict[str, Any] = {}
        self._whole: Robot | None = None
        self._whole_factory: Callable[[], Robot] | None = None
        self.display_pose: np.ndarray | None = None
        """The registered pose to show the robot in (:meth:`display_q`), or None."""

    @classmethod
    def from_model(cls, model: pin.Model, *, tool: str | None = None, base: str | None = None,
                   locked: dict[str, float] | None = None, name: str | None = None) -> Chain:
        """A Chain from an in-memory Pinocchio model (what pink and mink take), reduced to base → tool.

        Args:
            model: the whole robot's ``pin.Model`` (copied; yours is left as it is).
            tool: the tool frame (default: a frame named ``tool``, else the single leaf body).
            base: the frame the chain starts from (default: the model's root); poses are in this frame.
            locked: joints held fixed, name → value [rad or m]; joints off the chain are held at zero.
            name: the robot's name (default: the model's).

        Returns:
            The Chain (no file behind it: ``source`` and ``urdf_path`` are None, the viewer draws a stick figure).

        Raises:
            ChainError, FrameNotFoundError, JointNotFoundError, ConfigurationError, JointLimitError: named.
        """
        return cls(build_model(model, tool=tool, locked=locked, name=name, base=base))

    def attach(self, robot: Robot | Callable[[], Robot]) -> Chain:
        """Make ``robot`` (the whole model this chain was cut from, or how to build it on first use) the chain's
        ``robot``; returns self."""
        if callable(robot) and not hasattr(robot, "model"):
            self._whole_factory = robot
        else:
            self._whole = cast("Robot", robot)
        return self

    @property
    def robot(self) -> Robot:
        """The whole robot this chain is a view of (a file's built on first use, fixed base).

        Raises:
            ChainError: a chain cut from an in-memory model by ``Chain.from_model`` (``Robot.from_model(model)
                .chain(base, tool)`` keeps its robot).
        """
        if self._whole is None:
            if self._whole_factory is None:
                raise ChainError(f"{self.name} was cut from an in-memory model with Chain.from_model; "
                                 "kinelab.Robot.from_model(model).chain(base, tool) keeps the whole robot")
            self._whole = self._whole_factory()
        return self._whole

    @property
    def q_index(self) -> np.ndarray:
        """(n,) the index in the whole robot's q of each chain joint (its first entry: a continuous joint has two,
        cos then sin)."""
        model = self.robot.model
        return np.array([model.joints[model.getJointId(name)].idx_q for name in self.joint_names], dtype=int)

    def in_whole(self, q: ArrayLike, q_whole: ArrayLike | None = None) -> np.ndarray:
        """The whole robot's q with this chain's joints at q [rad or m] (the others as in ``q_whole``, default
        the whole robot's neutral configuration).

        Raises:
            ConfigurationError: q is not a configuration of this chain, or q_whole not one of the robot.
        """
        whole = self.robot
        out = whole.neutral() if q_whole is None else whole.check_q(q_whole, what="q_whole").copy()
        values = self.check_q(q)
        for k, i in enumerate(self.q_index):
            if self.joint_kinds[k] == "continuous":
                out[i], out[i + 1] = np.cos(values[k]), np.sin(values[k])
            else:
                out[i] = values[k]
        return out

    def _index_joints(self) -> None:
        """Names, kinds, limits and the index maps between kinelab's q and Pinocchio's."""
        self.joint_names = [j.name for j in self.joints]
        self.joint_kinds = [j.kind for j in self.joints]
        self.lower = _read_only(np.array([j.lower for j in self.joints]))
        self.upper = _read_only(np.array([j.upper for j in self.joints]))
        self.n, self.nq, self.nv = len(self.joints), self.model.nq, self.model.nv
        continuous = np.array([k == "continuous" for k in self.joint_kinds], dtype=bool)
        idx_q = np.array([j.idx_q for j in self.joints], dtype=int)
        self._scalar_pos = np.flatnonzero(~continuous)
        self._scalar_idx = idx_q[~continuous]
        self._cont_pos = np.flatnonzero(continuous)
        self._cont_idx = idx_q[continuous]
        self._identity_q = self.nq == self.n and bool(np.all(self._scalar_idx == np.arange(self.n)))
        order = np.argsort(idx_q)  # Pinocchio's q in its own order: kinelab's position and kind per joint
        self._pin_form = PinForm(np.ascontiguousarray(order, dtype=np.intp),
                                 np.ascontiguousarray(continuous[order], dtype=np.uint8), self.nq)
        self._lower_check = np.where(continuous, -np.inf, self.lower)
        self._upper_check = np.where(continuous, np.inf, self.upper)
        # the same bounds with the default slack, as Python floats: a solve checks limits twice, and a
        # loop over seven floats costs a fifth of the numpy expression
        self.check_bounds = (self._lower_check - LIMIT_SLACK, self._upper_check + LIMIT_SLACK)
        """(lower, upper) that :meth:`within_limits` compares with: the limits widened by LIMIT_SLACK,
        ∓inf for continuous joints."""
        self._lower_list = (self._lower_check - LIMIT_SLACK).tolist()
        self._upper_list = (self._upper_check + LIMIT_SLACK).tolist()

    @property
    def source_format(self) -> str:
        """The format of the file the robot was read from: "URDF", "xacro" or "MJCF" ("pin.Model": none)."""
        if self.source is None or self.urdf_path is None:
            return "pin.Model"
        if xacro.is_xacro(self.source):
            return "xacro"
        return "MJCF" if is_mjcf(self.urdf_path) else "URDF"

    def derived(self, key: str, build: Callable[[Chain], T]) -> T:
        """Data derived from this robot (a solver's chain arrays, say), built on first use and kept here,
        so it lives exactly as long as the Chain."""
        found = self._derived.get(key, _UNBUILT)
        if found is _UNBUILT:  # a builder may answer None (nothing to build): that is kept too
            found = self._derived[key] = build(self)
        return found

    def named_q(self, name: str) -> np.ndarray:
        """The chain configuration [rad or m] of the SRDF's named configuration ``name`` (``group_state``).

        Raises:
            SRDFError: no SRDF, an unknown name (the names listed), or a chain joint the configuration omits.
            JointLimitError: a value outside its joint's limits (the joint named).
        """
        return named_configuration(self, name)

    # -- coordinates ---------------------------------------------------------------------------
    def joint_index(self, name: str) -> int:
        """Position of joint ``name`` in kinelab's q (raises JointNotFoundError with the valid names)."""
        if not isinstance(name, str) or name not in self.joint_names:
            raise JointNotFoundError(name, self.joint_names)
        return self.joint_names.index(name)

    def _values(self, q: ArrayLike, what: str) -> np.ndarray:
        """``q`` as n floats (NaN and ±inf kept); ConfigurationError for another shape or a non-real type."""
        return real_values(self, q, what)

    def check_q(self, q: ArrayLike, *, limits: bool = False, what: str = "q") -> np.ndarray:
        """``q`` as a float array of length n, refusing wrong shapes, NaN/inf and (if asked) limits."""
        if not limits and plain_q(q, self.n):  # the usual call, checked in one compiled pass
            arr = cast(np.ndarray, q)
            return arr if arr.flags.c_contiguous else np.ascontiguousarray(arr)  # a strided view: the kernels' form
        return checked_q(self, q, limits, what)

    def within_limits(self, q: ArrayLike, slack: float = LIMIT_SLACK) -> bool:
        """True when every bounded joint lies within its limits (plus ``slack``); continuous joints have none; a
        NaN is within none.

        Raises:
            ConfigurationError: q is not n real numbers.
        """
        fast = type(q) is np.ndarray and q.shape == (self.n,) and q.dtype == np.float64
        arr = cast(np.ndarray, q) if fast else self._values(q, "q")
        if slack == LIMIT_SLACK:
            values = arr.tolist()
            return all(map(operator.le, self._lower_list, values)) and all(map(operator.le, values, self._upper_list))
        return bool((arr >= self._lower_check - slack).all() and (arr <= self._upper_check + slack).all())

    def outside_limits(self, q: ArrayLike) -> list[str]:
        """One line per joint of ``q`` outside its limits (beyond LIMIT_SLACK), naming the joint, the value and the
        limits; empty when q is within them (continuous joints have none)."""
        return outside_lines(self, q)

    def within_limits_batch(self, Q: np.ndarray) -> np.ndarray:
        """:meth:`within_limits` per row of a (B, n) array (default slack): a (B,) bool array; a NaN row is within
        none.

        Raises:
            ConfigurationError: Q is not a (B, n) array of numbers.
        """
        return rows_within(self, Q)

    def to_pin_q(self, q: ArrayLike) -> np.ndarray:
        """One number per joint → Pinocchio's q (continuous joints become cos, sin); a new array."""
        pin_q = self._pin_q(q)
        return pin_q.copy() if pin_q is q else pin_q

    def _pin_q(self, q: ArrayLike) -> np.ndarray:
        """Pinocchio's q for reading only: q itself when the two orders coincide (no copy)."""
        usual = self._pin_form.usual(q)  # a plain q, checked and converted in one compiled call
        return self._checked_pin_q(q) if usual is None else usual

    def _checked_pin_q(self, q: ArrayLike) -> np.ndarray:
        """:meth:`_pin_q` for any other q: the checks that name what is wrong, then the conversion."""
        arr = self.check_q(q)
        if self._identity_q:
            return arr
        return self._pin_form.of(arr)

    def from_pin_q(self, q_pin: ArrayLike) -> np.ndarray:
        """Pinocchio's q → one number per joint (continuous joints as atan2(sin, cos) in (−π, π])."""
        q_pin = np.asarray(q_pin, dtype=float)
        if q_pin.shape != (self.nq,):
            raise ConfigurationError(f"Pinocchio q must have nq = {self.nq} entries, got {count_of(q_pin.shape)}")
        out = np.empty(self.n)
        out[self._scalar_pos] = q_pin[self._scalar_idx]
        out[self._cont_pos] = np.arctan2(q_pin[self._cont_idx + 1], q_pin[self._cont_idx])
        return out

    def wrap_continuous(self, q: ArrayLike) -> np.ndarray:
        """q with continuous joints wrapped into (−π, π] (the same pose)."""
        q = np.array(self.check_q(q))
        if self._cont_pos.size:
            q[self._cont_pos] = wrap_to_pi(q[self._cont_pos])
        return q

    def neutral(self) -> np.ndarray:
        """Zero for every joint, moved into its limits where zero is outside them."""
        return np.clip(np.zeros(self.n), self.lower, self.upper)

    def display_q(self) -> np.ndarray:
        """A pose to show the robot in when none is given [rad, m]: the registered display pose, else the
        best-conditioned of 64 evenly spread configurations in the middle half of each joint's range (largest
        σ_min/σ_max of the tool Jacobian, linear rows divided by the characteristic length). All-zero poses
        are often singular (a stretched arm), which makes a poor first picture."""
        if self.display_pose is not None:
            return np.array(self.display_pose, dtype=float)
        return np.array(self.derived("display_q", best_conditioned), dtype=float)

    def reference_q(self) -> tuple[np.ndarray, str]:
        """The configuration a command starts from when given none [rad, m], and where it comes from in words: the
        SRDF's configuration named "home" (or "ready") when the robot was loaded with an SRDF that has one, else
        the middle of each joint's limits (0 for a continuous joint, and for a revolute joint whose limits span
        more turns than :meth:`random_q` draws from) when it is well conditioned, else :meth:`display_q` (a UR5's
        middle is all zeros: stretched flat, singular). Well conditioned: σ_min/σ_max of the tool Jacobian (linear
        rows divided by the characteristic length) at least ``NEAR_SINGULAR``, the threshold of
        :mod:`kinelab.analysis.singular`."""
        return reference_of(self)

    def random_q(self, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """A configuration drawn uniformly within the limits (continuous joints on [−π, π]; a revolute joint
        whose limits lie beyond ±SAMPLE_TURNS turns, such as a rotor declared with ±1e16 rad, on ±SAMPLE_TURNS
        turns: every pose it can take, at angles where rounding does not swamp a step)."""
        return uniform(generator(rng), *self.sample_bounds, None)

    def random_qs(self, count: int, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """``count`` configurations (rows) drawn as :meth:`random_q` draws one.

        Raises:
            OptionError: a count that is not a whole number ≥ 0, or whose rows would take more than 8 GiB.
        """
        if not isinstance(count, int | np.integer) or isinstance(count, bool) or count < 0:
            raise OptionError("count", count, "a whole number ≥ 0 of configurations")
        if int(count) * self.n * 8 > MAX_SAMPLE_BYTES:
            raise OptionError("count", count, f"at most {MAX_SAMPLE_BYTES // (8 * self.n)} configurations of "
                              f"{self.name} (their rows would take more than {MAX_SAMPLE_BYTES >> 30} GiB)")
        return uniform(generator(rng), *self.sample_bounds, (int(count), self.n))

    @functools.cached_property
    def sample_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) that random configurations are drawn between [rad or m] (see :meth:`random_q`)."""
        revolute = np.array([k != "prismatic" for k in self.joint_kinds])
        span = SAMPLE_TURNS * 2 * np.pi
        return (np.where(revolute, np.maximum(self.lower, -span), self.lower),
                np.where(revolute, np.minimum(self.upper, span), self.upper))

    # -- kinematics ----------------------------------------------------------------------------
    def _forward(self, q: ArrayLike) -> None:
        pin.forwardKinematics(self.model, self.data, self._pin_q(q))
        pin.updateFramePlacements(self.model, self.data)

    def fk(self, q: ArrayLike) -> pin.SE3:
        """oMtool: pose of the tool frame in the base frame at ``q`` (m, rad); a new SE3 (Pinocchio's
        ``updateFramePlacement`` returns the tool frame's placement by value)."""
        q_pin = self._pin_form.usual(q)  # one compiled call for a plain q; else the checks that name what is wrong
        pin.forwardKinematics(self.model, self.data, self._checked_pin_q(q) if q_pin is None else q_pin)
        return pin.updateFramePlacement(self.model, self.data, self.tool_frame_id)

    def fk_batch(self, Q: np.ndarray) -> np.ndarray:
        """oMtool for every row of Q (B × n, rad or m): a (B, 4, 4) stack of homogeneous matrices, by the judge
        :attr:`fk_certificate` names (the compiled FK where it is certified equal to Pinocchio's, else Pinocchio's).

        Raises:
            ConfigurationError: Q not (B, n) finite numbers (the first bad row named).
        """
        Q = self.check_qs(Q)
        arrays = self._judge_arrays()
        if arrays is not None:
            return arrays.fk_batch(Q)
        out = np.empty((Q.shape[0], 4, 4))
        model, data, fid = self.model, self.data, self.tool_frame_id
        for b in range(Q.shape[0]):
            pin.forwardKinematics(model, data, self._pin_q(Q[b]))
            out[b] = pin.updateFramePlacement(model, data, fid).homogeneous
        return out

    @property
    def fk_certificate(self) -> FKCertificate:
        """How this robot's answers are judged: the compiled chain FK, certified against Pinocchio's FK at seeded
        configurations including every joint's limits (≤ 1e-12 m and rad), or Pinocchio's FK with the reason
        (:mod:`kinelab.robot.certificate`). Computed on first use, kept with the robot."""
        return self.derived("fk certificate", certify)

    def verdict(self, H_target: np.ndarray, q: np.ndarray, axis: int = -1) -> tuple[float, float, bool]:
        """The judge's word on an answer: (position error [m], rotation error [rad], q within the limits) of q (n
        finite floats, C-contiguous) against the target (4 × 4 homogeneous, base frame), by the FK
        :attr:`fk_certificate` names. The rotation error is the angle of R*ᵀR, or with ``axis`` = 0, 1, 2 the angle
        between that tool axis and the target's (task "axis")."""
        judge = self.derived("compiled judge", _compiled_judge)
        lower, upper = self.check_bounds
        if judge is not None:
            found: tuple[float, float, bool] = judge.verdict(H_target, q, lower, upper, axis)
            return found

        return _verdict.pose_verdict(H_target, self.tool_pose_of_float_q(q).homogeneous, q, lower, upper, axis)

    def _judge_arrays(self) -> ChainArrays | None:
        """The chain's arrays when the compiled FK is this robot's judge, else None."""
        return self.derived("judge arrays", _judge_arrays)

    def jacobian_batch(self, Q: np.ndarray, frame: str = "local") -> np.ndarray:
        """The 6 × n tool Jacobian for every row of Q: (B, 6, n), rows [v; ω].

        Args:
            Q: (B, n) configurations [rad or m].
            frame: "local" (tool frame), "world" (base frame, v at the base origin) or
                "local_world_aligned" (base axes at the tool origin: from the compiled chain where it is this
                robot's certified judge, Pinocchio's to rounding; else Pinocchio's own, as the other two are).

        Raises:
            ConfigurationError: Q not (B, n) finite numbers; OptionError: an unknown frame.
        """
        frames = {"local": pin.LOCAL, "world": pin.WORLD, "local_world_aligned": pin.LOCAL_WORLD_ALIGNED}
        if frame not in frames:
            raise OptionError("frame", frame, f"one of {sorted(frames)}")
        Q = self.check_qs(Q)
        arrays = self._judge_arrays() if frame == "local_world_aligned" and self.n else None
        if arrays is not None:
            return arrays.jacobian_batch(Q)
        return np.stack([self._jacobian(q, frames[frame]) for q in Q]) if Q.shape[0] else np.empty((0, 6, self.n))

    def check_qs(self, Q: np.ndarray, what: str = "Q") -> np.ndarray:
        """Q as a (B, n) float array of finite numbers, refusing other shapes and naming the first bad row."""
        return checked_rows(self, Q, what)

    def tool_error(self, q: ArrayLike, oMtarget: pin.SE3) -> tuple[float, float]:
        """(position error [m], rotation angle error [rad]) of the tool at q against oMtarget (Pinocchio FK)."""
        return pose_error(oMtarget, self.tool_pose_of_float_q(self.check_q(q)))

    def tool_pose_of_float_q(self, q: np.ndarray) -> pin.SE3:
        """oMtool (Pinocchio FK) for a q known to be n finite floats (a solver's answer): no check repeated."""
        pin.forwardKinematics(self.model, self.data, q if self._identity_q else self._pin_q(q))
        return pin.updateFramePlacement(self.model, self.data, self.tool_frame_id)

    def frame_placement(self, q: ArrayLike, frame: str) -> pin.SE3:
        """oMframe: pose of any frame of the reduced model in the base frame."""
        fid = frame_id(self.model, frame, self.name)
        self._forward(q)
        return pin.SE3(self.data.oMf[fid])

    def joint_placements(self, q: ArrayLike) -> dict[str, pin.SE3]:
        """oMjoint for every chain joint: the joint frame (after its motion) in the base frame."""
        self._forward(q)
        return {j.name: pin.SE3(self.data.oMi[self.model.getJointId(j.name)]) for j in self.joints}

    def _jacobian(self, q: ArrayLike, frame: pin.ReferenceFrame) -> np.ndarray:
        q_pin = self._pin_form.usual(q)
        if q_pin is None:
            q_pin = self._checked_pin_q(q)
        J: np.ndarray = pin.computeFrameJacobian(self.model, self.data, q_pin, self.tool_frame_id, frame)
        return J if J.ndim == 2 else J.reshape(6, self.nv)  # a 1-DoF chain comes back as a flat 6-vector

    def jacobian_local(self, q: ArrayLike) -> np.ndarray:
        """6 × n tool Jacobian in the tool frame (LOCAL): twist [v; ω] of the tool in its own axes."""
        return self._jacobian(q, pin.LOCAL)

    def jacobian_world(self, q: ArrayLike) -> np.ndarray:
        """6 × n tool Jacobian in the base frame (WORLD): spatial twist, v at the base origin."""
        return self._jacobian(q, pin.WORLD)

    def jacobian_local_world_aligned(self, q: ArrayLike) -> np.ndarray:
        """6 × n tool Jacobian with base axes at the tool origin (LOCAL_WORLD_ALIGNED)."""
        return self._jacobian(q, pin.LOCAL_WORLD_ALIGNED)

    def integrate(self, q: ArrayLike, dq: ArrayLike) -> np.ndarray:
        """q ⊕ dq through ``pin.integrate`` (dq: n velocities × 1 s), back in one-number-per-joint form."""
        dq = self.check_q(dq, what="dq")
        return self.from_pin_q(pin.integrate(self.model, self.to_pin_q(q), dq))

    def difference(self, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
        """q1 ⊖ q0 through ``pin.difference``: the n velocities that take q0 to q1 in 1 s."""
        return np.asarray(pin.difference(self.model, self.to_pin_q(q0), self.to_pin_q(q1)), dtype=float)

    def visual_model(self, package_dirs: list[str] | None = None, kind: str = "visual") -> pin.GeometryModel:
        """Visual (or, ``kind="collision"``, collision) geometry matched to ``self.model`` (locked joints
        folded in, re-rooted as the model is), meshes resolved.

        ``package://`` URIs resolve under ``package_dirs`` (default: those given to :func:`load`, then
        ``ROS_PACKAGE_PATH``'s, then example-robot-data's); elements whose mesh cannot be found are left out
        with a warning naming the directories searched.
        """
        return geometry_model(self, package_dirs, kind)

    def missing_meshes(self, package_dirs: list[str] | None = None, kind: str = "visual") -> list[str]:
        """The mesh URIs of the file's ``<visual>`` (or ``<collision>``) elements that :meth:`visual_model`, looking
        where it looks, cannot find (none for an in-memory model or an MJCF file)."""
        path = self._built.urdf_path
        if path is None or is_mjcf(path):
            return []
        return missing_meshes(path, search_dirs(package_dirs or self.package_dirs), kind)

    @property
    def frame_names(self) -> list[str]:
        """Every frame of the reduced model, by name."""
        return [f.name for f in self.model.frames]

    def characteristic_length(self) -> float:
        """Mean distance between consecutive joint origins and the tool at the neutral pose [m].

        A length scale to weigh linear against angular quantities (IK objectives, Jacobian rank).
        """
        if self._length is None:
            self._length = self._mean_joint_spacing()
        return self._length

    def _mean_joint_spacing(self) -> float:
        oMi = self.joint_placements(self.neutral())
        pts = [m.translation for m in oMi.values()] + [self.fk(self.neutral()).translation]
        steps = [np.linalg.norm(b - a) for a, b in itertools.pairwise(pts)]
        positive = [s for s in steps if s > 1e-9]
        return float(np.mean(positive)) if positive else 1.0

    def __repr__(self) -> str:
        return f"Chain({self.name!r}, n={self.n}, tool={self.tool!r}, urdf={str(self.urdf_path)!r})"


def _judge_arrays(robot: Chain) -> ChainArrays | None:
    arrays = chain_arrays(robot) if robot.fk_certificate.certified else None
    return arrays if isinstance(arrays, ChainArrays) else None


def _compiled_judge(robot: Chain) -> Any:
    arrays = robot._judge_arrays()
    return None if arrays is None else arrays.judge()


def _read_only(arr: np.ndarray) -> np.ndarray:
    arr.flags.writeable = False  # the checks derived from the limits would not see an edit
    return arr
