"""MJCF (MuJoCo's XML): Pinocchio's model of the file, and the body tree kinelab needs from it.

Pinocchio reads the kinematics (``pin.buildModelFromMJCF``). Two things are added here. The body tree
(root, parents, the joint that moves each body, leaves) is taken from Pinocchio's frames, so that tool,
base and SRDF work as for a URDF. And slide (prismatic) joint ranges are restored from the file when its
angles are in degrees (MuJoCo's default): the parser converts every range to radians, metres included.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from kinelab.errors import URDFError
from kinelab.files import read_text
from kinelab.robot.closures import Closure
from kinelab.robot.joints import Mimic
from kinelab.robot.urdf import MAX_COMPONENT, MAX_OFFSET, UrdfTree, check_size

UNREAD = ("frame", "replicate", "attach")  # MuJoCo 3 elements Pinocchio's parser skips, with their bodies


def is_mjcf(path: Path) -> bool:
    """True when the file's root element is ``<mujoco>``."""
    try:
        for _, element in ET.iterparse(path, events=("start",)):
            return element.tag == "mujoco"
    except (OSError, ET.ParseError):
        return False
    return False


def read_mjcf(path: Path, root: pin.JointModel | None = None) -> tuple[pin.Model, UrdfTree]:
    """Pinocchio's model of an MJCF file (``root``: a joint between the world and its root body, a free-flyer
    say) and its body tree.

    Raises:
        URDFError: a file Pinocchio cannot read (the file and Pinocchio's reason named).
    """
    check_mjcf(path)
    try:
        model = pin.buildModelFromMJCF(str(path)) if root is None else \
            pin.buildModelAndConstraintsFromMJCF(str(path), root, "root_joint")[0]  # the unambiguous overload
    except Exception as exc:  # noqa: BLE001 - the parser raises RuntimeError, ValueError, IndexError, ...
        raise URDFError(f"Pinocchio cannot read the MJCF {path}: {type(exc).__name__}: {exc}") from None
    _restore_slide_ranges(model, ET.fromstring(read_text(path, "MJCF file", URDFError)))
    return model, body_tree(model)


def floats(path: Path) -> bool:
    """True when the file's root body carries its own free joint (``<freejoint>``, or a ``<joint type="free">``):
    the robot floats as written, and a free-flyer asked for on top of it is not added twice."""
    world = ET.fromstring(read_text(path, "MJCF file", URDFError)).find("worldbody")
    for body in [] if world is None else world.findall("body"):
        if body.find("freejoint") is not None or any(j.get("type") == "free" for j in body.findall("joint")):
            return True
    return False


def meshes_outside(path: Path) -> list[str]:
    """The mesh files an MJCF file names (``<mesh file=...>`` under its compiler's ``meshdir`` or ``assetdir``) that
    lie outside the file's own folder: kinelab hands no such path to a mesh loader (a robot file is data).

    Raises:
        URDFError: a file that cannot be read as XML (named).
    """
    try:
        root = ET.fromstring(read_text(path, "MJCF file", URDFError))
    except ET.ParseError as exc:
        raise URDFError(f"{path}: not well-formed XML ({exc})") from None
    compiler = root.find("compiler")
    folder = path.parent.resolve()
    meshdir = "" if compiler is None else compiler.get("meshdir", compiler.get("assetdir", ""))
    outside = []
    for mesh in root.iter("mesh"):
        name = mesh.get("file")
        if name and not (folder / meshdir / name).resolve().is_relative_to(folder):
            outside.append(name)
    return outside


def check_mjcf(path: Path) -> None:
    """The rules a URDF meets, for an MJCF file, before Pinocchio reads it: at most MAX_LINKS bodies, no
    ``<include>`` (not read: merge the file), finite positions within MAX_OFFSET, finite non-zero quaternions
    and axes, ranges with lower ≤ upper, unique body and joint names.

    Raises:
        URDFError: the file, the element and the rule named.
    """
    try:
        root = ET.fromstring(read_text(path, "MJCF file", URDFError))
    except ET.ParseError as exc:
        raise URDFError(f"malformed MJCF {path}: {exc}") from None
    bodies = list(root.iter("body"))
    check_size(path, len(bodies), "bodies")
    _check_unread(path, root)
    _check_classes(path, root)
    for kind, elements in (("body", bodies), ("joint", list(root.iter("joint")))):
        _check_unique(path, kind, [e.get("name", "") for e in elements if e.get("name")])
    for body in bodies:
        _check_body(path, body)
    for joint in root.iter("joint"):
        _check_joint(path, joint)


def _check_unread(path: Path, root: ET.Element) -> None:
    """Refuse what the parsers would skip without a word: an ``<include>`` (kinelab reads one file) and the UNREAD
    elements in the world body (Pinocchio's parser drops the bodies in them)."""
    if root.find(".//include") is not None:
        raise URDFError(f"{path}: <include> is not read by kinelab; merge the included file into {path.name}")
    for tag in UNREAD:
        if root.find(f".//worldbody//{tag}") is not None:
            raise URDFError(f"{path}: <{tag}> is not read by Pinocchio's MJCF parser (the bodies in it would be "
                            f"dropped without a word); write its bodies out of it, its placement composed into theirs")


def _check_unique(path: Path, kind: str, names: list[str]) -> None:
    """Refuse two elements of ``kind`` that share a name."""
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise URDFError(f"{path}: two {kind} elements are named {twice[0]!r}; names must be unique")


def _check_classes(path: Path, root: ET.Element) -> None:
    """Every ``class`` and ``childclass`` names a ``<default class=...>`` of the file (MuJoCo refuses the file
    otherwise; Pinocchio's parser fails on it with a raw error)."""
    defined = {str(d.get("class")) for d in root.iter("default") if d.get("class") is not None} | {"main"}
    for element in root.iter():
        for attribute in ("class", "childclass"):
            name = element.get(attribute)
            if name is not None and element.tag != "default" and name not in defined:
                raise URDFError(f"{path}: {element.tag} {element.get('name', '?')!r} has {attribute}={name!r}, which "
                                f"no <default class=...> defines; classes: {', '.join(sorted(defined))}")


def _numbers(path: Path, element: ET.Element, attribute: str, count: int) -> list[float] | None:
    text = element.get(attribute)
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise URDFError(f"{path}: {element.tag} {element.get('name', '?')!r} {attribute} must be {count} finite "
                        f"numbers, got {text!r}")
    return values


def _check_body(path: Path, body: ET.Element) -> None:
    name = body.get("name", "?")
    pos = _numbers(path, body, "pos", 3)
    if pos is not None and max(abs(v) for v in pos) > MAX_OFFSET:
        raise URDFError(f"{path}: body {name!r} pos {pos} is more than {MAX_OFFSET:g} m from its parent")
    _check_rotation(path, body, name)


def _check_rotation(path: Path, body: ET.Element, name: str) -> None:
    """A body's orientation, however given (quat, axisangle, euler, xyaxes, zaxis), finite and not degenerate."""
    for attribute, count, part in (("quat", 4, slice(0, 4)), ("axisangle", 4, slice(0, 3))):
        values = _numbers(path, body, attribute, count)
        if values is not None and math.hypot(*values[part]) < 1e-12:
            raise URDFError(f"{path}: body {name!r} {attribute} is zero; give a non-zero {attribute}")
    _numbers(path, body, "euler", 3)
    xyaxes, zaxis = _numbers(path, body, "xyaxes", 6), _numbers(path, body, "zaxis", 3)
    if xyaxes is not None and not _frame_axes(xyaxes[:3], xyaxes[3:]):
        raise URDFError(f"{path}: body {name!r} xyaxes {xyaxes} are not two independent directions (x zero, y zero "
                        "or y along x); give an x and a y axis")
    if zaxis is not None and not _direction(zaxis):
        raise URDFError(f"{path}: body {name!r} zaxis is zero or beyond ±{MAX_COMPONENT:g}; give a direction")


def _direction(v: list[float]) -> bool:
    """A non-zero direction whose length a float holds (1e308 components overflow it to a zero axis)."""
    return max(abs(x) for x in v) <= MAX_COMPONENT and math.hypot(*v) >= 1e-12


def _frame_axes(x: list[float], y: list[float]) -> bool:
    """Two directions that span a plane (MJCF's xyaxes: y is made orthogonal to x)."""
    if not (_direction(x) and _direction(y)):
        return False
    cross = (x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0])
    return math.hypot(*cross) >= 1e-9 * math.hypot(*x) * math.hypot(*y)


def _check_joint(path: Path, joint: ET.Element) -> None:
    name = joint.get("name", "?")
    axis = _numbers(path, joint, "axis", 3)
    if axis is not None and not _direction(axis):
        raise URDFError(f"{path}: joint {name!r} axis is zero or has a component beyond ±{MAX_COMPONENT:g}; an axis "
                        "must be a non-zero direction")
    ref = _numbers(path, joint, "ref", 1)
    if ref is not None and abs(ref[0]) > MAX_OFFSET:
        raise URDFError(f"{path}: joint {name!r} ref {ref[0]:g} lies beyond ±{MAX_OFFSET:g} (rad, degrees or m)")
    pos = _numbers(path, joint, "pos", 3)
    if pos is not None and max(map(abs, pos)) > MAX_OFFSET:
        raise URDFError(f"{path}: joint {name!r} pos {pos} lies beyond ±{MAX_OFFSET:g} m of its body")
    _check_range(path, joint, name)


def _check_range(path: Path, joint: ET.Element, name: str) -> None:
    """A joint's range: two finite numbers, lower ≤ upper, within ±MAX_OFFSET."""
    span = _numbers(path, joint, "range", 2)
    if span is not None and span[0] > span[1]:
        raise URDFError(f"{path}: joint {name!r} range lower {span[0]:g} > upper {span[1]:g}")
    if span is not None and max(map(abs, span)) > MAX_OFFSET:
        raise URDFError(f"{path}: joint {name!r} range {span} reaches beyond ±{MAX_OFFSET:g} (rad, degrees or m)")


def _restore_slide_ranges(model: pin.Model, root: ET.Element) -> None:
    """Put back the file's ranges the parser changes: a slide joint's (converted to radians with the angles, when
    they are in degrees) and a hinge's with a ``ref`` (shifted by ``ref``, while its angle is MuJoCo's qpos: the
    placements agree with MuJoCo's at the same q, the ranges then do not)."""
    compiler = root.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") != "radian"
    for joint in root.iter("joint"):
        name, rng, kind = joint.get("name"), joint.get("range"), joint.get("type", "hinge")
        if not (name and rng and model.existJointName(name)):
            continue
        lo, hi = (float(v) for v in rng.split()[:2])
        if kind == "hinge" and joint.get("ref") is not None:
            lo, hi = (math.radians(lo), math.radians(hi)) if degrees else (lo, hi)
        elif not (kind == "slide" and degrees):
            continue
        iq = model.idx_qs[model.getJointId(name)]
        model.lowerPositionLimit[iq], model.upperPositionLimit[iq] = lo, hi


def body_tree(model: pin.Model) -> UrdfTree:
    """The bodies of a Pinocchio model as a tree: each BODY frame's parent body and the joint (or fixed
    joint frame) that carries it; the root is the single top body, or "universe" when there are several."""
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    parents = _parent_frames(model)
    parent_of, joint_of = {}, {}
    for i in bodies:
        name = model.frames[i].name
        parent_of[name], joint_of[name] = _parent_body(model, parents, i)
    root = _root_body(parent_of)
    if root != "universe":
        del parent_of[root], joint_of[root]
    links = [model.frames[i].name for i in bodies] + (["universe"] if root == "universe" else [])
    leaves = [b for b in links if b not in parent_of.values() and b != root]
    return UrdfTree(root, parent_of, joint_of, {}, links, leaves)


def _root_body(parent_of: dict[str, str]) -> str:
    """The single body hanging from the universe, or "universe" when several do."""
    tops = [b for b, p in parent_of.items() if p == "universe"]
    return tops[0] if len(tops) == 1 else "universe"


def _parent_body(model: pin.Model, parents: list[int], i: int) -> tuple[str, str]:
    """The body above BODY frame i and the joint (or fixed joint frame) carrying it (``NAME_fixed`` when the body
    hangs straight from another)."""
    up = parents[i]
    carrier = model.frames[up].name if model.frames[up].type != pin.FrameType.BODY and up != 0 else None
    while up != 0 and model.frames[up].type != pin.FrameType.BODY:
        up = parents[up]
    return model.frames[up].name, carrier or f"{model.frames[i].name}_fixed"


def _parent_frames(model: pin.Model) -> list[int]:
    """Each frame's parent frame, with the frame tree mended where it does not reach the root.

    ``pin.buildReducedModel`` gives the frame of a locked joint itself as its parent. Such a frame hangs
    from the nearest BODY frame before it on the same parent joint whose own chain reaches the root (the
    body the joint was attached to, in the tree order Pinocchio's parsers add frames in), else from the
    universe. Every chain is then a path to frame 0: no walk up the tree can loop.
    """
    parents = [int(f.parentFrame) for f in model.frames]
    reaches = [False] * len(parents)
    reaches[0] = True
    for i in range(1, len(parents)):
        if not _reaches_root(parents, i, reaches):
            parents[i] = next((j for j in range(i - 1, 0, -1) if reaches[j]
                               and model.frames[j].type == pin.FrameType.BODY
                               and model.frames[j].parentJoint == model.frames[i].parentJoint), 0)
        reaches[i] = True
    return parents


def _reaches_root(parents: list[int], i: int, reaches: list[bool]) -> bool:
    """True when following ``parents`` up from frame ``i`` meets a frame known to reach frame 0."""
    seen = {i}
    up = parents[i]
    while not reaches[up]:
        if up in seen:
            return False
        seen.add(up)
        up = parents[up]
    return True


def equalities(path: Path, model: pin.Model, root: pin.JointModel | None = None) -> tuple[tuple[Closure, ...],
                                                                                          tuple[str, ...]]:
    """The MJCF file's ``<equality>`` connects and welds as closures, and its actuated joints (the ``joint`` of each
    ``<actuator>`` element that names one), read by Pinocchio 4's ``buildModelAndConstraintsFromMJCF``.

    Each constraint's two anchors become frames of ``model`` (changed in place): ``NAME_a`` on the first body's
    joint and ``NAME_b`` on the second's (NAME: the equality's name, else ``equality_K``; MuJoCo places the second
    anchor where the first is in the file's reference configuration, qpos0); a connect is a point
    closure, a weld a frame closure. A file with no ``<equality>`` gives none; one whose equalities Pinocchio
    cannot read gives none, with a warning naming why.
    """
    tree = ET.fromstring(read_text(path, "MJCF file", URDFError))
    actuated = tuple(dict.fromkeys(a.get("joint", "") for section in tree.iter("actuator") for a in section
                                   if model.existJointName(a.get("joint", ""))))
    if tree.find("equality") is None:
        return (), actuated
    try:
        built = (pin.buildModelAndConstraintsFromMJCF(str(path)) if root is None else
                 pin.buildModelAndConstraintsFromMJCF(str(path), root, "root_joint"))
    except Exception as exc:  # noqa: BLE001 - the parser raises RuntimeError, ValueError, IndexError, ...
        warnings.warn(f"{path.name}: Pinocchio cannot read its <equality> constraints ({type(exc).__name__}: {exc}); "
                      "the robot is loaded without loops", stacklevel=3)
        return (), actuated
    closures: list[Closure] = []
    for kind, tag, constraints in (("point", "connect", built[1]), ("frame", "weld", built[2])):
        elements = [e for section in tree.iter("equality") for e in section.iter(tag)]
        matched = len(elements) == len(constraints)  # Pinocchio's list in the file's order
        for k, constraint in enumerate(constraints):
            if matched and elements[k].get("active", "true") == "false":
                continue  # MuJoCo's inactive equality: not a loop until the user turns it on
            name = (elements[k].get("name") if matched else None) or f"equality_{len(closures)}"
            for end, joint, placement in (("a", constraint.joint1_id, constraint.joint1_placement),
                                          ("b", constraint.joint2_id, constraint.joint2_placement)):
                model.addFrame(pin.Frame(f"{name}_{end}", joint, placement, pin.FrameType.OP_FRAME))
            closures.append(Closure(f"{name}_a", f"{name}_b", kind))
    return tuple(closures), actuated


def joint_couplings(path: Path, model: pin.Model) -> tuple[Mimic, ...]:
    """The file's active ``<equality><joint joint1=... joint2=... polycoef=...>`` elements whose polynomial is linear,
    as couplings: ``joint1 = multiplier · joint2 + offset`` in MuJoCo's meaning (``y − y0 = a0 + a1 (x − x0)``, with
    y0, x0 the joints' ``ref``), held by every whole-body step and solve (``robot.mimics``). One whose polynomial
    bends (a2, a3 or a4 not zero), or that holds a joint alone, is left out with a warning naming it."""
    tree = ET.fromstring(read_text(path, "MJCF file", URDFError))
    compiler = tree.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") != "radian"
    refs = {j.get("name"): _ref(j, degrees) for j in tree.iter("joint") if j.get("name")}
    out = []
    for element in (e for section in tree.iter("equality") for e in section.iter("joint")):
        follower, leader = element.get("joint1", ""), element.get("joint2")
        coef = [float(v) for v in element.get("polycoef", "0 1 0 0 0").split()] + [0.0] * 5
        if element.get("active", "true") == "false" or not model.existJointName(follower):
            continue
        if leader is None or not model.existJointName(leader) or any(coef[2:5]):
            warnings.warn(f"{path.name}: the joint equality on {follower!r} is not read (kinelab holds a joint "
                          "equal to a linear function of another joint)", stacklevel=3)
            continue
        iq = model.idx_qs[model.getJointId(follower)]
        out.append(Mimic(follower, leader, coef[1], refs.get(follower, 0.0) + coef[0] - coef[1] * refs.get(leader, 0.0),
                         float(model.lowerPositionLimit[iq]), float(model.upperPositionLimit[iq])))
    return tuple(out)


def _ref(joint: ET.Element, degrees: bool) -> float:
    """A hinge's or slide's ``ref`` (its qpos0) in radians or metres."""
    ref = float(joint.get("ref", "0"))
    return math.radians(ref) if degrees and joint.get("type", "hinge") == "hinge" else ref
