"""MJCF (MuJoCo's XML): Pinocchio's model of the file, and the body tree kinelab needs from it.

Pinocchio reads the kinematics (``pin.buildModelFromMJCF``). Two things are added here. The body tree
(root, parents, the joint that moves each body, leaves) is taken from Pinocchio's frames, so that tool,
base and SRDF work as for a URDF. And slide (prismatic) joint ranges are restored from the file when its
angles are in degrees (MuJoCo's default): the parser converts every range to radians, metres included.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from kinelab.errors import URDFError
from kinelab.robot.urdf import UrdfTree


def is_mjcf(path: Path) -> bool:
    """True when the file's root element is ``<mujoco>``."""
    try:
        for _, element in ET.iterparse(path, events=("start",)):
            return element.tag == "mujoco"
    except (OSError, ET.ParseError):
        return False
    return False


def read_mjcf(path: Path) -> tuple[pin.Model, UrdfTree]:
    """Pinocchio's model of an MJCF file and its body tree.

    Raises:
        URDFError: a file Pinocchio cannot read (the file and Pinocchio's reason named).
    """
    try:
        model = pin.buildModelFromMJCF(str(path))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(f"Pinocchio cannot read the MJCF {path}: {exc}") from None
    _restore_slide_ranges(model, ET.parse(path).getroot())
    return model, body_tree(model)


def _restore_slide_ranges(model: pin.Model, root: ET.Element) -> None:
    compiler = root.find("compiler")
    if compiler is not None and compiler.get("angle", "degree") == "radian":
        return
    for joint in root.iter("joint"):
        name, rng = joint.get("name"), joint.get("range")
        if joint.get("type") == "slide" and name and rng and model.existJointName(name):
            lo, hi = (float(v) for v in rng.split()[:2])
            iq = model.idx_qs[model.getJointId(name)]
            model.lowerPositionLimit[iq], model.upperPositionLimit[iq] = lo, hi


def body_tree(model: pin.Model) -> UrdfTree:
    """The bodies of a Pinocchio model as a tree: each BODY frame's parent body and the joint (or fixed
    joint frame) that carries it; the root is the single top body, or "universe" when there are several."""
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    parent_of, joint_of = {}, {}
    for i in bodies:
        up = model.frames[i].parentFrame
        carrier = model.frames[up].name if model.frames[up].type != pin.FrameType.BODY and up != 0 else None
        while up != 0 and model.frames[up].type != pin.FrameType.BODY:
            up = model.frames[up].parentFrame
        name = model.frames[i].name
        parent_of[name] = model.frames[up].name
        joint_of[name] = carrier or f"{name}_fixed"
    tops = [b for b, p in parent_of.items() if p == "universe"]
    root = tops[0] if len(tops) == 1 else "universe"
    if root != "universe":
        del parent_of[root], joint_of[root]
    links = [model.frames[i].name for i in bodies] + (["universe"] if root == "universe" else [])
    leaves = [b for b in links if b not in parent_of.values() and b != root]
    return UrdfTree(root, parent_of, joint_of, {}, links, leaves)
