"""SRDF: the groups (a chain base → tip, or a list of joints) and the named configurations of a robot.

Only what kinematics needs is read: ``<group>`` (with ``<chain>``, ``<joint>`` and nested ``<group>``),
``<group_state>`` and ``<end_effector>``. Collision pairs and virtual joints are ignored.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from kinelab.errors import SRDFError
from kinelab.files import read_text


@dataclass(frozen=True)
class Group:
    """A planning group: a chain (base link, tip link), joints, and the groups it includes."""

    name: str
    chain: tuple[str, str] | None = None
    joints: tuple[str, ...] = ()
    subgroups: tuple[str, ...] = ()


@dataclass
class Srdf:
    """The groups, named configurations (name → joint → value [rad or m]) and end effectors of one SRDF."""

    path: Path
    groups: dict[str, Group] = field(default_factory=dict)
    states: dict[str, dict[str, float]] = field(default_factory=dict)
    end_effectors: dict[str, str] = field(default_factory=dict)  # group → parent link
    virtual_joints: tuple[str, ...] = ()  # a floating base's joint (declared, or given a pose): skipped
    floats: bool = False  # a <virtual_joint type="floating">: the robot walks or flies, its base free
    disabled_collisions: tuple[tuple[str, str], ...] = ()  # link pairs never checked against each other

    def group(self, name: str) -> Group:
        """The group named, or an SRDFError listing the groups."""
        if name not in self.groups:
            raise SRDFError(f"{self.path.name} has no group {name!r}; groups: {', '.join(self.groups) or 'none'}")
        return self.groups[name]

    def state(self, name: str) -> dict[str, float]:
        """The named configuration, or an SRDFError listing the names."""
        if name not in self.states:
            raise SRDFError(f"{self.path.name} has no configuration {name!r}; configurations: "
                            f"{', '.join(self.states) or 'none'}")
        return self.states[name]

    def group_joints(self, name: str) -> list[str]:
        """The joints a group lists, its subgroups' included in order (a chain group lists none: see ``chain``).

        Raises:
            SRDFError: an unknown group, or groups that include each other (the cycle named).
        """
        cycle = self._cycle(name)
        if cycle:
            raise SRDFError(f"{self.path.name}: group {cycle[-1]!r} includes itself ({' -> '.join(cycle)}); a group "
                            "may include only other groups")
        out: list[str] = []
        known: set[str] = set()
        todo, visited = [name], set()
        while todo:  # depth first, each group once: a chain of thousands of groups needs no recursion
            current = todo.pop()
            if current in visited:
                continue
            visited.add(current)
            g = self.group(current)
            out += [j for j in g.joints if j not in known]
            known.update(g.joints)
            todo.extend(reversed(g.subgroups))
        return out

    def _cycle(self, name: str, done: set[str] | None = None) -> list[str]:
        """The groups of a cycle reached from ``name`` (first and last the same), or []; ``done`` holds groups
        already known to reach none (shared between calls, it makes a check of every group one pass).

        Raises:
            SRDFError: a subgroup that is not a group of the file.
        """
        on_path: dict[str, int] = {}
        path: list[str] = []
        done = set() if done is None else done
        todo: list[tuple[str, bool]] = [(name, False)]
        while todo:
            current, leaving = todo.pop()
            if leaving:
                path.pop()
                del on_path[current]
                done.add(current)
                continue
            if current in on_path:
                return [*path[on_path[current]:], current]
            if current in done:
                continue
            on_path[current] = len(path)
            path.append(current)
            todo.append((current, True))
            todo.extend((sub, False) for sub in reversed(self.group(current).subgroups))
        return []

    def check_joints(self, known: list[str]) -> None:
        """Refuse a group or configuration naming a joint the robot does not have (file and joint named)."""
        done: set[str] = set()
        for g in self.groups:  # every subgroup named exists and none includes itself; one pass over them all
            cycle = self._cycle(g, done)
            if cycle:
                raise SRDFError(f"{self.path.name}: group {cycle[-1]!r} includes itself ({' -> '.join(cycle)}); a "
                                "group may include only other groups")
        for where, names in [*((f"group {g!r}", list(self.groups[g].joints)) for g in self.groups),
                             *((f"configuration {s!r}", list(v)) for s, v in self.states.items())]:
            unknown = [j for j in names if j not in known and j not in self.virtual_joints]
            if unknown:
                raise SRDFError(f"{self.path.name}: {where} names joint {unknown[0]!r}, which the robot does not have")

    def check_links(self, known: list[str]) -> None:
        """Refuse an end effector or a chain naming a link the robot does not have (file and link named)."""
        for where, link in [*((f"end effector of group {g!r}", link) for g, link in self.end_effectors.items()),
                            *((f"group {g!r}'s chain", link) for g, grp in self.groups.items() if grp.chain
                              for link in grp.chain)]:
            if link not in known:
                raise SRDFError(f"{self.path.name}: the {where} names link {link!r}, which the robot does not have")

    def tool_and_base(self, group: str, child_link: dict[str, str]) -> tuple[str, str | None]:
        """(tool link, base link or None for the root) of a group: its chain's tip and base, else its end
        effector's parent link, else the child link of its last joint (``child_link``: joint → link)."""
        g = self.group(group)
        if g.chain is not None:
            return g.chain[1], g.chain[0]
        if group in self.end_effectors:
            return self.end_effectors[group], None
        joints = self.group_joints(group)
        if not joints:
            raise SRDFError(f"{self.path.name}: group {group!r} has no chain and no joints to take a tool from")
        return child_link[joints[-1]], None

    def reference(self) -> dict[str, float]:
        """Every joint value the named configurations give, the first configuration naming a joint winning."""
        out: dict[str, float] = {}
        for values in self.states.values():
            for joint, value in values.items():
                if joint not in self.virtual_joints:
                    out.setdefault(joint, value)
        return out


def read_srdf(path: str | Path) -> Srdf:
    """Read the groups, named configurations and end effectors of an SRDF file.

    Raises:
        SRDFError: a missing or malformed file, a configuration value that is not a number.
    """
    path = Path(path)
    try:
        root = ET.fromstring(read_text(path, "SRDF", SRDFError))
    except ET.ParseError as exc:
        raise SRDFError(f"cannot read SRDF {path}: {exc}") from None
    _check_unique(root, path)
    out = Srdf(path)
    for g in root.findall("group"):  # top-level definitions (a nested <group name=.../> only refers to one)
        out.groups.setdefault(g.get("name", ""), _group(g))
    virtual = [v.get("name", "") for v in root.iter("virtual_joint")]
    for st in root.iter("group_state"):
        out.states[st.get("name", "")], floating = _state(st, path)
        virtual += floating
    out.virtual_joints = tuple(dict.fromkeys(virtual))
    out.floats = any(v.get("type") == "floating" for v in root.iter("virtual_joint"))
    for ee in root.iter("end_effector"):
        out.end_effectors.setdefault(ee.get("group", ""), ee.get("parent_link", ""))
    out.disabled_collisions = tuple((d.get("link1", ""), d.get("link2", "")) for d in root.iter("disable_collisions"))
    return out


def _check_unique(root: ET.Element, path: Path) -> None:
    """Refuse two groups or two group states of one name (the second would be dropped, or win, without a word).

    Raises:
        SRDFError: the name given twice.
    """
    for tag, elements in (("group", root.findall("group")), ("group_state", list(root.iter("group_state")))):
        names = [e.get("name", "") for e in elements]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise SRDFError(f"{path.name}: two {tag} elements are named {twice[0]!r}; names must be unique")


def _group(g: ET.Element) -> Group:
    """A ``<group>``: its chain (base and tip links), joints and the groups it names."""
    chain = g.find("chain")
    return Group(g.get("name", ""),
                 (chain.get("base_link", ""), chain.get("tip_link", "")) if chain is not None else None,
                 tuple(j.get("name", "") for j in g.findall("joint")),
                 tuple(s.get("name", "") for s in g.findall("group")))


def _state(st: ET.Element, path: Path) -> tuple[dict[str, float], list[str]]:
    """A ``<group_state>``'s joint values, and the joints it gives a floating base's pose (x y z qx qy qz qw: not a
    chain joint's value).

    Raises:
        SRDFError: a value that is not a finite number.
    """
    values, floating = {}, []
    for j in st.findall("joint"):
        if len(j.get("value", "").split()) > 1:
            floating.append(j.get("name", ""))
        else:
            values[j.get("name", "")] = _number(j, path)
    return values, floating


def _number(joint: ET.Element, path: Path) -> float:
    try:
        value = float(joint.get("value", "").split()[0])
    except (ValueError, IndexError):
        value = math.nan
    if not math.isfinite(value):
        raise SRDFError(f"{path.name}: joint {joint.get('name')!r} of a group_state has value "
                        f"{joint.get('value')!r}, not a finite number") from None
    return value
