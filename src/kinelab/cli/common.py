"""What every command shares: the one-line parser errors, the robot arguments, q on the command line, output.

Angles on the command line are radians unless ``--deg`` is given; ``--deg`` applies to revolute and
continuous joints only (prismatic joints stay in metres).

The parsers import nothing heavy: NumPy, Pinocchio, the robot and the solvers load in the handlers that use them,
so ``kinelab --help`` and ``kinelab robots`` start without them.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import TYPE_CHECKING, Any, NoReturn, TypeAlias

from kinelab import lazy
from kinelab.errors import ConfigurationError, KinelabError

if TYPE_CHECKING:
    import numpy as np
    import pinocchio as pin
    from numpy.typing import ArrayLike

    from kinelab import collision, geometry, progress
    from kinelab import robot as robot_module
    from kinelab.robot import Chain
else:
    collision = lazy.module("kinelab.collision", globals())
    geometry = lazy.module("kinelab.geometry", globals())
    np = lazy.module("numpy", globals())
    pin = lazy.module("pinocchio", globals())
    progress = lazy.module("kinelab.progress", globals())
    robot_module = lazy.module("kinelab.robot", globals())


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2, as for every user error."""

    def error(self, message: str) -> NoReturn:
        """Print ``message`` on one line with the help hint and exit with code 2."""
        command = " ".join(self.prog.split()[1:])  # "" for the top parser, "ik" for a subcommand
        self.exit(2, f"kinelab: error: {message} (see 'kinelab {command + ' ' if command else ''}--help')\n")

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:
        """argparse's parse, then a refusal of any empty value: ``--tool ''`` or ``--out ''`` would otherwise read as
        "not given" and the command would run with the default (a page served for ever, a report written where the
        user did not ask)."""
        found, extra = super().parse_known_args(args, namespace)
        for action in self._actions:
            if _has_empty(getattr(found, action.dest, None)):
                name = action.option_strings[-1] if action.option_strings else action.dest
                leave = " or leave the option out" if action.option_strings else ""
                self.error(f"argument {name}: an empty value; give {action.metavar or action.dest.upper()}{leave}")
        return found, extra



def _has_empty(value: object) -> bool:
    """True when an option's value, or one of its values (lists of lists for repeated nargs), is a blank string."""
    values = value if isinstance(value, list) else [value]
    flat = [v for item in values for v in (item if isinstance(item, list) else [item])]
    return any(isinstance(v, str) and not v.strip() for v in flat)


Subcommands: TypeAlias = "argparse._SubParsersAction[Parser]"
"""What each command's ``add`` is handed: the ``kinelab`` parser's subcommands."""


def positive_number(text: str) -> float:
    """An argparse type: a finite number > 0 (a time, a length, a noise level).

    Raises:
        argparse.ArgumentTypeError: anything else (argparse names the option).
    """
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number > 0")
    return value


def count(text: str, least: int = 1) -> int:
    """An argparse type: a whole number ≥ 1 (≥ ``least``) that a C int holds (a count of targets, rounds, samples).

    Raises:
        argparse.ArgumentTypeError: anything else (argparse names the option).
    """
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not least <= value <= 2**31 - 1:
        raise argparse.ArgumentTypeError(f"{text} is not a whole number in [{least}, {2**31 - 1}]")
    return value


def count_or_zero(text: str) -> int:
    """An argparse type: a whole number ≥ 0 that a C int holds (0: a part of a protocol skipped).

    Raises:
        argparse.ArgumentTypeError: anything else (argparse names the option).
    """
    return count(text, least=0)


def q_from_cli(robot: Chain, values: list[str], deg: bool, what: str = "q") -> np.ndarray:
    """One number per joint (rad or m; degrees with --deg), or the name of an SRDF configuration.

    Raises:
        ConfigurationError: a value that is not a number, or the wrong count.
    """
    if len(values) == 1 and not is_number(values[0]):
        return robot.named_q(values[0])
    numbers = []
    for v in values:
        if not is_number(v):
            raise ConfigurationError(f"{what}: {v!r} is not a number (give {robot.n} numbers, or one SRDF "
                                     "configuration name with --srdf)")
        numbers.append(float(v))
    q = robot.check_q(numbers, what=what)
    angular = np.array([k != "prismatic" for k in robot.joint_kinds])
    if deg:
        return np.where(angular, np.deg2rad(q), q)
    for i in np.flatnonzero(angular & (np.abs(q) > 2 * np.pi + 1e-9)):
        j = robot.joints[i]
        if not j.lower <= q[i] <= j.upper:  # a joint whose limits allow it may turn that far in radians
            raise ConfigurationError(f"{what}: {q[i]:g} for {j.name} looks like degrees (beyond ±2π rad and "
                                     "outside its limits): add --deg, or give radians")
    return q


def is_number(text: str) -> bool:
    """Whether a command-line word reads as a number."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def load_robot(args: argparse.Namespace) -> Chain:
    """The robot a per-robot command names, with its --tool, --base, --srdf, --group, --package-dir and
    --xacro-arg."""
    return robot_module.load(args.robot, tool=args.tool, base=args.base, srdf=args.srdf, group=args.group,
                             package_dirs=args.package_dir, xacro_args=pairs(args.xacro_arg, "--xacro-arg"),
                             trust_xacro=args.trust_xacro, locked=_locked(args.lock), whole=False)


def pairs(items: list[str] | None, flag: str) -> dict[str, str] | None:
    """NAME=VALUE flags as a dict (a flag without '=' is refused)."""
    if not items:
        return None
    bad = [item for item in items if "=" not in item]
    if bad:
        raise KinelabError(f"{flag} takes NAME=VALUE, got {bad[0]!r}")
    return dict(item.split("=", 1) for item in items)


def _locked(items: list[str] | None) -> dict[str, float] | None:
    """--lock JOINT=VALUE flags as load()'s ``locked`` (rad or m)."""
    found = pairs(items, "--lock")
    if found is None:
        return None
    bad = [f"{name}={value}" for name, value in found.items() if not is_number(value)]
    if bad:
        raise KinelabError(f"--lock {bad[0]}: the value is not a number (rad or m)")
    return {name: float(value) for name, value in found.items()}


def robot_arguments(s: argparse.ArgumentParser, q_help: str | None = None, limits: bool = True) -> None:
    """The arguments every per-robot command shares: ROBOT [Q...] [--deg] [--tool ...] [--ignore-limits]."""
    s.add_argument("robot", help="registered name or model file (URDF, xacro, MJCF)")
    if q_help:
        s.add_argument("q", nargs="*", help=q_help + " (or the name of an SRDF configuration, with --srdf)")
        s.add_argument("--deg", action="store_true", help="angles of revolute/continuous joints in degrees")
    source_arguments(s)
    if limits:
        s.add_argument("--ignore-limits", action="store_true",
                       help="accept q outside the joint limits (fk and view compute any finite q and note the joints "
                            "outside; this flag drops the note)")


def source_arguments(s: argparse.ArgumentParser) -> None:
    """Where the chain starts and ends, and the files that describe the robot beyond its model file."""
    s.add_argument("--tool", help="tool frame (default: the robot's own)")
    s.add_argument("--base", help="frame the chain starts from (default: the URDF root); poses are in this frame")
    s.add_argument("--srdf", help="SRDF file: named configurations (give a name as Q) and groups")
    s.add_argument("--group", help="SRDF group whose chain gives base and tool")
    s.add_argument("--package-dir", action="append", help="where package:// meshes resolve (repeatable)")
    s.add_argument("--xacro-arg", action="append", metavar="NAME=VALUE", help="an argument of a .xacro robot")
    s.add_argument("--lock", action="append", metavar="JOINT=VALUE",
                   help="hold a joint at a value (rad or m) and leave it out of the chain (repeatable)")
    s.add_argument("--trust-xacro", action="store_true",
                   help="let a .xacro robot run what xacro runs ($(eval), $(env), load_yaml); refused without it")


def target_arguments(s: argparse.ArgumentParser) -> None:
    """``--target-q`` or ``--target-xyz`` with ``--target-rpy``: an IK target (``kinelab ik``, ``branches``)."""
    s.add_argument("--target-q", nargs="+", help="target as a configuration (its FK pose), or an SRDF name")
    s.add_argument("--target-xyz", nargs=3, type=float, help="target position [m] in the base frame")
    s.add_argument("--target-rpy", nargs=3, type=float,
                   help="target roll, pitch, yaw (rad; deg with --deg); without it the target rotation is the identity")


def collision_arguments(s: argparse.ArgumentParser) -> None:
    """--collisions, --obstacles FILE and --margin: what answers must not collide with."""
    s.add_argument("--collisions", action="store_true", help="the robot must not collide with itself")
    s.add_argument("--obstacles", metavar="FILE",
                   help="an obstacle file (JSON: planes, boxes, spheres, cylinders, capsules in the base frame); "
                        "implies --collisions")
    s.add_argument("--margin", type=float, default=0.0, help="clearance every pair must keep [m] (default 0)")


def collisions_of(args: argparse.Namespace) -> Any:
    """The :class:`kinelab.Collisions` the collision flags ask for, or None."""
    if not args.collisions and args.obstacles is None:
        if args.margin:
            raise KinelabError("--margin is a collision clearance: give --collisions or --obstacles FILE")
        return None

    env = None if args.obstacles is None else collision.Environment.from_file(args.obstacles)
    return collision.Collisions(environment=env, margin=args.margin)


def json_flag(s: argparse.ArgumentParser, what: str = "the result") -> None:
    """The --json flag of a command that prints results."""
    s.add_argument("--json", action="store_true", help=f"print {what} as JSON")


def verbose_flag(s: argparse.ArgumentParser) -> None:
    """--verbose: the solver's own terms (methods, monitor, completeness) beside the plain words."""
    s.add_argument("--verbose", action="store_true",
                   help="also print the solver's own terms: method, singularity monitor, how complete a set is "
                        "(docs/glossary.md)")


def seed_argument(s: argparse.ArgumentParser) -> None:
    """--seed, the same on every command."""
    s.add_argument("--seed", type=int, default=0, help="seed of the random starts or samples (an integer ≥ 0)")


def pose_dict(oMtool: pin.SE3) -> dict[str, Any]:
    """The JSON form of a pose: position [m], rotation matrix, quat_wxyz, rpy [rad]."""
    return {
        "position_m": oMtool.translation.tolist(),
        "rotation_matrix": oMtool.rotation.tolist(),
        "quat_wxyz": geometry.quat_wxyz_from_matrix(oMtool.rotation).tolist(),
        "rpy_rad": pin.rpy.matrixToRpy(oMtool.rotation).tolist(),
    }


def print_json(obj: object) -> None:
    """Print ``obj`` as indented JSON."""
    print(json.dumps(obj, indent=2))


def rounded(values: ArrayLike, digits: int) -> list[float]:
    """Rounded for printing, without the −0.0 that rounding a tiny negative number leaves."""
    out: list[float] = (np.round(np.asarray(values, dtype=float), digits) + 0.0).tolist()
    return out


def plural(count: int, word: str, plural_form: str | None = None) -> str:
    """"1 sample", "2 samples" (or the plural form given)."""
    return f"{count} {word}" if count == 1 else f"{count} {plural_form or word + 's'}"


def shown(values: ArrayLike, precision: int = 6, prefix: str = "") -> str:
    """Numbers as the CLI prints them: ``precision`` digits, rounding noise below 1e-12 as 0, no "-0", one line
    per row however many joints (``prefix``: the text before the array, for the rows after the first)."""
    clean = np.round(np.asarray(values, dtype=float), precision) + 0.0  # + 0.0 turns the −0 of rounding into 0
    return np.array2string(clean, precision=precision, suppress_small=True, max_line_width=10_000, prefix=prefix)


class Interrupted(KeyboardInterrupt):
    """Ctrl-C on a command that kept its work: ``note`` says what was kept and how to go on."""

    def __init__(self, note: str):
        super().__init__(note)
        self.note = note


def progress_of(args: argparse.Namespace) -> bool:
    """Whether a command shows its progress bars: not with --json, and only where someone watches (a terminal or
    Jupyter, :func:`kinelab.progress.interactive`): never bar frames in a log file."""
    return not getattr(args, "json", False) and progress.interactive()
