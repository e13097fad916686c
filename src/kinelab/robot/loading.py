"""Loading: a registered name or a model file → a chain (:class:`~kinelab.robot.chain.Chain`, what an arm's user
gets) or the whole robot (:class:`~kinelab.robot.tree.Robot`: a humanoid, a two-armed robot, a quadruped).

Which one: a registered arm's name (``"panda"``, ``"talos_left"``) or a file with a tool frame gives a chain; a
registered whole robot's name (``"talos"``, ``"g1"``, ``"baxter"``), ``whole=True`` or ``floating=True`` gives the
whole robot. Every decision of a build is :mod:`kinelab.robot.build`'s.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from kinelab.errors import ChainError, OptionError
from kinelab.robot import catalog, descriptions
from kinelab.robot.build import Built, whole_model
from kinelab.robot.chain import Chain
from kinelab.robot.closures import Closure, read_closures
from kinelab.robot.meshes import build_visual_model, mesh_package_dirs, mjcf_geometry
from kinelab.robot.mjcf import is_mjcf
from kinelab.robot.reduce import build_file
from kinelab.robot.srdf import read_srdf
from kinelab.robot.tree import Robot

__all__ = ["load", "whole_of"]


def load(name_or_path: str | Path, tool: str | None = None, locked: dict[str, float] | None = None,
         base: str | None = None, package_dirs: list[str] | None = None, srdf: str | Path | None = None,
         group: str | None = None, xacro_args: dict[str, str] | None = None, *,
         trust_xacro: bool = False, whole: bool | None = None, floating: bool | None = None,
         closures: Sequence[Closure] | str | Path | None = None, actuated: Sequence[str] | None = None) -> Any:
    """Load a registered robot (``kinelab.robots()``) or a model file: a :class:`~kinelab.robot.chain.Chain`
    (an arm) or the whole :class:`~kinelab.robot.tree.Robot` (see the module's docstring).

    Args:
        name_or_path: a registered name such as ``"era"``, ``"panda"`` or ``"talos"``, a path to a URDF, xacro
            or MJCF file, or ``"rd:NAME"``: a description of robot_descriptions (the extra
            ``kinelab[descriptions]``), read from its cache (:mod:`~kinelab.robot.descriptions`).
        tool: the chain's tool frame; default: the registered tool, else a frame named ``tool``, else the
            single leaf link (an error lists the leaves when there are several).
        locked: joints to hold fixed, name → value (rad or m): chain joints, or joints off the chain (held
            at zero, clipped into their limits, when not named).
        base: the frame the chain starts from (default: the URDF root); it must lie on the root → tool
            path. Joints above it are locked, and every pose (FK, targets) is expressed in this frame.
        package_dirs: directories where ``package://NAME/...`` mesh URIs resolve (as ``DIR/NAME/...``, or
            DIR itself when it is the package NAME), before ``ROS_PACKAGE_PATH``'s and example-robot-data's.
            Kinematics never read meshes; the viewer does.
        srdf: an SRDF file: its named configurations (``named_q``), its groups, and the values at which
            joints off the chain are held (the first configuration naming a joint; ``locked`` wins).
        group: an SRDF group whose chain (base → tip), end effector or last joint gives base and tool.
        xacro_args: arguments of a ``.xacro`` source (name → value), expanded with xacrodoc (the extra
            ``kinelab[xacro]``); MJCF sources (root ``<mujoco>``) are read by Pinocchio's MJCF parser.
        trust_xacro: let a ``.xacro`` source run what xacro runs (``$(eval ...)``, ``$(env ...)``,
            ``load_yaml``); without it those are refused with their line (:mod:`~kinelab.robot.xacro`).
        whole: True: the whole robot (no chain is cut); None (default): whole for a registered whole robot.
        floating: the whole robot with a free-flyer at its root (implies ``whole``); None: the registered
            robot's own choice (a humanoid's or quadruped's base floats), else free when its SRDF declares a
            ``<virtual_joint type="floating">`` (a walker's), else fixed.
        closures: the loops the robot closes (implies ``whole``): a list of :class:`~kinelab.Closure`, or a
            closures declaration file (YAML, :mod:`~kinelab.robot.closures`); None: a registered robot's own.
        actuated: the joints a controller drives (the others move with the loops); a declaration file's
            ``actuated`` where None.

    Returns:
        A Chain, or the whole Robot.

    Raises:
        RobotNotFoundError, DescriptionError, URDFError, SRDFError, ChainError, FrameNotFoundError: named.
        JointNotFoundError: a locked joint that does not exist (the valid names listed).
        OptionError: a chain's setting (tool, base, locked, group) given with the whole robot.
    """
    _check_load_arguments(name_or_path, tool, locked, base, package_dirs, srdf, group, xacro_args, trust_xacro)
    _check_flag("whole", whole)
    _check_flag("floating", floating)
    path, entry, name, package_dirs = _source(name_or_path, package_dirs)
    if whole or floating or closures is not None or (whole is None and entry is not None and entry.whole):
        robot = _whole(path, entry, name, package_dirs, srdf, xacro_args, trust_xacro, floating,
                       (tool, base, locked, group))
        _declare(robot, entry, closures, actuated)
        return robot
    if actuated is not None:
        raise OptionError("actuated", actuated, "None without closures (a whole robot's loops: closures=...)")
    return _chain(path, entry, name, tool, locked, base, package_dirs, srdf, group, xacro_args, trust_xacro)


def _source(name_or_path: str | Path, package_dirs: list[str] | None
            ) -> tuple[Path, catalog.Entry | None, str | None, list[str] | None]:
    """(file, registered entry, name, package folders) of what :func:`load` was given: a description of
    robot_descriptions (its packages added), a registered name or a path."""
    if str(name_or_path).startswith(descriptions.PREFIX):
        found = descriptions.resolve(str(name_or_path))
        return found.path, None, found.name, [*(package_dirs or []), *found.package_dirs]
    path, entry = catalog.resolve(name_or_path)
    return path, entry, entry.name if entry else None, package_dirs


def _chain(path: Path, entry: catalog.Entry | None, name: str | None, tool: str | None,
           locked: dict[str, float] | None, base: str | None, package_dirs: list[str] | None,
           srdf: str | Path | None, group: str | None, xacro_args: dict[str, str] | None,
           trust_xacro: bool) -> Chain:
    """:func:`load`'s chain: the registered tool, base or group where the entry has them."""
    if entry is not None and entry.whole and not (tool or base or group):
        raise ChainError(f"{entry.name} is a whole robot: name the chain's tool (--tool on the command line, tool= "
                         f"in Python), such as {', '.join((entry.hands + entry.feet)[:3]) or 'one of its leaf links'}, "
                         "or take the whole robot (kinelab.load(name); --whole where a command takes it)")
    if entry is not None and not group:
        tool, base, group, srdf = _registered(entry, tool, base, srdf)
    chain = Chain(build_file(path, tool=tool, locked=locked, name=name, base=base, package_dirs=package_dirs,
                             srdf=srdf, group=group, xacro_args=xacro_args, trust_xacro=trust_xacro))
    chain.attach(partial(whole_of, chain))
    if entry is not None and entry.display is not None and chain.n == len(entry.display):
        chain.display_pose = np.array(entry.display)
    return chain


def _registered(entry: catalog.Entry, tool: str | None, base: str | None,
                srdf: str | Path | None) -> tuple[str | None, str | None, str | None, str | Path | None]:
    """(tool, base, group, srdf) with the entry's where the caller gave none (its group only when neither tool nor
    base is given)."""
    tool, base = tool or entry.tool, base or entry.base
    group = entry.group if entry.group and not (tool or base) else None
    return tool, base, group, srdf or catalog.srdf_path(entry)


def _whole(path: Path, entry: catalog.Entry | None, name: str | None, package_dirs: list[str] | None,
           srdf: str | Path | None, xacro_args: dict[str, str] | None, trust_xacro: bool, floating: bool | None,
           chain_settings: tuple[Any, ...]) -> Robot:
    """:func:`load`'s whole robot."""
    for key, value in zip(("tool", "base", "locked", "group"), chain_settings, strict=True):
        if value is not None:
            raise OptionError(key, value, "None with the whole robot (a chain of it: robot.chain(base, tool))")
    srdf = srdf or (catalog.srdf_path(entry) if entry is not None else None)
    if floating is None:  # the catalogue says, else the SRDF's floating virtual joint (a walker's: anymal, go2, a1)
        floating = entry.floating if entry is not None else bool(srdf is not None and read_srdf(srdf).floats)
    made = whole_model(path, floating=floating, name=name, package_dirs=package_dirs, srdf=srdf,
                       xacro_args=xacro_args, trust_xacro=trust_xacro)
    chains = partial(_chain, path, None, made.name, package_dirs=package_dirs, srdf=srdf, group=None,
                     xacro_args=xacro_args, trust_xacro=trust_xacro)
    robot = Robot(made.model, name=made.name, source=made.source, srdf=made.srdf,
                  chain_source=lambda tool, base, locked: chains(tool, locked, base),
                  geometry=partial(_geometry, made.model, made.urdf_path, mesh_package_dirs(package_dirs)))
    robot.mimics = made.mimics
    if made.closures:
        robot.declare_closures(made.closures, made.actuated)
    if entry is not None:
        robot.hands, robot.feet = entry.hands, entry.feet
    return robot


def _declare(robot: Robot, entry: catalog.Entry | None, closures: Sequence[Closure] | str | Path | None,
             actuated: Sequence[str] | None) -> None:
    """The robot's loops declared: those given (a list, or a declaration file the user named), else the registered
    robot's."""
    if closures is None and entry is not None:
        closures = catalog.closures_path(entry)
    if closures is None and robot.closures:  # an MJCF's own <equality> loops, declared by _whole
        closures, actuated = robot.closures, robot.actuated if actuated is None else actuated
    if closures is None:
        if actuated is not None:
            raise OptionError("actuated", actuated, "None without closures (a whole robot's loops: closures=...)")
        return
    if isinstance(closures, str | Path):
        loops, declared = read_closures(closures)
        robot.declare_closures(loops, declared if actuated is None else actuated)
    else:
        robot.declare_closures(closures, () if actuated is None else actuated)


def _geometry(model: Any, urdf_path: Path, package_dirs: list[str], kind: str) -> Any:
    """The whole robot's geometry of ``kind`` ("visual" or "collision")."""
    if is_mjcf(urdf_path):
        return mjcf_geometry(model, urdf_path, kind)
    return build_visual_model(model, urdf_path, package_dirs, kind)


def whole_of(chain: Chain) -> Robot:
    """The whole robot a chain was cut from: its file's whole model (fixed base), or its in-memory model."""
    built: Built = chain._built
    if built.source is not None:
        path = built.source
        return _whole(path, None, chain.name, chain.package_dirs, None if chain.srdf is None else chain.srdf.path,
                      chain.xacro_args or None, chain.trust_xacro, False, (None, None, None, None))
    assert built.full is not None  # an in-memory chain keeps the model it was cut from
    return Robot.from_model(built.full, name=chain.name)


def _check_flag(name: str, value: Any) -> None:
    if value is not None and not isinstance(value, bool):
        raise OptionError(name, value, "True, False or None")


def _check_load_arguments(source: Any, tool: Any, locked: Any, base: Any, package_dirs: Any, srdf: Any,
                          group: Any, xacro_args: Any, trust_xacro: Any) -> None:
    """Refuse an argument of the wrong type, naming it and what it takes (before any file is read)."""
    checks = (
        ("name_or_path", source, _is_path, False, "a registered name, a file path or 'rd:NAME'"),
        ("tool", tool, _is_name, True, "a frame name, or None"),
        ("base", base, _is_name, True, "a frame name, or None"),
        ("group", group, _is_name, True, "an SRDF group name, or None"),
        ("srdf", srdf, _is_path, True, "a path to an SRDF file, or None"),
        ("package_dirs", package_dirs, _is_path_list, True, "a list of folder paths, or None"),
        ("locked", locked, _is_named_table, True, "a dict joint name → value [rad or m], or None"),
        ("xacro_args", xacro_args, _is_named_table, True, "a dict argument name → value, or None"),
        ("trust_xacro", trust_xacro, lambda v: isinstance(v, bool), False, "True or False"),
    )
    for name, value, test, optional, valid in checks:
        if not ((optional and value is None) or test(value)):
            raise OptionError(name, value, valid)


def _is_path_list(value: Any) -> bool:
    """A list or tuple of paths."""
    return isinstance(value, list | tuple) and all(map(_is_path, value))


def _is_path(value: Any) -> bool:
    """A Path, or a string that names one (an empty string names nothing, though Path("") is the current folder)."""
    return isinstance(value, Path) or _is_name(value)


def _is_name(value: Any) -> bool:
    return isinstance(value, str) and value.strip() != ""


def _is_named_table(value: Any) -> bool:
    return isinstance(value, dict) and all(isinstance(k, str) for k in value)
