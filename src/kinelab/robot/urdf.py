"""A URDF read with the standard library before Pinocchio sees it: the joint/link graph, and the rules a
file must meet to be a model (so that errors name the file, the element and the rule).

Rules: one root link; no link that is its own parent; every joint has a parent and a child; origins are
finite and within ``MAX_OFFSET`` of their parent; axes are finite, not zero, and no component beyond
``MAX_COMPONENT``; limits are finite with lower ≤ upper; the text decodes in the encoding the XML declares
(UTF-8 when it declares none).

What Pinocchio's own parser (urdfdom on tinyxml2) reads, this reader reads too: a comment nested inside a
comment (xacro output has them) and a namespace prefix used without its declaration (``<xacro:...>`` left in
a file) are tolerated; a mimic joint whose leader the file lacks is kept as a plain joint, with one warning
(Pinocchio ignores the tag when it builds the model without mimic joints).
"""

from __future__ import annotations

import contextlib
import math
import re
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

from kinelab.errors import ChainError, URDFError

MAX_COMPONENT = 1e6  # the largest component of a direction (an axis): its length must fit a float
MAX_OFFSET = 1e4  # [m] the largest joint or link offset a model may have (no robot is 10 km long)
# links (or MJCF bodies) a file may have: checked before Pinocchio's parser, which crashes the process on a
# URDF of 4000 links and runs out of memory on an MJCF of 2000 bodies; the longest chain kinelab can use is
# far shorter (Pinocchio's Data limit, about 320 joints)
MAX_LINKS = 1500


@dataclass(frozen=True)
class UrdfTree:
    """The joint/link graph of a URDF."""

    root: str
    parent_of: dict[str, str]  # child link -> parent link
    joint_of: dict[str, str]  # child link -> joint name
    mimic: dict[str, str]  # joint -> the joint it mimics
    links: list[str]
    leaves: list[str]
    broken_mimic: dict[str, str] = field(default_factory=dict)  # joint -> a leader the file lacks
    mimic_factors: dict[str, tuple[float, float]] = field(default_factory=dict)  # joint -> (multiplier, offset)

    def check_mimics(self, path: Path, chain: list[str], locked: Iterable[str]) -> None:
        """A mimic joint whose leader is missing: refused on the chain (unless locked), locked with one warning
        off it (Pinocchio's model ignores the tag there too).

        Raises:
            URDFError: such a joint on the chain.
        """
        held = set(locked)
        for name, leader in self.broken_mimic.items():
            if name in chain and name not in held:
                raise URDFError(f"{path}: joint {name!r} mimics {leader!r}, which is not a joint of this file; "
                                f"hold it at a value (locked={{{name!r}: value}}) or fix the file")
            warnings.warn(f"{path.name}: joint {name!r} mimics {leader!r}, which is not a joint of this file; "
                          "it is off the chain and locked", stacklevel=5)


def read_tree(path: Path) -> UrdfTree:
    """The graph of the URDF at ``path``, its elements checked against the rules above.

    Raises:
        URDFError: a missing or malformed file, or an element that breaks a rule (named with the rule).
        ChainError: a closed loop.
    """
    xml = _parse(path)
    links = [link.get("name", "") for link in xml.findall("link")]
    check_size(path, len(links), "links")
    parent_of, joint_of, mimic = _edges(path, xml)
    _check_links_defined(path, links, parent_of, joint_of)
    mimic, broken = _split_mimics(mimic, {j.get("name", "?") for j in xml.findall("joint")})
    roots = [link for link in links if link not in parent_of]
    if not links:
        raise URDFError(f"malformed URDF {path}: it has no <link> element (a robot is at least one link; a file "
                        "written from a xacro that expanded to nothing looks like this)")
    if len(roots) != 1:
        raise URDFError(f"malformed URDF {path}: {len(roots)} links have no parent ({', '.join(roots[:5])}); a URDF "
                        "tree has one root (join the others to it with fixed joints)")
    parents = set(parent_of.values())
    return UrdfTree(roots[0], parent_of, joint_of, mimic, links, [link for link in links if link not in parents],
                    broken, _mimic_factors(xml))


def _mimic_factors(xml: ET.Element) -> dict[str, tuple[float, float]]:
    """Each mimic joint's (multiplier, offset) as the file gives them (URDF's defaults 1 and 0); a joint whose
    numbers are not finite numbers is left out (never folded as a coupling)."""
    factors = {}
    for joint in xml.findall("joint"):
        m = joint.find("mimic")
        if m is None:
            continue
        try:
            values = (float(m.get("multiplier", "1")), float(m.get("offset", "0")))
        except ValueError:
            continue
        if all(map(math.isfinite, values)):
            factors[joint.get("name", "?")] = values
    return factors


def _split_mimics(mimic: dict[str, str], joints: set[str]) -> tuple[dict[str, str], dict[str, str]]:
    """The mimic table split into the followers whose leader is a joint of the file and those whose is not."""
    broken = {name: leader for name, leader in mimic.items() if leader not in joints}
    return {name: leader for name, leader in mimic.items() if name not in broken}, broken


def _check_links_defined(path: Path, links: list[str], parent_of: dict[str, str], joint_of: dict[str, str]) -> None:
    """Refuse a joint that names a link the file does not define."""
    known = set(links)
    for child, parent in parent_of.items():
        unknown = [link for link in (parent, child) if link not in known]
        if unknown:
            raise URDFError(f"{path}: joint {joint_of[child]!r} names link {unknown[0]!r}, "
                            "which the file does not define")


def _edges(path: Path, xml: ET.Element) -> tuple[dict[str, str], dict[str, str], dict[str, str]]:
    """Each child link's parent link and joint, and each mimic joint's leader, the joints checked.

    Raises:
        URDFError: a joint that breaks a rule.
        ChainError: a link that is the child of two joints (a closed loop).
    """
    parent_of: dict[str, str] = {}
    joint_of: dict[str, str] = {}
    mimic: dict[str, str] = {}
    for joint in xml.findall("joint"):
        name = joint.get("name", "?")
        parent, child = _check_joint(path, joint)
        if child in joint_of:
            raise ChainError(
                f"{path.name} has a closed loop: link {child!r} is the child of both joint "
                f"{joint_of[child]!r} and joint {name!r}; kinelab handles serial chains and trees only"
            )
        parent_of[child], joint_of[child] = parent, name
        m = joint.find("mimic")
        if m is not None:
            mimic[name] = m.get("joint", "")
    return parent_of, joint_of, mimic


def check_size(path: Path, count: int, what: str) -> None:
    """Refuse a file of more than MAX_LINKS links (bodies) before any parser allocates for it.

    Raises:
        URDFError: naming the count and the limit.
    """
    if count > MAX_LINKS:
        raise URDFError(f"{path.name} has {count} {what}; kinelab reads files of at most {MAX_LINKS} (Pinocchio's "
                        "parser fails on files far larger, and no chain longer than about 320 joints fits its Data)")


def _parse(path: Path) -> ET.Element:
    if not path.is_file():
        raise URDFError(f"URDF file not found: {path}")
    try:
        xml = ET.parse(path).getroot()
    except ET.ParseError as exc:
        xml = _parse_leniently(path, exc)
    except (UnicodeDecodeError, LookupError) as exc:
        raise URDFError(f"URDF {path} cannot be decoded: {exc}") from None
    if xml.tag != "robot":
        raise URDFError(f"malformed URDF {path}: the root element is <{xml.tag}>, expected <robot>")
    return xml


_COMMENT = re.compile(r"<!--.*?-->", re.S)
_PREFIX = re.compile(r"<\/?([A-Za-z_][\w.-]*):|\s([A-Za-z_][\w.-]*):[\w.-]+\s*=")
_ROOT_TAG = re.compile(r"<robot\b")


def _parse_leniently(path: Path, first: ET.ParseError) -> ET.Element:
    """The file as Pinocchio's parser reads it: comments cut out (a nested one leaves its tail as text) and every
    undeclared namespace prefix declared on <robot>; the first error is reported when that does not help."""
    try:
        text = path.read_bytes().decode(_declared_encoding(path))
    except (UnicodeDecodeError, LookupError) as exc:
        raise URDFError(f"URDF {path} cannot be decoded: {exc}") from None
    text = re.sub(r"^\s*<\?xml[^>]*\?>", "", _COMMENT.sub("", text))
    prefixes = {p for pair in _PREFIX.findall(text) for p in pair if p and p not in ("xml", "xmlns")}
    declared = set(re.findall(r"xmlns:([\w.-]+)\s*=", text))
    extra = "".join(f' xmlns:{p}="urn:kinelab:undeclared:{p}"' for p in sorted(prefixes - declared))
    try:
        return _first_root(_ROOT_TAG.sub("<robot" + extra, text, count=1))
    except ET.ParseError:
        raise URDFError(f"malformed URDF {path}: {first}") from None


def _first_root(text: str) -> ET.Element:
    """The document's first top-level element, whatever follows its end tag (Pinocchio's parser takes the first
    ``<robot>`` and reads no further: files in the wild leave a comment open past ``</robot>``).

    Raises:
        ET.ParseError: the text is not well-formed before that end tag.
    """
    parser: ET.XMLPullParser[tuple[str, Any]] = ET.XMLPullParser(events=("start", "end"))
    with contextlib.suppress(ET.ParseError):  # an error past the root's end is not read; one before it is raised
        parser.feed(text)
    depth, root = 0, None
    for item in parser.read_events():
        event, element = cast(tuple[str, ET.Element], item)
        root = element if root is None else root
        depth += 1 if event == "start" else -1
        if depth == 0:
            return root
    parser.close()  # raises the error that ended the text before the root's end tag
    raise ET.ParseError("no element")


def _declared_encoding(path: Path) -> str:
    head = path.read_bytes()[:200].decode("ascii", "replace")
    found = re.search(r"encoding\s*=\s*[\"']([\w.-]+)[\"']", head)
    return found.group(1) if found else "utf-8"


def _check_joint(path: Path, joint: ET.Element) -> tuple[str, str]:
    """(parent link, child link) of a joint whose origin, axis and limits meet the rules."""
    name = joint.get("name", "?")
    parent, child = joint.find("parent"), joint.find("child")
    if parent is None or child is None:
        raise URDFError(f"malformed URDF {path}: joint {name!r} lacks <parent> or <child>")
    p, c = parent.get("link", ""), child.get("link", "")
    if p == c:
        raise URDFError(f"{path}: joint {name!r} connects link {p!r} to itself")
    where = f"{path}: joint {name!r}"
    _check_origin(where, joint.find("origin"))
    axis = joint.find("axis")
    if axis is not None and joint.get("type") not in ("fixed", "floating"):
        _check_axis(where, axis)
    limit = joint.find("limit")
    if limit is not None and joint.get("type") in ("revolute", "prismatic"):
        lo = _numbers(where, "limit lower", limit.get("lower", "0"), 1)[0]
        hi = _numbers(where, "limit upper", limit.get("upper", "0"), 1)[0]
        if lo > hi:
            raise URDFError(f"{where}: limit lower {lo:g} > upper {hi:g}")
    return p, c


def _check_origin(where: str, origin: ET.Element | None) -> None:
    """A joint's origin: finite xyz [m] within MAX_OFFSET of its parent, finite rpy [rad]."""
    if origin is None:
        return
    xyz = _numbers(where, "origin xyz", origin.get("xyz", "0 0 0"), 3)
    _numbers(where, "origin rpy", origin.get("rpy", "0 0 0"), 3)
    if max(abs(v) for v in xyz) > MAX_OFFSET:
        raise URDFError(f"{where}: origin xyz {xyz} is more than {MAX_OFFSET:g} m from its parent")


def _check_axis(where: str, axis: ET.Element) -> None:
    """A moving joint's axis: a finite, non-zero direction whose length a float holds."""
    a = _numbers(where, "axis xyz", axis.get("xyz", "1 0 0"), 3)
    if math.hypot(*a) < 1e-12:
        raise URDFError(f"{where}: the axis is zero; an axis must be a non-zero direction")
    if max(map(abs, a)) > MAX_COMPONENT:  # its length overflows: Pinocchio would turn about no unit axis
        raise URDFError(f"{where}: the axis {a} has a component beyond ±{MAX_COMPONENT:g}; give a direction "
                        "(its length is normalised)")


def _numbers(where: str, what: str, text: str, count: int) -> list[float]:
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise URDFError(f"{where}: {what} must be {count} finite number{'s' if count > 1 else ''}, got {text!r}")
    return values
