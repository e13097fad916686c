"""``kinelab teach``: move a robot by hand in the browser — a slider per joint, a target to drag that the robot
follows by IK, its branches, collisions, and the tool pose, σ_min, manipulability and velocity ellipsoid read live;
for a whole robot, a target per hand, its feet and centre of mass held (:mod:`kinelab.view.teach.whole`).

The page is served on 127.0.0.1 only; in a notebook, :func:`teach` shows it in the cell.
"""

from __future__ import annotations

from kinelab.errors import OptionError
from kinelab.robot import Chain
from kinelab.robot.tree import Robot
from kinelab.typing import Configuration
from kinelab.view.teach.server import TeachServer
from kinelab.view.teach.session import TeachOptions, TeachSession
from kinelab.view.teach.whole import WholeTeachSession


class Teach:
    """A teach page for one robot, served in the background (a notebook's or a script's way).

    ``teach.url`` is the page; in a notebook the object shows the page in the cell; ``teach.session`` moves the
    robot from Python (``session.set_q``, ``session.set_target``; the page follows within half a second);
    ``teach.close()`` stops the server.
    """

    def __init__(self, robot: Chain | Robot, q: Configuration | None = None, options: TeachOptions | None = None,
                 port: int = 0,
                 hands: tuple[str, ...] | None = None, feet: tuple[str, ...] | None = None):
        self.session: TeachSession | WholeTeachSession
        if isinstance(robot, Robot):
            self.session = WholeTeachSession(robot, q, options, hands, feet)
        else:
            if hands is not None or feet is not None:
                raise OptionError("hands", hands, "None for a chain (its target is its tool's)")
            self.session = TeachSession(robot, q, options)
        self.server = TeachServer(self.session, port).start()

    @property
    def url(self) -> str:
        """The page's address (127.0.0.1)."""
        return self.server.url

    def close(self) -> None:
        """Stop the server (idempotent)."""
        self.server.close()

    def _repr_html_(self) -> str:
        return (f'<div><iframe src="{self.url}" style="width:100%;height:640px;border:0"></iframe>'
                f'<div style="font-size:12px">kinelab teach: {self.url} (served by this kernel)</div></div>')

    def __enter__(self) -> Teach:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def teach(robot: Chain | Robot, q: Configuration | None = None, options: TeachOptions | None = None, port: int = 0,
          hands: tuple[str, ...] | None = None, feet: tuple[str, ...] | None = None) -> Teach:
    """Serve a teach page for ``robot`` on 127.0.0.1 in the background and return it (shown in a notebook cell).

    Args:
        robot: a chain or a whole robot (:func:`kinelab.load`).
        q: the start [rad or m], within the limits (default: the robot's reference configuration; a whole
            robot's SRDF "half_sitting", its feet on the floor).
        options: how the target is followed (:class:`TeachOptions`).
        port: the port (0: a free one).
        hands: a whole robot's frames to drag (default: its registered hands).
        feet: a whole robot's frames held where they stand (default: its registered feet).

    Returns:
        The :class:`Teach` page (``url``, ``session``, ``close``).

    Raises:
        ConfigurationError: q of the wrong length, not finite or outside the limits.
        KinelabError: the port is taken.
    """
    return Teach(robot, q, options, port, hands, feet)


__all__ = ["Teach", "TeachOptions", "TeachServer", "TeachSession", "WholeTeachSession", "teach"]
