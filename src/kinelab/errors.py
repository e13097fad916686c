"""kinelab's exceptions: one base class, narrow subclasses that carry what went wrong and what is valid."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping


class KinelabError(Exception):
    """Base class of every error kinelab raises on bad input or an impossible request."""


def did_you_mean(name: str, valid: Iterable[str], words: Mapping[str, str] | None = None) -> str:
    """" (did you mean 'x'?)" for the valid name closest to ``name`` — the same letters in another case, a close
    spelling, or a name whose description holds ``name`` as a word (``words``: word → name) — else "".

    Args:
        name: what the user gave.
        valid: the valid names.
        words: lower-case words that stand for a valid name (a robot's maker, say).

    Returns:
        The suggestion, with a leading space, or "".
    """
    names = list(valid)
    folded = {n.lower(): n for n in names}
    key = str(name).strip().lower()
    found = folded.get(key) or (words or {}).get(key)
    if found is None:
        close = difflib.get_close_matches(key, list(folded), n=1, cutoff=0.75)
        found = folded[close[0]] if close else None
    return f" (did you mean {found!r}?)" if found is not None and found != name else ""


def count_of(shape: tuple[int, ...]) -> str:
    """What an array of ``shape`` holds, in words for an error message: "none", "3 numbers", "an array of shape
    (2, 3)"."""
    if len(shape) == 1:
        return "none" if shape[0] == 0 else "1 number" if shape[0] == 1 else f"{shape[0]} numbers"
    return "one number" if shape == () else f"an array of shape {shape}"


def _listing(options: Iterable[str], most: int = 40) -> str:
    names = list(options)
    shown = ", ".join(names[:most])
    return shown + (f", ... ({len(names)} in all)" if len(names) > most else "")


class RobotNotFoundError(KinelabError):
    """A robot name that is neither registered nor an existing URDF file."""

    def __init__(self, name: str, valid: Iterable[str], words: Mapping[str, str] | None = None):
        self.name = name
        self.valid = list(valid)
        super().__init__(
            f"unknown robot {name!r}{did_you_mean(name, self.valid, words)}: not a registered name and no such "
            f"file; registered robots are: {_listing(self.valid)}"
        )


class DescriptionError(KinelabError):
    """An ``rd:NAME`` source that cannot be opened: robot_descriptions missing, an unknown name, or a
    description whose repository is not in robot_descriptions' cache."""


class URDFError(KinelabError):
    """A URDF that cannot be read: missing, malformed, or not describing a usable chain."""


class SRDFError(KinelabError):
    """An SRDF file that cannot be read, or that names joints, links or groups the robot does not have."""


class ChainError(KinelabError):
    """The base-to-tool path is not a serial chain kinelab can use (ambiguous tool, loop, joint type)."""


class FrameNotFoundError(KinelabError):
    """A frame name that the robot does not have."""

    def __init__(self, name: str, valid: Iterable[str], robot: str = ""):
        self.name = name
        self.valid = list(valid)
        where = f" in robot {robot!r}" if robot else ""
        super().__init__(f"unknown frame {name!r}{where}{did_you_mean(name, self.valid)}; frames are: "
                         f"{_listing(self.valid, 60)}")


class JointNotFoundError(KinelabError):
    """A joint name that is not one of the robot's chain joints."""

    def __init__(self, name: str, valid: Iterable[str]):
        self.name = name
        self.valid = list(valid)
        super().__init__(f"unknown joint {name!r}{did_you_mean(name, self.valid)}; joints are: "
                         f"{_listing(self.valid)}")


class ConfigurationError(KinelabError):
    """A joint vector of the wrong shape or with non-finite entries."""


class JointLimitError(ConfigurationError):
    """A joint value outside its limits, where the limits matter."""

    def __init__(self, joint: str, value: float, lower: float, upper: float, unit: str = ""):
        self.joint, self.value, self.lower, self.upper = joint, value, lower, upper
        u = f" {unit}" if unit else ""
        super().__init__(
            f"joint {joint!r} = {value:.6g}{u} is outside its limits [{lower:.6g}, {upper:.6g}]{u}"
        )


class TargetError(KinelabError):
    """A target that is not a valid pose (shape, NaN/inf, not a rotation, not a unit quaternion)."""


class AssemblyError(KinelabError):
    """No configuration of a robot's passive joints closes every loop with its actuated joints held (within the
    limits); ``residual`` is the smallest closure error reached [m, rad]."""

    def __init__(self, message: str, residual: float):
        self.residual = residual
        super().__init__(message)


class BiquaternionError(KinelabError):
    """A biquaternion that is not what an operation needs (non-finite, not unit, wrong shape)."""


class OptionError(KinelabError):
    """A solver or command option with a value outside what it accepts; names the option and the valid values."""

    def __init__(self, option: str, value: object, valid: str, message: str | None = None):
        self.option, self.value, self.valid = option, value, valid
        super().__init__(message or f"option {option}={value!r} is not valid: {valid}")


class SolverNotFoundError(KinelabError):
    """A solver name that is not registered."""

    def __init__(self, name: str, valid: Iterable[str], why: str = ""):
        self.name = name
        self.valid = sorted(valid)
        if why:  # a known solver this entry point cannot run
            super().__init__(f"solver {name!r} {why}; solvers here are: {', '.join(self.valid)}")
        else:
            super().__init__(f"unknown solver {name!r}{did_you_mean(name, self.valid)}; solvers are: "
                             f"{', '.join(self.valid)}")
