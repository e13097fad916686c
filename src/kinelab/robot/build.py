"""Building a Chain: a model file (URDF, xacro, MJCF) or an in-memory ``pin.Model`` → the chain's reduced model.

Everything a load decides happens here, once: reading the file (and expanding xacro), the SRDF and its group,
the base → tool chain, mimic joints, the joints held fixed (off the chain, or named in ``locked``), the
reduced model and its re-rooting at the base frame. The result is a frozen :class:`Built`;
:class:`~kinelab.robot.chain.Chain` uses it and decides nothing.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinelab.errors import (
    ChainError,
    FrameNotFoundError,
    URDFError,
)
from kinelab.files import checked_file
from kinelab.robot import xacro
from kinelab.robot.closures import Closure
from kinelab.robot.joints import Joint, Mimic
from kinelab.robot.meshes import c_stderr_captured
from kinelab.robot.mjcf import equalities, floats, is_mjcf, joint_couplings, read_mjcf
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


@dataclass(frozen=True)
class Whole:
    """A whole robot's model read from a file (:func:`whole_model`).

    Attributes:
        model: the whole Pinocchio model (a free-flyer at its root when asked for; mimic joints as Pinocchio's).
        name: the robot's name; source: the file the user named; urdf_path: the file Pinocchio read.
        srdf: the SRDF read, or None.
        closures, actuated: an MJCF file's equality constraints as loops, and its actuators' joints.
        mimics: mimic joints Pinocchio could not build, folded: plain joints of the model that every whole-body
            step and solve holds at ``multiplier · leader + offset``.
    """

    model: pin.Model
    name: str
    source: Path
    urdf_path: Path
    srdf: Srdf | None
    mimics: tuple[Mimic, ...] = ()
    closures: tuple[Closure, ...] = ()  # an MJCF's <equality> connects and welds
    actuated: tuple[str, ...] = ()  # an MJCF's actuated joints


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
    loops: tuple[tuple[Closure, ...], tuple[str, ...]] = ((), ())
    if is_mjcf(urdf_path):
        root = None if floats(urdf_path) else root  # a file whose root body floats already: no second free-flyer
        model, tree = read_mjcf(urdf_path, root)
        loops = equalities(urdf_path, model, root)
    else:
        tree = read_tree(urdf_path)
        model = _whole_urdf(urdf_path, bool(tree.mimic), root)
    check_names(model, urdf_path)
    check_data_size(model, name or model.name or urdf_path.stem)
    found = srdf_of(srdf, tree)
    couplings = joint_couplings(urdf_path, model) if is_mjcf(urdf_path) else _folded(model, tree)
    return Whole(model, name or model.name or urdf_path.stem, source, urdf_path, found, couplings, *loops)


def _folded(model: pin.Model, tree: UrdfTree) -> tuple[Mimic, ...]:
    """The file's mimic joints that are plain joints of the model (Pinocchio could not build them), with one
    coordinate each and their factors read: held as couplings by the whole-body step."""
    folded = []
    for name, leader in tree.mimic.items():
        if name not in tree.mimic_factors or not (model.existJointName(name) and model.existJointName(leader)):
            continue
        joint, lead = model.joints[model.getJointId(name)], model.joints[model.getJointId(leader)]
        if joint.nq == joint.nv == lead.nq == lead.nv == 1:  # a plain joint of its own (not Pinocchio's mimic)
            multiplier, offset = tree.mimic_factors[name]
            folded.append(Mimic(name, leader, multiplier, offset, float(model.lowerPositionLimit[joint.idx_q]),
                                float(model.upperPositionLimit[joint.idx_q])))
    return tuple(folded)


def _whole_urdf(path: Path, mimic: bool, root: pin.JointModel | None) -> pin.Model:
    """The URDF's whole model, its mimic joints Pinocchio's own where it can build them, else plain joints (said)."""
    if mimic:
        try:
            return build_full_model(path, mimic=True, root=root)
        except URDFError as refused:
            warnings.warn(f"{path.name}: Pinocchio cannot build its mimic joints ({refused}); they are plain joints "
                          "of the model, held as couplings by every whole-body step and solve (robot.mimics)",
                          stacklevel=3)
    return build_full_model(path, root=root)


def check_names(model: pin.Model, path: Path) -> None:
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


def build_full_model(path: Path, mimic: bool = False, root: pin.JointModel | None = None) -> pin.Model:
    """The whole model of a URDF file as Pinocchio builds it (``mimic``: its mimic joints Pinocchio's own; ``root``:
    a free-flyer or other root joint), urdfdom's messages turned into a URDFError."""
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
    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    if not ids:
        raise FrameNotFoundError(name, [f.name for f in model.frames], robot)
    return next((i for i in ids if model.frames[i].type == pin.FrameType.BODY), ids[0])


def joint_kind(joint_model: pin.JointModel) -> str | None:
    """"revolute", "prismatic" or "continuous" for a 1-DoF joint model, None for any other."""
    short = joint_model.shortname()
    if short in _REVOLUTE:
        return "revolute"
    if short in _PRISMATIC:
        return "prismatic"
    if short in _CONTINUOUS:
        return "continuous"
    return None


def data_bytes(nv: int) -> int:
    """Bytes a Pinocchio Data takes for nv velocities: it allocates nv × nv × nv tensors (second-order
    derivatives) and a 6 × nv × nv one, whatever the algorithms used, so its size grows as nv³."""
    return 8 * (8 * nv**3 + 6 * nv**2 + 64 * nv)  # measured: 513 MB at nv = 200, 1.7 GB at nv = 300


def check_data_size(model: pin.Model, name: str) -> None:
    """Refuse a model whose Pinocchio Data would take more than MAX_DATA_BYTES (a ChainError naming the size)."""
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


def one_to_pin(kind: str, value: float) -> list[float]:
    """A joint value [rad or m] in Pinocchio's form: (cos, sin) for a continuous joint, else itself."""
    return [np.cos(value), np.sin(value)] if kind == "continuous" else [value]


def local_axes(model: pin.Model) -> list[np.ndarray]:
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


def srdf_of(srdf: str | Path | None, tree: UrdfTree) -> Srdf | None:
    """The SRDF file ``srdf`` read and checked against the robot's joints and links (None: no file).

    Raises:
        SRDFError: the file refused, or naming a joint or link the robot does not have.
    """
    if srdf is None:
        return None
    found = read_srdf(srdf)
    found.check_joints(list(tree.joint_of.values()))
    found.check_links(tree.links)
    return found
