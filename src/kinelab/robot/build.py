"""Building a Chain: a model file (URDF, xacro, MJCF) or an in-memory ``pin.Model`` → the chain's reduced model.

Everything a load decides happens here, once: reading the file (and expanding xacro), the SRDF and its group,
the base → tool chain, mimic joints, the joints held fixed (off the chain, or named in ``locked``), the
reduced model and its re-rooting at the base frame. The result is a frozen :class:`Built`;
:class:`~kinelab.robot.chain.Chain` uses it and decides nothing.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

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
from kinelab.files import checked_file
from kinelab.robot import xacro
from kinelab.robot.joints import Joint, Mimic
from kinelab.robot.meshes import c_stderr_captured, mesh_package_dirs
from kinelab.robot.mjcf import body_tree, is_mjcf, read_mjcf
from kinelab.robot.space import LIMIT_SLACK
from kinelab.robot.srdf import Srdf, read_srdf
from kinelab.robot.urdf import UrdfTree, read_tree

_REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
_PRISMATIC = {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}
_CONTINUOUS = {"JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"}
MAX_DATA_BYTES = 2**31  # 2 GiB for one Pinocchio Data (see data_bytes)


@dataclass(frozen=True)
class Built:
    """Everything a :class:`~kinelab.robot.chain.Chain` is made of, decided once.

    Attributes:
        name: the robot's name.
        source: the file the user named (None for an in-memory model); urdf_path: the file Pinocchio read (the
            xacro expansion, or ``source``).
        model: the chain's model: every joint off the chain (and every locked one) folded in, in the base frame.
        tool, base: the chain's end frames; joints: the chain's joints in q order; mimics: followers on it.
        locked: the joints held fixed and their values [rad or m].
        srdf: the SRDF read, or None; package_dirs: where ``package://`` meshes resolve.
        xacro_args, trust_xacro: how a xacro source was expanded.
        full, lock_ids, q_ref, bMw: the unreduced model, the joints folded and their values, and baseMworld
            when re-rooted (the viewer rebuilds the visual geometry the same way).
    """

    name: str
    source: Path | None
    urdf_path: Path | None
    model: pin.Model
    tool: str
    base: str
    joints: tuple[Joint, ...]
    mimics: dict[str, Mimic]
    locked: dict[str, float]
    srdf: Srdf | None = None
    package_dirs: list[str] = field(default_factory=list)
    xacro_args: dict[str, str] = field(default_factory=dict)
    trust_xacro: bool = False
    full: pin.Model | None = None
    lock_ids: tuple[int, ...] = ()
    q_ref: np.ndarray | None = None
    bMw: pin.SE3 | None = None


def build_file(path: str | Path, tool: str | None = None, locked: dict[str, float] | None = None,
               name: str | None = None, base: str | None = None, package_dirs: list[str] | None = None,
               srdf: str | Path | None = None, group: str | None = None, xacro_args: dict[str, str] | None = None,
               trust_xacro: bool = False) -> Built:
    """The chain of a model file (see :func:`kinelab.load` for the arguments).

    Raises:
        URDFError, SRDFError, ChainError, FrameNotFoundError, JointNotFoundError, ConfigurationError,
        JointLimitError: named.
    """
    return _Builder.from_file(Path(path), tool, locked, name, base, package_dirs, srdf, group, xacro_args,
                              trust_xacro).built()


@dataclass(frozen=True)
class Whole:
    """A whole robot's model read from a file (:func:`whole_model`).

    Attributes:
        model: the whole Pinocchio model (a free-flyer at its root when asked for; mimic joints as Pinocchio's).
        name: the robot's name; source: the file the user named; urdf_path: the file Pinocchio read.
        srdf: the SRDF read, or None.
    """

    model: pin.Model
    name: str
    source: Path
    urdf_path: Path
    srdf: Srdf | None


def whole_model(path: str | Path, *, floating: bool = False, name: str | None = None,
                package_dirs: list[str] | None = None, srdf: str | Path | None = None,
                xacro_args: dict[str, str] | None = None, trust_xacro: bool = False) -> Whole:
    """The whole model of a file (URDF, xacro or MJCF): every joint, none locked.

    Args:
        path: the file.
        floating: a free-flyer between the world and the file's root link.
        name: the robot's name (default: the file's).
        package_dirs: where a xacro's includes may be read from.
        srdf: an SRDF file (checked against the file's joints and links).
        xacro_args: a xacro source's arguments.
        trust_xacro: let a xacro source run what xacro runs.

    Raises:
        URDFError, SRDFError, ChainError: the file, the SRDF or the model refused, named.
    """
    source = Path(path)
    checked_file(source, "robot file", URDFError)
    urdf_path = xacro.expand(source, xacro_args, trusted=trust_xacro, package_dirs=package_dirs) \
        if xacro.is_xacro(source) else source
    root = pin.JointModelFreeFlyer() if floating else None
    if is_mjcf(urdf_path):
        model, tree = read_mjcf(urdf_path, root)
    else:
        tree = read_tree(urdf_path)
        model = _whole_urdf(urdf_path, bool(tree.mimic), root)
    _check_names(model, urdf_path)
    _check_data_size(model, name or model.name or urdf_path.stem)
    found = _Builder._read_srdf(srdf, tree)
    return Whole(model, name or model.name or urdf_path.stem, source, urdf_path, found)


def _whole_urdf(path: Path, mimic: bool, root: pin.JointModel | None) -> pin.Model:
    """The URDF's whole model, its mimic joints Pinocchio's own where it can build them, else plain joints (said)."""
    if mimic:
        try:
            return _build_full_model(path, mimic=True, root=root)
        except URDFError as refused:
            warnings.warn(f"{path.name}: Pinocchio cannot build its mimic joints ({refused}); they are plain joints "
                          "(hold them with a CouplingTask)", stacklevel=3)
    return _build_full_model(path, root=root)


def build_model(model: pin.Model, tool: str | None = None, locked: dict[str, float] | None = None,
                name: str | None = None, base: str | None = None) -> Built:
    """The chain of an in-memory Pinocchio model (a copy: the caller's model is left as it is).

    Args:
        model: the whole robot's model (revolute, continuous and prismatic joints on the chain).
        tool: the tool frame; default a frame named ``tool``, else the single leaf body.
        locked: joints held fixed, name → value (rad or m); joints off the chain are held at zero (clipped).
        name: the robot's name (default: the model's).
        base: the frame the chain starts from (default: the model's root).

    Raises:
        ChainError, FrameNotFoundError, JointNotFoundError, ConfigurationError, JointLimitError: named.
    """
    if not isinstance(model, pin.Model):
        raise ChainError(f"from_model takes a pinocchio.Model, got {type(model).__name__}")
    return _Builder.from_model(pin.Model(model), tool, locked, name, base).built()


class _Builder:
    """The steps of one build; its attributes are the decisions made so far."""

    def __init__(self, name: str, source: Path | None, urdf_path: Path | None, full: pin.Model, tree: UrdfTree,
                 package_dirs: list[str], xacro_args: dict[str, str], trust_xacro: bool):
        self.name, self.source, self.urdf_path, self.tree = name, source, urdf_path, tree
        self.package_dirs, self.xacro_args, self.trust_xacro = package_dirs, xacro_args, trust_xacro
        self._start = full
        self.srdf: Srdf | None = None
        self.mimics: dict[str, Mimic] = {}
        self._bMw: pin.SE3 | None = None

    @classmethod
    def from_file(cls, source: Path, tool: str | None, locked: dict[str, float] | None, name: str | None,
                  base: str | None, package_dirs: list[str] | None, srdf: str | Path | None, group: str | None,
                  xacro_args: dict[str, str] | None, trust_xacro: bool) -> _Builder:
        checked_file(source, "robot file", URDFError)  # a device, a pipe or 10 GB: refused before any parser reads
        if xacro_args and not xacro.is_xacro(source):  # an argument that nothing reads is a mistake, said
            raise OptionError("xacro_args", xacro_args, f"arguments of a .xacro source; {source.name} is not one")
        urdf_path = source
        if xacro.is_xacro(source):
            urdf_path = xacro.expand(source, xacro_args, trusted=trust_xacro, package_dirs=package_dirs)
        if is_mjcf(urdf_path):
            full, tree = read_mjcf(urdf_path)
        else:
            tree = read_tree(urdf_path)
            full = _build_full_model(urdf_path)
        _check_names(full, urdf_path)
        b = cls(name or full.name or urdf_path.stem, source, urdf_path, full, tree, mesh_package_dirs(package_dirs),
                dict(xacro_args or {}), bool(trust_xacro))
        b.srdf = b._read_srdf(srdf, tree)
        if group is not None:
            tool, base = b._group_frames(group, tree, tool, base)
        b.reduce(tool, base, locked)
        return b

    @classmethod
    def from_model(cls, model: pin.Model, tool: str | None, locked: dict[str, float] | None, name: str | None,
                   base: str | None) -> _Builder:
        b = cls(name or model.name or "robot", None, None, model, body_tree(model), [], {}, False)
        b.reduce(tool, base, locked)
        return b

    def reduce(self, tool: str | None, base: str | None, locked: dict[str, float] | None) -> None:
        """The chain base → tool, its mimics and locked joints, the reduced and re-rooted model."""
        full, tree = self._start, self.tree
        self.base = base or tree.root
        self.tool = tool or self._default_tool(tree, full)
        chain = self._chain(full, base)
        if any(full.names[j] in tree.mimic and full.names[j] not in (locked or {}) for j in chain):
            full, chain = self._with_mimics(full, chain, tree, base)
        self._check_chain(full, chain, tree)
        if self.urdf_path is not None:
            tree.check_mimics(self.urdf_path, [full.names[j] for j in chain], (locked or {}))
        reference = self.srdf.reference() if self.srdf else {}
        held = {j: v for j, v in reference.items() if full.existJointName(j) and full.getJointId(j) not in chain}
        self.locked = self._locked_values(full, chain, {**held, **(locked or {})})
        self._reduce(full)
        if base is not None and base != tree.root:
            self._reroot(base)

    def built(self) -> Built:
        """The frozen result."""
        return Built(self.name, self.source, self.urdf_path, self.model, self.tool, self.base, tuple(self.joints),
                     self.mimics, self.locked, self.srdf, self.package_dirs, self.xacro_args, self.trust_xacro,
                     self._full, tuple(self._lock_ids), self._q_ref, self._bMw)

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
        frame_id(self.model, self.tool, self.name)
        self.joints = self._joint_table()
        if not self.joints:
            raise ChainError(f"{self.name}: no movable joint between the base and frame {self.tool!r}")


    @staticmethod
    def _default_tool(tree: UrdfTree, full: pin.Model) -> str:
        """A frame named "tool"; else the single leaf body, or the one site on it (an MJCF tip site)."""
        if any(f.name == "tool" for f in full.frames):
            return "tool"
        if len(tree.leaves) == 1:
            leaf = tree.leaves[0]
            ids = [i for i, f in enumerate(full.frames) if f.name == leaf and f.type == pin.FrameType.BODY]
            sites = [f.name for f in full.frames if f.type == pin.FrameType.OP_FRAME and ids
                     and f.parentFrame == ids[0]]
            return sites[0] if len(sites) == 1 else leaf
        raise ChainError(
            f"the tool frame is ambiguous: {tree.root!r} branches into {len(tree.leaves)} leaf links "
            f"({', '.join(tree.leaves[:12])}{', ...' if len(tree.leaves) > 12 else ''}); pass tool=NAME"
        )

    @staticmethod
    def _check_chain(full: pin.Model, chain: list[int], tree: UrdfTree) -> None:
        for jid in chain:
            jname = full.names[jid]
            if full.joints[jid].shortname() == "JointModelMimic":
                continue  # follows its leader (Chain._with_mimics checked it is on the chain)
            if _kind(full.joints[jid]) is None:
                raise ChainError(
                    f"joint {jname!r} is a {full.joints[jid].shortname()}: kinelab chains take revolute, "
                    "continuous and prismatic joints only"
                )

    def _chain(self, full: pin.Model, base: str | None) -> list[int]:
        """Joint ids from the base (or the root) to the tool frame."""
        tool_id = frame_id(full, self.tool, self.name)
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
        assert self.urdf_path is not None  # an in-memory model has no mimic table (body_tree)
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
        found.check_links(tree.links)
        return found

    def _group_frames(self, group: str, tree: UrdfTree, tool: str | None, base: str | None) -> tuple[str, str | None]:
        """(tool, base) for an SRDF group: those given win over the group's."""
        if self.srdf is None:
            raise SRDFError(f"group={group!r} needs srdf= (the file that defines the group)")
        g_tool, g_base = self.srdf.tool_and_base(group, {j: link for link, j in tree.joint_of.items()})
        return tool or g_tool, base or g_base

    def _below_base(self, full: pin.Model, chain: list[int], base: str) -> list[int]:
        """The chain's joints between frame ``base`` and the tool; the base must lie on the root → tool path."""
        base_id = frame_id(full, base, self.name)
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
        bMw = self._bMw = data.oMf[frame_id(self.model, base, self.name)].inverse()
        for jid in range(1, self.model.njoints):
            if self.model.parents[jid] == 0:
                self.model.jointPlacements[jid] = bMw * self.model.jointPlacements[jid]
        for fid in range(self.model.nframes):
            frame = self.model.frames[fid]
            if frame.parentJoint == 0:
                frame.placement = bMw * frame.placement
                self.model.frames[fid] = frame

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


def _check_names(model: pin.Model, path: Path) -> None:
    """Refuse a model whose names are not UTF-8: Pinocchio keeps a name's bytes as the file has them (a latin-1
    file naming its robot "é"), and Python cannot read them back.

    Raises:
        URDFError: naming the file and what to do.
    """
    try:
        [model.name, *model.names, *(f.name for f in model.frames)]
    except UnicodeDecodeError:
        raise URDFError(f"robot file {path}: a robot, joint or link name is not UTF-8 text (the file declares "
                        "another encoding); kinelab reads names as UTF-8: save the file as UTF-8") from None


def _build_full_model(path: Path, mimic: bool = False, root: pin.JointModel | None = None) -> pin.Model:
    said: list[str] = []
    try:
        with c_stderr_captured(said):  # urdfdom prints its complaints on the process's stderr
            model = pin.buildModelFromUrdf(str(path), mimic=mimic) if root is None else \
                pin.buildModelFromUrdf(str(path), root, mimic=mimic)
    except (RuntimeError, ValueError, UnicodeDecodeError) as exc:
        detail = " ".join([str(exc), *said]).strip()
        raise URDFError(f"Pinocchio cannot read {path}: {detail}") from None
    if said:
        warnings.warn(f"Pinocchio's URDF parser on {path.name}: {' '.join(said)}", stacklevel=3)
    return model


def frame_id(model: pin.Model, name: str, robot: str) -> int:
    """Id of frame ``name``, preferring the link (BODY) frame where a joint shares the name."""
    if not isinstance(name, str):
        raise FrameNotFoundError(repr(name), [f.name for f in model.frames], robot)
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


def _one_to_pin(kind: str, value: float) -> list[float]:
    return [np.cos(value), np.sin(value)] if kind == "continuous" else [value]




def _local_axes(model: pin.Model) -> list[np.ndarray]:
    """Unit axis of every 1-DoF joint in its own frame, from the joint models themselves (no Data: a
    Pinocchio Data holds nv³-sized tensors, so building one per joint made a load cubic in size)."""
    axes = []
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        if joint.nq == 0:  # a mimic joint has no axis of its own in kinelab's q
            axes.append(np.zeros(3))
            continue
        axes.append(_motion_axis(joint))
    return axes


def _motion_axis(joint: pin.JointModel) -> np.ndarray:
    """A 1-DoF joint's unit axis in its own frame, read off its motion subspace S = [linear; angular] (every
    joint kind has one; Pinocchio's Python API gives ``axis`` only to some, and none to an unbounded
    revolute joint on a tilted axis)."""
    data = joint.createData()
    joint.calc(data, np.array([1.0, 0.0]) if joint.nq == 2 else np.zeros(joint.nq))
    S = np.asarray(data.S, dtype=float).ravel()
    axis = S[3:] if np.linalg.norm(S[3:]) > 0.5 else S[:3]  # a revolute joint turns, a prismatic one slides
    return np.array(axis / np.linalg.norm(axis))


