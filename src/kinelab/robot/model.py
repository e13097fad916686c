"""Robot: a URDF loaded into Pinocchio, reduced to the serial chain from the base to a tool frame.

Coordinates. kinelab speaks "one number per joint" (``q``, length ``robot.n``): an angle in rad for
revolute and continuous joints, a displacement in m for prismatic ones, in chain order base → tool.
Pinocchio stores a continuous joint as (cos, sin), so its configuration ``q_pin`` has ``robot.nq``
entries; ``to_pin_q``/``from_pin_q`` convert. Velocities and Jacobian columns need no conversion:
``nv == n`` for every joint kinelab accepts.

Frames. Poses are ``pin.SE3`` of a frame in the robot's base (root link) frame, named ``oM<frame>``.
Jacobians are 6 × n with rows [linear; angular] (Pinocchio's order); the method name states the frame.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import math
import operator
import os
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar, cast

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinelab.errors import (
    ChainError,
    ConfigurationError,
    FrameNotFoundError,
    JointLimitError,
    JointNotFoundError,
    OptionError,
    SRDFError,
    URDFError,
)
from kinelab.geometry import pose_error, wrap_to_pi
from kinelab.robot import catalog, descriptions, xacro
from kinelab.robot.meshes import build_visual_model, mesh_package_dirs
from kinelab.robot.mjcf import is_mjcf, read_mjcf
from kinelab.robot.srdf import Srdf, read_srdf
from kinelab.robot.urdf import UrdfTree, read_tree

_REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
_PRISMATIC = {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}
_CONTINUOUS = {"JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"}
T = TypeVar("T")
MAX_DATA_BYTES = 2**31  # 2 GiB for one Pinocchio Data (see data_bytes)
LIMIT_SLACK = 1e-9  # joint values this far past a limit still count as within it (rad or m)


@dataclass(frozen=True)
class Joint:
    """One chain joint: ``kind`` is revolute, prismatic or continuous; limits in rad or m."""

    name: str
    kind: str
    lower: float
    upper: float
    idx_q: int  # first index in Pinocchio's q
    idx_v: int  # index in Pinocchio's v (and Jacobian column)
    axis_local: tuple[float, float, float]

    @property
    def unit(self) -> str:
        return "m" if self.kind == "prismatic" else "rad"


@dataclass(frozen=True)
class Mimic:
    """A chain joint that follows another: q_follower = multiplier · q_leader + offset (rad or m)."""

    name: str
    leader: str
    multiplier: float
    offset: float
    lower: float  # the follower's own limits
    upper: float


def _narrowed(leader: str, lo: float, hi: float, mimics: Iterable[Mimic]) -> tuple[float, float]:
    """The leader's limits narrowed so that every follower stays within its own (an empty range: ChainError)."""
    for m in mimics:
        if m.leader == leader and m.multiplier != 0.0:
            a, b = sorted(((m.lower - m.offset) / m.multiplier, (m.upper - m.offset) / m.multiplier))
            lo, hi = max(lo, a), min(hi, b)
            if lo > hi:
                raise ChainError(f"joint {m.name!r} mimics {leader!r}: no value of {leader!r} keeps both "
                                 "within their limits")
    return lo, hi


def _build_full_model(path: Path, mimic: bool = False) -> pin.Model:
    said: list[str] = []
    try:
        with _c_stderr_captured(said):  # urdfdom prints its complaints on the process's stderr
            model = pin.buildModelFromUrdf(str(path), mimic=mimic)
    except (RuntimeError, ValueError, UnicodeDecodeError) as exc:
        detail = " ".join([str(exc), *said]).strip()
        raise URDFError(f"Pinocchio cannot read {path}: {detail}") from None
    if said:
        warnings.warn(f"Pinocchio's URDF parser on {path.name}: {' '.join(said)}", stacklevel=3)
    return model


@contextlib.contextmanager
def _c_stderr_captured(said: list[str]) -> Iterator[None]:
    """File descriptor 2 redirected to a temporary file for the block; its lines appended to ``said``."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            said.extend(line.strip() for line in sink.read().decode("utf-8", "replace").splitlines() if line.strip())


def _frame_id(model: pin.Model, name: str, robot: str) -> int:
    """Id of frame ``name``, preferring the link (BODY) frame where a joint shares the name."""
    body = [i for i, f in enumerate(model.frames) if f.name == name and f.type == pin.FrameType.BODY]
    if body:
        return body[0]
    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    if not ids:
        raise FrameNotFoundError(name, [f.name for f in model.frames], robot)
    return ids[0]


def _kind(joint_model: pin.JointModel) -> str | None:
    short = joint_model.shortname()
    if short in _REVOLUTE:
        return "revolute"
    if short in _PRISMATIC:
        return "prismatic"
    if short in _CONTINUOUS:
        return "continuous"
    return None


def _locked_value(full: pin.Model, jid: int, value: object) -> float:
    """A user's locked value for joint jid: a finite number within the joint's limits."""
    name = full.names[jid]
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ConfigurationError(f"locked[{name!r}] must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ConfigurationError(f"locked[{name!r}] is {number}: locked values must be finite")
    iq = full.idx_qs[jid]
    if full.joints[jid].nq == 1:
        lo, hi = float(full.lowerPositionLimit[iq]), float(full.upperPositionLimit[iq])
        if not lo - LIMIT_SLACK <= number <= hi + LIMIT_SLACK:
            raise JointLimitError(name, number, lo, hi)
    return number


SAMPLE_TURNS = 4  # random configurations keep revolute joints within ±4 turns (see Robot.random_q)


def data_bytes(nv: int) -> int:
    """Bytes a Pinocchio Data takes for nv velocities: it allocates nv × nv × nv tensors (second-order
    derivatives) and a 6 × nv × nv one, whatever the algorithms used, so its size grows as nv³."""
    return 8 * (8 * nv**3 + 6 * nv**2 + 64 * nv)  # measured: 513 MB at nv = 200, 1.7 GB at nv = 300


def _check_data_size(model: pin.Model, name: str) -> None:
    need = data_bytes(model.nv)
    if need > MAX_DATA_BYTES:
        raise ChainError(
            f"{name}: the chain has {model.nv} joints, and a Pinocchio Data for it would take about "
            f"{need / 2**30:.1f} GiB (Pinocchio allocates nv³-sized tensors); kinelab loads chains whose Data "
            f"fits in {MAX_DATA_BYTES / 2**30:g} GiB (about {max_joints()} joints)"
        )


def max_joints() -> int:
    """The longest chain whose Pinocchio Data fits in MAX_DATA_BYTES."""
    nv = 1
    while data_bytes(nv + 1) <= MAX_DATA_BYTES:
        nv += 1
    return nv


def _read_only(arr: np.ndarray) -> np.ndarray:
    arr.flags.writeable = False  # the checks derived from the limits would not see an edit
    return arr


def _one_to_pin(kind: str, value: float) -> list[float]:
    return [np.cos(value), np.sin(value)] if kind == "continuous" else [value]


class Robot:
    """A serial chain base → tool, with Pinocchio as the kinematic reference.

    Build with :func:`kinelab.load`. Joints off the base → tool path (fingers, other branches) are
    locked; ``locked`` locks chain joints too. Attributes: ``name``, ``urdf_path``, ``model``,
    ``data``, ``tool`` (frame name), ``tool_frame_id``, ``joints``, ``joint_names``, ``lower``,
    ``upper`` (one number per joint, rad or m), ``n``, ``nq``, ``nv``, ``locked``.
    """

    def __init__(
        self,
        urdf_path: str | Path,
        tool: str | None = None,
        locked: dict[str, float] | None = None,
        name: str | None = None,
        base: str | None = None,
        package_dirs: list[str] | None = None,
        srdf: str | Path | None = None,
        group: str | None = None,
        xacro_args: dict[str, str] | None = None,
        trust_xacro: bool = False,
    ):
        self.source = Path(urdf_path)
        self.xacro_args, self.trust_xacro = dict(xacro_args or {}), bool(trust_xacro)
        self.urdf_path = xacro.expand(self.source, xacro_args, trusted=self.trust_xacro) \
            if xacro.is_xacro(self.source) else self.source
        self.package_dirs = mesh_package_dirs(package_dirs)
        if is_mjcf(self.urdf_path):
            full, tree = read_mjcf(self.urdf_path)
        else:
            tree = read_tree(self.urdf_path)
            full = _build_full_model(self.urdf_path)
        self.name = name or full.name or self.urdf_path.stem
        self.srdf = self._read_srdf(srdf, tree)
        if group is not None:
            tool, base = self._group_frames(group, tree, tool, base)
        self.base = base or tree.root
        self.tool = tool or self._default_tool(tree, full)
        chain = self._chain(full, base)
        self.mimics: dict[str, Mimic] = {}
        """Chain joints that follow another chain joint (URDF ``<mimic>``): name → :class:`Mimic`."""
        if any(full.names[j] in tree.mimic and full.names[j] not in (locked or {}) for j in chain):
            full, chain = self._with_mimics(full, chain, tree, base)
        self._check_chain(full, chain, tree)
        tree.check_mimics(self.urdf_path, [full.names[j] for j in chain], (locked or {}))
        reference = self.srdf.reference() if self.srdf else {}
        held = {j: v for j, v in reference.items() if full.existJointName(j) and full.getJointId(j) not in chain}
        self.locked = self._locked_values(full, chain, {**held, **(locked or {})})
        self._bMw: pin.SE3 | None = None
        self._reduce(full)
        if base is not None and base != tree.root:
            self._reroot(base)
        self._index_joints()
        self._length: float | None = None
        self._derived: dict[str, Any] = {}
        self.display_pose: np.ndarray | None = None
        """The registered pose to show the robot in (:meth:`display_q`), or None."""

    def _reduce(self, full: pin.Model) -> None:
        """The model with every locked joint folded in at its value, and its joint table."""
        q_ref = pin.neutral(full)
        for jname, value in self.locked.items():
            jid = full.getJointId(jname)
            kind = _kind(full.joints[jid])
            if kind is None:  # a free or spherical joint above the chain: held at its neutral pose
                continue
            nq = full.joints[jid].nq
            q_ref[full.idx_qs[jid] : full.idx_qs[jid] + nq] = _one_to_pin(kind, value)[:nq]
        lock_ids = [full.getJointId(j) for j in self.locked]
        self._full, self._lock_ids, self._q_ref = full, lock_ids, q_ref
        try:
            self.model = pin.buildReducedModel(full, lock_ids, q_ref) if lock_ids else full
        except ValueError as exc:  # Pinocchio cannot fold a locked joint whose name a link also bears
            raise ChainError(f"{self.name}: Pinocchio cannot lock the joints off the chain ({exc}); give "
                             "another tool= or base=") from None
        _check_data_size(self.model, self.name)
        self.data = self.model.createData()
        self.tool_frame_id = _frame_id(self.model, self.tool, self.name)
        self.joints = self._joint_table()
        if not self.joints:
            raise ChainError(f"{self.name}: no movable joint between the base and frame {self.tool!r}")

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
        """The format of the file the robot was read from: "URDF", "xacro" or "MJCF"."""
        if xacro.is_xacro(self.source):
            return "xacro"
        return "MJCF" if is_mjcf(self.urdf_path) else "URDF"

    def derived(self, key: str, build: Callable[[Robot], T]) -> T:
        """Data derived from this robot (a solver's chain arrays, say), built on first use and kept here,
        so it lives exactly as long as the Robot."""
        if key not in self._derived:
            self._derived[key] = build(self)
        return cast(T, self._derived[key])

    # -- construction ------------------------------------------------------------------------
    @staticmethod
    def _default_tool(tree: UrdfTree, full: pin.Model) -> str:
        if any(f.name == "tool" for f in full.frames):
            return "tool"
        if len(tree.leaves) == 1:
            return tree.leaves[0]
        raise ChainError(
            f"the tool frame is ambiguous: {tree.root!r} branches into {len(tree.leaves)} leaf links "
            f"({', '.join(tree.leaves[:12])}{', ...' if len(tree.leaves) > 12 else ''}); pass tool=NAME"
        )

    @staticmethod
    def _check_chain(full: pin.Model, chain: list[int], tree: UrdfTree) -> None:
        for jid in chain:
            jname = full.names[jid]
            if full.joints[jid].shortname() == "JointModelMimic":
                continue  # follows its leader (Robot._with_mimics checked it is on the chain)
            if _kind(full.joints[jid]) is None:
                raise ChainError(
                    f"joint {jname!r} is a {full.joints[jid].shortname()}: kinelab chains take revolute, "
                    "continuous and prismatic joints only"
                )

    def _chain(self, full: pin.Model, base: str | None) -> list[int]:
        """Joint ids from the base (or the root) to the tool frame."""
        tool_id = _frame_id(full, self.tool, self.name)
        chain = [j for j in full.supports[full.frames[tool_id].parentJoint] if j != 0]
        return self._below_base(full, chain, base) if base is not None else chain

    def _with_mimics(self, plain: pin.Model, chain: list[int], tree: UrdfTree,
                     base: str | None) -> tuple[pin.Model, list[int]]:
        """Pinocchio's model with its mimic joints (a follower has no coordinate of its own), the chain in it,
        and ``self.mimics``; each leader's limits narrowed so that its followers stay within theirs."""
        for jid in chain:
            name = plain.names[jid]
            if name in tree.mimic and plain.getJointId(tree.mimic[name]) not in chain:
                raise ChainError(f"joint {name!r} mimics {tree.mimic[name]!r}, which is off the base-tool chain: "
                                 f"hold it at a value (locked={{{name!r}: value}}) or choose another tool frame")
        full = _build_full_model(self.urdf_path, mimic=True)
        for jid in range(1, full.njoints):
            follower = full.joints[jid].extract()
            if full.joints[jid].shortname() == "JointModelMimic" and jid in self._chain(full, base):
                name, leader = full.names[jid], tree.mimic[full.names[jid]]
                iq = plain.idx_qs[plain.getJointId(name)]
                self.mimics[name] = Mimic(name, leader, float(follower.scaling), float(follower.offset),
                                          float(plain.lowerPositionLimit[iq]), float(plain.upperPositionLimit[iq]))
        return full, self._chain(full, base)

    @staticmethod
    def _read_srdf(srdf: str | Path | None, tree: UrdfTree) -> Srdf | None:
        if srdf is None:
            return None
        found = read_srdf(srdf)
        found.check_joints(list(tree.joint_of.values()))
        return found

    def _group_frames(self, group: str, tree: UrdfTree, tool: str | None, base: str | None) -> tuple[str, str | None]:
        """(tool, base) for an SRDF group: those given win over the group's."""
        if self.srdf is None:
            raise SRDFError(f"group={group!r} needs srdf= (the file that defines the group)")
        g_tool, g_base = self.srdf.tool_and_base(group, {j: link for link, j in tree.joint_of.items()})
        return tool or g_tool, base or g_base

    def named_q(self, name: str) -> np.ndarray:
        """The chain configuration [rad or m] of the SRDF's named configuration ``name`` (``group_state``).

        Raises:
            SRDFError: no SRDF, an unknown name (the names listed), or a chain joint the configuration omits.
        """
        if self.srdf is None:
            raise SRDFError(f"{self.name} was loaded without an SRDF: load(..., srdf=PATH) to use named "
                            "configurations")
        values = self.srdf.state(name)
        missing = [j for j in self.joint_names if j not in values]
        if missing:
            raise SRDFError(f"{self.srdf.path.name}: configuration {name!r} gives no value for chain joint "
                            f"{missing[0]!r}")
        return np.array([values[j] for j in self.joint_names])

    def _below_base(self, full: pin.Model, chain: list[int], base: str) -> list[int]:
        """The chain's joints between frame ``base`` and the tool; the base must lie on the root → tool path."""
        base_id = _frame_id(full, base, self.name)
        above = [j for j in full.supports[full.frames[base_id].parentJoint] if j != 0]
        if any(j not in chain for j in above):
            raise ChainError(f"{self.name}: base frame {base!r} is not on the path from the root to the tool "
                             f"{self.tool!r} (a base must be an ancestor of the tool)")
        return [j for j in chain if j not in above]

    def _reroot(self, base: str) -> None:
        """Express the reduced model in the ``base`` frame: every placement on the universe is premultiplied by
        baseMworld (the joints above the base are locked, so the base is fixed in the world)."""
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        bMw = self._bMw = data.oMf[_frame_id(self.model, base, self.name)].inverse()
        for jid in range(1, self.model.njoints):
            if self.model.parents[jid] == 0:
                self.model.jointPlacements[jid] = bMw * self.model.jointPlacements[jid]
        for fid in range(self.model.nframes):
            frame = self.model.frames[fid]
            if frame.parentJoint == 0:
                frame.placement = bMw * frame.placement
                self.model.frames[fid] = frame
        self.data = self.model.createData()

    @staticmethod
    def _locked_values(full: pin.Model, chain: list[int], user: dict[str, float]) -> dict[str, float]:
        names = [full.names[j] for j in range(1, full.njoints)]
        for jname in user:
            if jname not in names:
                raise JointNotFoundError(jname, names)
        locked = {}
        for jid in range(1, full.njoints):
            jname = full.names[jid]
            if jname in user:
                locked[jname] = _locked_value(full, jid, user[jname])
            elif jid not in chain:
                iq = full.idx_qs[jid]
                lo, hi = full.lowerPositionLimit[iq], full.upperPositionLimit[iq]
                locked[jname] = float(np.clip(0.0, lo, hi)) if full.joints[jid].nq == 1 else 0.0
        return locked

    def _joint_table(self) -> list[Joint]:
        m = self.model
        axes = _local_axes(m)
        table = []
        for jid in range(1, m.njoints):
            jm = m.joints[jid]
            if jm.nq == 0:  # a mimic joint: its leader's coordinate moves it
                continue
            kind = _kind(jm)
            iq, iv = jm.idx_q, jm.idx_v
            if kind == "continuous":
                lo, hi = -np.pi, np.pi
            else:
                lo, hi = float(m.lowerPositionLimit[iq]), float(m.upperPositionLimit[iq])
                lo, hi = _narrowed(m.names[jid], lo, hi, self.mimics.values())
            ax, ay, az = (float(a) for a in axes[jid - 1])
            table.append(Joint(m.names[jid], kind or "revolute", lo, hi, iq, iv, (ax, ay, az)))
        return table

    # -- coordinates ---------------------------------------------------------------------------
    def joint_index(self, name: str) -> int:
        """Position of joint ``name`` in kinelab's q (raises JointNotFoundError with the valid names)."""
        if name not in self.joint_names:
            raise JointNotFoundError(name, self.joint_names)
        return self.joint_names.index(name)

    def check_q(self, q: ArrayLike, *, limits: bool = False, what: str = "q") -> np.ndarray:
        """``q`` as a float array of length n, refusing wrong shapes, NaN/inf and (if asked) limits."""
        try:
            raw = q if type(q) is np.ndarray else np.asarray(q)
            if raw.dtype.kind not in "fiu":  # complex, bool, text and objects are not joint values
                raise TypeError
            arr = raw if raw.dtype == np.float64 else raw.astype(float)
        except (TypeError, ValueError):
            raise ConfigurationError(f"{what} must be {self.n} numbers (real), got {q!r}") from None
        if arr.shape == (self.n,) and not limits and math.isfinite(sum(arr.tolist())):  # NaN, ±inf poison it
            return arr
        if arr.shape != (self.n,):
            raise ConfigurationError(
                f"{what} must have {self.n} numbers ({', '.join(self.joint_names)}) for {self.name}, "
                f"got shape {arr.shape}"
            )
        bad = ~np.isfinite(arr)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ConfigurationError(f"{what}[{i}] ({self.joint_names[i]}) is {arr[i]}: values must be finite")
        if limits:
            outside = (arr < self._lower_check - LIMIT_SLACK) | (arr > self._upper_check + LIMIT_SLACK)
            if outside.any():
                i = int(np.flatnonzero(outside)[0])
                j = self.joints[i]
                raise JointLimitError(j.name, arr[i], j.lower, j.upper, j.unit)
        return arr

    def within_limits(self, q: ArrayLike, slack: float = LIMIT_SLACK) -> bool:
        """True when every bounded joint lies within its limits (plus ``slack``); continuous joints have none."""
        if slack == LIMIT_SLACK:
            values = (q if type(q) is np.ndarray else np.asarray(q, dtype=float)).tolist()
            return len(values) == self.n and all(map(operator.le, self._lower_list, values)) and \
                all(map(operator.le, values, self._upper_list))
        arr = np.asarray(q, dtype=float)
        return bool((arr >= self._lower_check - slack).all() and (arr <= self._upper_check + slack).all())

    def outside_limits(self, q: ArrayLike) -> list[str]:
        """One line per joint of ``q`` outside its limits (beyond LIMIT_SLACK), naming the joint, the value and the
        limits; empty when q is within them (continuous joints have none)."""
        values = np.asarray(q, dtype=float)
        lower, upper = self.check_bounds
        return [f"{j.name} = {v:g} {j.unit} is outside its limits [{j.lower:.4g}, {j.upper:.4g}] {j.unit}"
                for j, v, lo, hi in zip(self.joints, values.tolist(), lower, upper, strict=True) if not lo <= v <= hi]

    def within_limits_batch(self, Q: np.ndarray) -> np.ndarray:
        """:meth:`within_limits` per row of a (B, n) array (default slack): a (B,) bool array."""
        Q = np.asarray(Q, dtype=float)
        lower, upper = self.check_bounds
        inside: np.ndarray = (lower <= Q) & (upper >= Q)
        return np.asarray(inside.all(axis=1))

    def to_pin_q(self, q: ArrayLike) -> np.ndarray:
        """One number per joint → Pinocchio's q (continuous joints become cos, sin); a new array."""
        pin_q = self._pin_q(q)
        return pin_q.copy() if pin_q is q else pin_q

    def _pin_q(self, q: ArrayLike) -> np.ndarray:
        """Pinocchio's q for reading only: q itself when the two orders coincide (no copy)."""
        arr = self.check_q(q)
        if self._identity_q:
            return arr
        out = np.empty(self.nq)
        out[self._scalar_idx] = arr[self._scalar_pos]
        angles = arr[self._cont_pos]
        out[self._cont_idx] = np.cos(angles)
        out[self._cont_idx + 1] = np.sin(angles)
        return out

    def from_pin_q(self, q_pin: ArrayLike) -> np.ndarray:
        """Pinocchio's q → one number per joint (continuous joints as atan2(sin, cos) in (−π, π])."""
        q_pin = np.asarray(q_pin, dtype=float)
        if q_pin.shape != (self.nq,):
            raise ConfigurationError(f"Pinocchio q must have nq = {self.nq} entries, got shape {q_pin.shape}")
        out = np.empty(self.n)
        out[self._scalar_pos] = q_pin[self._scalar_idx]
        out[self._cont_pos] = np.arctan2(q_pin[self._cont_idx + 1], q_pin[self._cont_idx])
        return out

    def wrap_continuous(self, q: ArrayLike) -> np.ndarray:
        """q with continuous joints wrapped into (−π, π] (the same pose)."""
        q = np.array(q, dtype=float)
        if self._cont_pos.size:
            q[self._cont_pos] = wrap_to_pi(q[self._cont_pos])
        return q

    def neutral(self) -> np.ndarray:
        """Zero for every joint, moved into its limits where zero is outside them."""
        return np.clip(np.zeros(self.n), self.lower, self.upper)

    def display_q(self) -> np.ndarray:
        """A pose to show the robot in when none is given [rad, m]: the registered display pose, else the
        best-conditioned of 64 seeded configurations in the middle half of each joint's range (largest
        σ_min/σ_max of the tool Jacobian, linear rows divided by the characteristic length). All-zero poses
        are often singular (a stretched arm), which makes a poor first picture."""
        if self.display_pose is not None:
            return np.array(self.display_pose, dtype=float)
        return np.array(self.derived("display_q", _best_conditioned), dtype=float)

    def random_q(self, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """A configuration drawn uniformly within the limits (continuous joints on [−π, π]; a revolute joint
        whose limits lie beyond ±SAMPLE_TURNS turns, such as a rotor declared with ±1e16 rad, on ±SAMPLE_TURNS
        turns: every pose it can take, at angles where rounding does not swamp a step)."""
        rng = np.random.default_rng(rng)
        return rng.uniform(*self._sample_bounds)

    def random_qs(self, count: int, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """``count`` configurations (rows) drawn as :meth:`random_q` draws one."""
        rng = np.random.default_rng(rng)
        return rng.uniform(*self._sample_bounds, size=(count, self.n))

    @functools.cached_property
    def _sample_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        revolute = np.array([k != "prismatic" for k in self.joint_kinds])
        span = SAMPLE_TURNS * 2 * np.pi
        return (np.where(revolute, np.maximum(self.lower, -span), self.lower),
                np.where(revolute, np.minimum(self.upper, span), self.upper))

    # -- kinematics ----------------------------------------------------------------------------
    def _forward(self, q: ArrayLike) -> None:
        pin.forwardKinematics(self.model, self.data, self._pin_q(q))
        pin.updateFramePlacements(self.model, self.data)

    def fk(self, q: ArrayLike) -> pin.SE3:
        """oMtool: pose of the tool frame in the base frame at ``q`` (m, rad)."""
        self._forward(q)
        return pin.SE3(self.data.oMf[self.tool_frame_id])

    def fk_batch(self, Q: np.ndarray) -> np.ndarray:
        """oMtool for every row of Q (B × n, rad or m): a (B, 4, 4) stack of homogeneous matrices (Pinocchio FK).

        Raises:
            ConfigurationError: Q not (B, n) finite numbers (the first bad row named).
        """
        Q = self.check_qs(Q)
        out = np.empty((Q.shape[0], 4, 4))
        model, data, fid = self.model, self.data, self.tool_frame_id
        for b in range(Q.shape[0]):
            pin.forwardKinematics(model, data, self._pin_q(Q[b]))
            out[b] = pin.updateFramePlacement(model, data, fid).homogeneous
        return out

    def jacobian_batch(self, Q: np.ndarray, frame: str = "local") -> np.ndarray:
        """The 6 × n tool Jacobian for every row of Q: (B, 6, n), rows [v; ω].

        Args:
            Q: (B, n) configurations [rad or m].
            frame: "local" (tool frame), "world" (base frame, v at the base origin) or
                "local_world_aligned" (base axes at the tool origin).

        Raises:
            ConfigurationError: Q not (B, n) finite numbers; OptionError: an unknown frame.
        """
        frames = {"local": pin.LOCAL, "world": pin.WORLD, "local_world_aligned": pin.LOCAL_WORLD_ALIGNED}
        if frame not in frames:
            raise OptionError("frame", frame, f"one of {sorted(frames)}")
        Q = self.check_qs(Q)
        return np.stack([self._jacobian(q, frames[frame]) for q in Q]) if Q.shape[0] else np.empty((0, 6, self.n))

    def check_qs(self, Q: np.ndarray, what: str = "Q") -> np.ndarray:
        """Q as a (B, n) float array of finite numbers, refusing other shapes and naming the first bad row."""
        arr = np.asarray(Q) if not isinstance(Q, np.ndarray) else Q
        if arr.dtype.kind not in "fiu" or arr.ndim != 2 or arr.shape[1] != self.n:
            raise ConfigurationError(f"{what} must be a (B, {self.n}) array of numbers for {self.name}, "
                                     f"got {getattr(arr, 'shape', '?')} of {arr.dtype}")
        arr = np.asarray(arr, dtype=float)
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            b = int(np.flatnonzero(bad)[0])
            self.check_q(arr[b], what=f"{what}[{b}]")
        return arr

    def tool_error(self, q: ArrayLike, oMtarget: pin.SE3) -> tuple[float, float]:
        """(position error [m], rotation angle error [rad]) of the tool at q against oMtarget (Pinocchio FK)."""
        return pose_error(oMtarget, self.tool_pose_of_float_q(self.check_q(q)))

    def tool_pose_of_float_q(self, q: np.ndarray) -> pin.SE3:
        """oMtool (Pinocchio FK) for a q known to be n finite floats (a solver's answer): no check repeated."""
        pin.forwardKinematics(self.model, self.data, q if self._identity_q else self._pin_q(q))
        return pin.updateFramePlacement(self.model, self.data, self.tool_frame_id)

    def frame_placement(self, q: ArrayLike, frame: str) -> pin.SE3:
        """oMframe: pose of any frame of the reduced model in the base frame."""
        fid = _frame_id(self.model, frame, self.name)
        self._forward(q)
        return pin.SE3(self.data.oMf[fid])

    def joint_placements(self, q: ArrayLike) -> dict[str, pin.SE3]:
        """oMjoint for every chain joint: the joint frame (after its motion) in the base frame."""
        self._forward(q)
        return {j.name: pin.SE3(self.data.oMi[self.model.getJointId(j.name)]) for j in self.joints}

    def _jacobian(self, q: ArrayLike, frame: pin.ReferenceFrame) -> np.ndarray:
        q_pin = self.to_pin_q(q)
        J = pin.computeFrameJacobian(self.model, self.data, q_pin, self.tool_frame_id, frame)
        return np.array(J).reshape(6, self.nv)  # a 1-DoF chain comes back as a flat 6-vector

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
        dq = np.asarray(dq, dtype=float)
        return self.from_pin_q(pin.integrate(self.model, self.to_pin_q(q), dq))

    def difference(self, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
        """q1 ⊖ q0 through ``pin.difference``: the n velocities that take q0 to q1 in 1 s."""
        return np.asarray(pin.difference(self.model, self.to_pin_q(q0), self.to_pin_q(q1)), dtype=float)

    def visual_model(self, package_dirs: list[str] | None = None) -> pin.GeometryModel:
        """Visual geometry matched to ``self.model`` (locked joints folded in), meshes resolved.

        ``package://`` URIs resolve under ``package_dirs`` (default: those given to :func:`load`, then
        ``ROS_PACKAGE_PATH``'s, then example-robot-data's); visuals whose mesh cannot be found are left out
        with a warning.
        """
        if is_mjcf(self.urdf_path):
            geom = pin.buildGeomFromMJCF(self._full, str(self.urdf_path), pin.GeometryType.VISUAL)
        else:
            geom = build_visual_model(self._full, self.urdf_path, package_dirs or self.package_dirs)
        if self._lock_ids:
            _, geom = pin.buildReducedModel(self._full, geom, self._lock_ids, self._q_ref)
        if self._bMw is not None:  # re-rooted at the base frame, as the model was
            for gid in range(geom.ngeoms):
                obj = geom.geometryObjects[gid]
                if obj.parentJoint == 0:
                    obj.placement = self._bMw * obj.placement
                    geom.geometryObjects[gid] = obj
        return geom

    @property
    def frame_names(self) -> list[str]:
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
        return f"Robot({self.name!r}, n={self.n}, tool={self.tool!r}, urdf={str(self.urdf_path)!r})"


_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def _best_conditioned(robot: Robot) -> np.ndarray:
    rng = np.random.default_rng(0)
    lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    mid, half = (lo + hi) / 2, np.minimum((hi - lo) / 4, np.pi / 2)
    length = robot.characteristic_length()
    best, best_ratio = robot.neutral(), -1.0
    for _ in range(64):
        q = mid + rng.uniform(-1.0, 1.0, robot.n) * half
        J = robot.jacobian_local_world_aligned(q)
        J[:3] /= length
        s = np.linalg.svd(J, compute_uv=False)
        ratio = s[min(robot.n, 6) - 1] / s[0] if s[0] > 0 else 0.0
        if ratio > best_ratio:
            best, best_ratio = q, ratio
    return best


def _local_axes(model: pin.Model) -> list[np.ndarray]:
    """Unit axis of every 1-DoF joint in its own frame, from the joint models themselves (no Data: a
    Pinocchio Data holds nv³-sized tensors, so building one per joint made a load cubic in size)."""
    axes = []
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        if joint.nq == 0:  # a mimic joint has no axis of its own in kinelab's q
            axes.append(np.zeros(3))
            continue
        axis = getattr(joint.extract(), "axis", None)
        if axis is None:  # an aligned joint: JointModelRX, PY, RUBZ, ...
            axis = _AXES[joint.shortname()[-1]]
        axes.append(np.asarray(axis, dtype=float))
    return axes


def load(name_or_path: str | Path, tool: str | None = None, locked: dict[str, float] | None = None,
         base: str | None = None, package_dirs: list[str] | None = None, srdf: str | Path | None = None,
         group: str | None = None, xacro_args: dict[str, str] | None = None, *,
         trust_xacro: bool = False) -> Robot:
    """Load a registered robot (``kinelab.robots()``) or a URDF file as a :class:`Robot`.

    Args:
        name_or_path: a registered name such as ``"era"`` or ``"panda"``, a path to a URDF, xacro or MJCF
            file, or ``"rd:NAME"``: a description of robot_descriptions (the extra
            ``kinelab[descriptions]``), read from its cache (:mod:`~kinelab.robot.descriptions`).
        tool: the tool frame; default: the registered tool, else a frame named ``tool``, else the
            single leaf link (an error lists the leaves when there are several).
        locked: joints to hold fixed, name → value (rad or m): chain joints, or joints off the chain (held
            at zero, clipped into their limits, when not named).
        base: the frame the chain starts from (default: the URDF root); it must lie on the root → tool
            path. Joints above it are locked, and every pose (FK, targets) is expressed in this frame.
        package_dirs: directories where ``package://NAME/...`` mesh URIs resolve (as ``DIR/NAME/...``, or
            DIR itself when it is the package NAME), before ``ROS_PACKAGE_PATH``'s and example-robot-data's.
            Kinematics never read meshes; the viewer does.
        srdf: an SRDF file: its named configurations (:meth:`Robot.named_q`), its groups, and the values at
            which joints off the chain are held (the first configuration naming a joint; ``locked`` wins).
        group: an SRDF group whose chain (base → tip), end effector or last joint gives base and tool.
        xacro_args: arguments of a ``.xacro`` source (name → value), expanded with xacrodoc (the extra
            ``kinelab[xacro]``); MJCF sources (root ``<mujoco>``) are read by Pinocchio's MJCF parser.
        trust_xacro: let a ``.xacro`` source run what xacro runs (``$(eval ...)``, ``$(env ...)``,
            ``load_yaml``); without it those are refused with their line (:mod:`~kinelab.robot.xacro`).

    Raises:
        RobotNotFoundError, DescriptionError, URDFError, SRDFError, ChainError, FrameNotFoundError: named.
        JointNotFoundError: a locked joint that does not exist (the valid names listed).
    """
    if str(name_or_path).startswith(descriptions.PREFIX):
        found = descriptions.resolve(str(name_or_path))
        return Robot(found.path, tool=tool, locked=locked, name=found.name, base=base,
                     package_dirs=[*(package_dirs or []), *found.package_dirs], srdf=srdf, group=group)
    path, entry = catalog.resolve(name_or_path)
    if entry is not None and not group:
        tool, base = tool or entry.tool, base or entry.base
        if entry.group and not (tool or base):
            group = entry.group
        srdf = srdf or catalog.srdf_path(entry)
    robot = Robot(path, tool=tool, locked=locked, name=entry.name if entry else None, base=base,
                  package_dirs=package_dirs, srdf=srdf, group=group, xacro_args=xacro_args, trust_xacro=trust_xacro)
    if entry is not None and entry.display is not None and robot.n == len(entry.display):
        robot.display_pose = np.array(entry.display)
    return robot
