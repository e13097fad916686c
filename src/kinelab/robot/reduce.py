"""A robot file or model reduced to one base → tool chain: the joints between them kept (a mimic joint folded
into its leader), every other joint locked at its value, the model re-rooted at the base frame, each joint's
limits, kind and place in Pinocchio's q read once (:class:`~kinelab.robot.build.Built`)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinelab.errors import (
    ChainError,
    ConfigurationError,
    JointLimitError,
    JointNotFoundError,
    OptionError,
    SRDFError,
    URDFError,
)
from kinelab.files import checked_file
from kinelab.robot import xacro
from kinelab.robot.build import (
    Built,
    build_full_model,
    check_data_size,
    check_names,
    frame_id,
    joint_kind,
    local_axes,
    one_to_pin,
    srdf_of,
)
from kinelab.robot.folding import reduced
from kinelab.robot.joints import Joint, Mimic
from kinelab.robot.meshes import mesh_package_dirs
from kinelab.robot.mjcf import body_tree, is_mjcf, read_mjcf
from kinelab.robot.space import LIMIT_SLACK
from kinelab.robot.srdf import Srdf
from kinelab.robot.urdf import UrdfTree, read_tree


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


def _leaf_tool(full: pin.Model, leaf: str) -> str:
    """The one site (operational frame) on the leaf body where it has exactly one (an MJCF tip site), else the
    leaf."""
    ids = [i for i, f in enumerate(full.frames) if f.name == leaf and f.type == pin.FrameType.BODY]
    if not ids:
        return leaf
    sites = [f.name for f in full.frames if f.type == pin.FrameType.OP_FRAME and f.parentFrame == ids[0]]
    return sites[0] if len(sites) == 1 else leaf


def _has_free_mimic(full: pin.Model, chain: list[int], tree: UrdfTree, locked: dict[str, float]) -> bool:
    """True when a joint of the chain mimics another and is not locked (the model is then built with mimics)."""
    return any(full.names[j] in tree.mimic and full.names[j] not in locked for j in chain)


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
            full = build_full_model(urdf_path)
        check_names(full, urdf_path)
        b = cls(name or full.name or urdf_path.stem, source, urdf_path, full, tree, mesh_package_dirs(package_dirs),
                dict(xacro_args or {}), bool(trust_xacro))
        b.srdf = srdf_of(srdf, tree)
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
        full, tree, locked = self._start, self.tree, locked or {}
        self.base = base or tree.root
        self.tool = tool or self._default_tool(tree, full)
        chain = self._chain(full, base)
        if _has_free_mimic(full, chain, tree, locked):
            full, chain = self._with_mimics(full, chain, tree, base)
        self._check_chain(full, chain, tree)
        if self.urdf_path is not None:
            tree.check_mimics(self.urdf_path, [full.names[j] for j in chain], locked)
        self.locked = self._locked_values(full, chain, {**self._held_by_srdf(full, chain), **locked})
        self._reduce(full)
        if base is not None and base != tree.root:
            self._reroot(base)

    def _held_by_srdf(self, full: pin.Model, chain: list[int]) -> dict[str, float]:
        """The SRDF's reference values [rad or m] of the model's joints off the chain (none without an SRDF)."""
        reference = self.srdf.reference() if self.srdf else {}
        return {j: v for j, v in reference.items() if full.existJointName(j) and full.getJointId(j) not in chain}

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
            kind = joint_kind(full.joints[jid])
            if kind is None:  # a free or spherical joint above the chain: held at its neutral pose
                continue
            nq = full.joints[jid].nq
            q_ref[full.idx_qs[jid] : full.idx_qs[jid] + nq] = one_to_pin(kind, value)[:nq]
        lock_ids = [full.getJointId(j) for j in self.locked]
        self._full, self._lock_ids, self._q_ref = full, lock_ids, q_ref
        try:
            self.model = reduced(full, lock_ids, q_ref) if lock_ids else full
        except ValueError as exc:  # what Pinocchio still cannot fold, said
            raise ChainError(f"{self.name}: Pinocchio cannot lock the joints off the chain ({exc}); give "
                             "another tool= or base=") from None
        check_data_size(self.model, self.name)
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
            return _leaf_tool(full, tree.leaves[0])
        raise ChainError(
            f"the tool frame is ambiguous: {tree.root!r} branches into {len(tree.leaves)} leaf links "
            f"({', '.join(tree.leaves[:12])}{', ...' if len(tree.leaves) > 12 else ''}); name one (--tool on the "
            f"command line, tool= in Python), likely {', '.join(likely_tools(tree))}; or take the whole robot "
            "(--whole, whole=True)"
        )

    @staticmethod
    def _check_chain(full: pin.Model, chain: list[int], tree: UrdfTree) -> None:
        for jid in chain:
            jname = full.names[jid]
            if full.joints[jid].shortname() == "JointModelMimic":
                continue  # follows its leader (Chain._with_mimics checked it is on the chain)
            if joint_kind(full.joints[jid]) is None:
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
        full = build_full_model(self.urdf_path, mimic=True)
        for jid in range(1, full.njoints):
            follower = full.joints[jid].extract()
            if full.joints[jid].shortname() == "JointModelMimic" and jid in self._chain(full, base):
                name, leader = full.names[jid], tree.mimic[full.names[jid]]
                iq = plain.idx_qs[plain.getJointId(name)]
                self.mimics[name] = Mimic(name, leader, float(follower.scaling), float(follower.offset),
                                          float(plain.lowerPositionLimit[iq]), float(plain.upperPositionLimit[iq]))
        return full, self._chain(full, base)

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
        axes = local_axes(m)
        table = []
        for jid in range(1, m.njoints):
            jm = m.joints[jid]
            if jm.nq == 0:  # a mimic joint: its leader's coordinate moves it
                continue
            kind = joint_kind(jm)
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


TOOL_WORDS = ("gripper", "hand", "tool", "tcp", "ee", "flange", "wrist", "finger", "foot", "sole")


def likely_tools(tree: UrdfTree, count: int = 3) -> list[str]:
    """The leaves most likely meant as a tool: those named like one (gripper, hand, tool, ...) first, the deepest
    (most links from the root) first among equals."""
    def depth(link: str) -> int:
        n = 0
        while link in tree.parent_of:
            link, n = tree.parent_of[link], n + 1
        return n

    def named(link: str) -> int:
        return next((k for k, word in enumerate(TOOL_WORDS) if word in link.lower()), len(TOOL_WORDS))

    return sorted(tree.leaves, key=lambda link: (named(link), -depth(link), link))[:count]

