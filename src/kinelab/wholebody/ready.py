"""The one-off work of an arm's first solve, done when it is loaded: :func:`load` is ``kinelab.load``.

A process's first :func:`kinelab.solve` used to pay for everything later calls reuse: importing the solvers'
modules (about 80 ms), classifying the chain, building the closed form's tables, compiling the engine, certifying
the compiled FK. :func:`ready` does that work for the calls a user's loop makes with the default settings —
``solve`` without a start and with one, ``solve_batch``, ``solve_all`` — by building their prepared solvers and
running each once on the tool pose of the middle of the limits, so the first call of each costs what later ones
cost (``kinelab bench --first-call``). What was readied, and the route each call takes, is kept on the robot
(:class:`Ready`, read by :func:`readied`) and said by ``kinelab info``.

Settings other than the defaults build their own prepared solver on their first call, as before. The robot layer's
own loader (:func:`kinelab.robot.load`, what the command line uses: a command solves once at most) readies nothing.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinelab.errors import OptionError
from kinelab.robot import loading
from kinelab.robot.chain import Chain

if TYPE_CHECKING:
    from kinelab.robot.closures import Closure

KEY = "ready"  # where the record lives on the robot (Chain.derived)


@dataclass(frozen=True)
class Ready:
    """What :func:`ready` prepared on one arm.

    Attributes:
        routes: (entry point, the route its default call takes), in call order.
        seconds: wall time of the preparation [s] (the modules' import included when it came first).
        refused: "" when every call was readied, else the error that stopped it (the first call then meets it).
    """

    routes: tuple[tuple[str, str], ...]
    seconds: float
    refused: str = ""


def load(name_or_path: str | Path, tool: str | None = None, locked: dict[str, float] | None = None,
         base: str | None = None, package_dirs: list[str] | None = None, srdf: str | Path | None = None,
         group: str | None = None, xacro_args: dict[str, str] | None = None, *,
         trust_xacro: bool = False, whole: bool | None = None, floating: bool | None = None,
         closures: Sequence[Closure] | str | Path | None = None, actuated: Sequence[str] | None = None,
         prepare: bool = True) -> Any:
    """``kinelab.load``: a robot as :func:`kinelab.robot.loading.load` builds it, an arm's default calls readied.

    Args:
        name_or_path: a registered name, a URDF, xacro or MJCF file, or "rd:NAME" (as
            :func:`kinelab.robot.loading.load`, whose arguments these all are).
        tool: the chain's tool frame.
        locked: joints held fixed, name → value [rad or m].
        base: the frame the chain starts from.
        package_dirs: where ``package://`` mesh URIs resolve.
        srdf: an SRDF file.
        group: an SRDF group giving base and tool.
        xacro_args: a ``.xacro`` source's arguments.
        trust_xacro: let a ``.xacro`` source run what xacro runs.
        whole: the whole robot (no chain cut); None: a registered robot's own choice.
        floating: the whole robot with a free-flyer at its root; None: the robot's own choice.
        closures: the loops the robot closes (a list of Closure or a declarations file).
        actuated: the joints a controller drives, with closures.
        prepare: True (the default): an arm's solvers readied here (:func:`ready`): their modules imported, the
            closed form's tables, the compiled engine and the FK certificate built for the default ``solve``,
            ``solve_batch`` and ``solve_all``, so that a process's first solve costs what later ones cost (the
            work moves here: about 0.1 s once per process, 2-30 ms per arm). False: built on the first call instead.
            A whole robot's step builds on its first call either way.

    Returns:
        A Chain (readied when ``prepare``), or the whole Robot.

    Raises:
        OptionError: ``prepare`` not a bool. Otherwise as :func:`kinelab.robot.loading.load`.
    """
    if not isinstance(prepare, bool):
        raise OptionError("prepare", prepare, "True or False")
    robot = loading.load(name_or_path, tool, locked, base, package_dirs, srdf, group, xacro_args,
                         trust_xacro=trust_xacro, whole=whole, floating=floating, closures=closures,
                         actuated=actuated)
    if prepare and isinstance(robot, Chain):
        ready(robot)
    return robot


def routes(robot: Chain) -> tuple[tuple[str, str], ...]:
    """The route each default call takes on this arm, without taking it: what ``solver="auto"`` picks
    (docs/route.md) for ``solve`` without and with a start and ``solve_batch`` ("analytic" or "frdm"), and how
    ``solve_all`` finds every branch ("closed form", "search", "elimination" or "multistart", its ``method``)."""
    from kinelab.ik import auto
    from kinelab.ik.analytic import classify, kernel

    def solver(start_given: bool) -> str:
        return auto.single(robot, auto.AUTO, "pose", None, False, start_given)

    arm = classify.classify(robot).arm
    if arm is not None and not auto.holds_a_joint(robot):
        every = "search" if kernel.SEARCH_6R <= arm.kind < kernel.GENERAL_6R else "closed form"
    else:
        every = "elimination" if classify.general_class(robot).arm is not None else "multistart"
    return (("solve", solver(False)), ("solve with q0", solver(True)),
            ("solve_batch", auto.resolved(robot, auto.AUTO, "pose", None, False)), ("solve_all", every))


def ready(robot: Chain) -> Ready:
    """Prepare ``robot``'s default calls (see the module's docstring) and keep the record on it.

    Returns:
        The :class:`Ready` record (also :func:`readied` afterwards).
    """
    t0 = time.perf_counter()
    taken: tuple[tuple[str, str], ...] = ()
    refused = ""
    try:
        taken = _warm(robot)
    except Exception as error:  # noqa: BLE001 - readying is a saving, never a failure of the load: the user's
        refused = f"{type(error).__name__}: {error}"  # own first call meets the same error, named there
    found = Ready(taken, time.perf_counter() - t0, refused)
    robot._derived[KEY] = found  # noqa: SLF001 - the record of work done, not derived on demand
    return found


def readied(robot: Chain) -> Ready | None:
    """What the load readied on ``robot`` (:class:`Ready`), or None where nothing was (``prepare=False``, the robot
    layer's own loader)."""
    found: Ready | None = robot.derived(KEY, _nothing)
    return found


def _nothing(_: Chain) -> None:
    return None


def _warm(robot: Chain) -> tuple[tuple[str, str], ...]:
    """Run each default call once on the tool pose at the middle of the limits (seeded: no entropy drawn); the
    routes they took, in :func:`routes`' words."""
    from kinelab.ik import api, auto
    from kinelab.wholebody import api as front  # kinelab.solve's module, imported here rather than on the first call

    lower, upper = robot.sample_bounds
    q_mid = 0.5 * (lower + upper)
    target = robot.fk(q_mid)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a short arm's note on a pose target is for the user's own call
        alone = front.solve(robot, target, seed=0)
        started = front.solve(robot, target, q0=q_mid, seed=0)
        batch = api.solve_batch(robot, [target], seed=0)
        every = routes(robot)[-1][1]
        if every == "multistart":  # a round of starts costs 10-100 ms: its solver built, not run
            api.all_solver(robot, auto.AUTO, 1e-6, 1e-6, api.AUTO_BUDGET, None, "pose", "z", None, {})
        else:  # microseconds: the default call itself, its one-call form built
            every = str(api.solve_all(robot, target, seed=0).method.value)
    return (("solve", alone.solver), ("solve with q0", started.solver),
            ("solve_batch", batch.mode.split(" ")[0].split("+")[0]), ("solve_all", every))
