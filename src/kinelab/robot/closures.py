"""Closed kinematic loops: a robot whose links close loops (four-bars, parallel ankles, delta robots) is loaded as
the tree its URDF describes, each loop cut at one joint and declared as a closure — two frames that must meet.

A :class:`Closure` holds frame ``frame_b`` on frame ``frame_a``: the components its ``mask`` selects of the error
``e = [aMb.translation; log3(aMb.rotation)]`` (in ``frame_a``'s axes, [linear; angular], m and rad) are zero on a
closed loop, where ``aMb = oMa⁻¹ · oMb``. ``kind="point"`` selects the three linear components (the two frames'
origins coincide: a spherical joint at the cut), ``"frame"`` all six (a weld), and six 0/1 values any subset (a
planar loop's in-plane point, a revolute cut's five: Pinocchio's issue #2729).

The robot's joints split into actuated joints (the ones a controller drives, declared) and passive ones (moved by
the loops); :func:`assemble` moves the passive joints until every loop is closed, the actuated ones held.

Declarations (:func:`read_closures`) are YAML, in the shape of scikit-robot's ``loop_closures.yaml`` sidecar (a
list of closures and the independent, here ``actuated``, joints)::

    closures:
      - {frame_a: coupler_tip, frame_b: rocker_tip, kind: [1, 1, 0, 0, 0, 0]}
    actuated: [crank_joint]
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinelab.errors import FrameNotFoundError, JointNotFoundError, OptionError, URDFError

if TYPE_CHECKING:
    pass

KINDS = {"point": (1, 1, 1, 0, 0, 0), "frame": (1, 1, 1, 1, 1, 1)}
ASSEMBLY_TOL = 1e-10  # [m, rad] the largest closure error an assembly is claimed with
NEWTON_ITERATIONS = 60
RESTARTS = 20


@dataclass(frozen=True)
class Closure:
    """A loop closed by holding ``frame_b`` on ``frame_a`` (see the module's docstring).

    Attributes:
        frame_a, frame_b: the two frames' names (the error is in ``frame_a``'s axes).
        kind: "point", "frame", or six 0/1 values selecting [x, y, z, rx, ry, rz] of the error.
        mask: the six 0/1 values ``kind`` selects.
    """

    frame_a: str
    frame_b: str
    kind: str | tuple[int, ...] = "point"

    def __post_init__(self) -> None:
        """Check the frames' names and the kind.

        Raises:
            OptionError: two names that are not two different strings, or a kind out of the three forms.
        """
        if not isinstance(self.frame_a, str) or not isinstance(self.frame_b, str) or self.frame_a == self.frame_b:
            raise OptionError("Closure frames", (self.frame_a, self.frame_b), "two different frame names")
        object.__setattr__(self, "kind", _kind(self.kind))

    @property
    def mask(self) -> tuple[int, ...]:
        """Which of [x, y, z, rx, ry, rz] the loop holds."""
        return KINDS[self.kind] if isinstance(self.kind, str) else self.kind

    @functools.cached_property
    def rows(self) -> np.ndarray:
        """The indices of the held components."""
        return np.flatnonzero(self.mask)

    @property
    def label(self) -> str:
        """The closure in words."""
        kind = self.kind if isinstance(self.kind, str) else "".join(
            n for n, m in zip(("x", "y", "z", "rx", "ry", "rz"), self.kind, strict=True) if m)
        return f"loop {self.frame_a} = {self.frame_b} ({kind})"


def _kind(kind: Any) -> str | tuple[int, ...]:
    """The kind as "point", "frame" or six 0/1 values.

    Raises:
        OptionError: anything else (named, with the three forms).
    """
    if isinstance(kind, str) and kind in KINDS:
        return kind
    valid = "'point', 'frame' or six 0/1 values over [x, y, z, rx, ry, rz] with at least one 1"
    if isinstance(kind, str) or not isinstance(kind, Sequence) or len(kind) != 6:
        raise OptionError("Closure kind", kind, valid)
    if any(type(k) not in (int, bool) or k not in (0, 1) for k in kind) or not any(kind):
        raise OptionError("Closure kind", kind, valid)
    return tuple(int(k) for k in kind)


def check_closures(model: pin.Model, closures: Any, actuated: Any) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    """The closures and actuated joints of a model, checked.

    Args:
        model: the robot's model.
        closures: a sequence of :class:`Closure`.
        actuated: the actuated joints' names (one-coordinate joints).

    Raises:
        OptionError: not a sequence of Closure / of names. FrameNotFoundError, JointNotFoundError: named.
    """
    if not isinstance(closures, Sequence) or not all(isinstance(c, Closure) for c in closures):
        raise OptionError("closures", closures, "a list of kinelab.Closure")
    names = [f.name for f in model.frames]
    for closure in closures:
        for frame in (closure.frame_a, closure.frame_b):
            if frame not in names:
                raise FrameNotFoundError(frame, names)
    if isinstance(actuated, str) or not isinstance(actuated, Sequence) or not all(isinstance(a, str) for a in actuated):
        raise OptionError("actuated", actuated, "a list of joint names")
    for joint in actuated:
        if not model.existJointName(joint):
            raise JointNotFoundError(joint, list(model.names)[1:])
        if model.joints[model.getJointId(joint)].nv != 1:
            raise OptionError("actuated", joint, "joints with one coordinate (revolute or prismatic)")
    return tuple(closures), tuple(actuated)


def read_closures(path: str | Path) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    """A closures declaration (YAML, see the module's docstring), read as data (``yaml.safe_load``).

    Returns:
        (closures, actuated joints' names).

    Raises:
        URDFError: a missing or unreadable file, or one not of the declared shape (what is wrong named).
    """
    import yaml  # type: ignore[import-untyped]

    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise URDFError(f"cannot read the closures declaration {path}: {str(exc).splitlines()[0]}") from None
    if not isinstance(data, dict) or not isinstance(data.get("closures"), list) or set(data) - {"closures", "actuated"}:
        raise URDFError(f"{path}: a closures declaration is a mapping with 'closures' (a list) and 'actuated'")
    loops = []
    for i, entry in enumerate(data["closures"]):
        if not isinstance(entry, dict) or set(entry) - {"kind"} != {"frame_a", "frame_b"}:
            raise URDFError(f"{path}: closures[{i}] must be {{frame_a, frame_b, kind}}, got {entry!r}")
        try:
            loops.append(Closure(entry["frame_a"], entry["frame_b"], entry.get("kind", "point")))
        except OptionError as exc:
            raise URDFError(f"{path}: closures[{i}]: {exc}") from None
    actuated = data.get("actuated", [])
    if not isinstance(actuated, list) or not all(isinstance(a, str) for a in actuated):
        raise URDFError(f"{path}: 'actuated' must be a list of joint names, got {actuated!r}")
    return tuple(loops), tuple(actuated)
