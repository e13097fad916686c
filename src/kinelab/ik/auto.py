"""``solver="auto"`` where one answer is asked for (``solve``, ``solve_batch``, ``IK``): the fastest route with the
same guarantees — every answer judged within the limits by the certified FK, the branch nearest the start when a
start is given.

A chain in a closed-form class (docs/analytic.md) answers a pose in closed form, a 7R arm whose six are in one
with its end joint held at the start's value; both are 2–7× FRDM's batch throughput on the registered arms
(``kinelab bench``). Everywhere else FRDM answers: another task, a collision check, solver options, a chain whose
class is a 1-D search (the CRX-10iA's: 3k targets/s against FRDM's 45k; Baxter's six with a joint held), or the
general elimination. docs/route.md has the table of every registered arm. (``solve_all``'s "auto" chooses among every
branch: :mod:`kinelab.ik.registry`.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from kinelab import lazy
from kinelab.robot.chain import Chain
from kinelab.typing import CollisionSpec

if TYPE_CHECKING:
    from kinelab.ik import registry
    from kinelab.ik.analytic import classify as classify_module
    from kinelab.ik.analytic import held, kernel
else:
    registry = lazy.module("kinelab.ik.registry", globals())
    classify_module = lazy.module("kinelab.ik.analytic.classify", globals())
    held = lazy.module("kinelab.ik.analytic.held", globals())
    kernel = lazy.module("kinelab.ik.analytic.kernel", globals())

AUTO = "auto"


def resolved(robot: Chain, solver: str, task: str, collisions: CollisionSpec, has_options: bool) -> str:
    """The solver ``solver`` stands for on this robot: itself, unless it is "auto" (see the module's docstring)."""
    if solver != AUTO:
        return solver
    if task != "pose" or collisions is not None or has_options:
        return "frdm"
    return "analytic" if closed_form_serves(robot) else "frdm"


def single(robot: Chain, solver: str, task: str, collisions: CollisionSpec, has_options: bool,
           start_given: bool) -> str:
    """The solver a single call (``solve``) takes for ``solver``: what :func:`resolved` says, except "auto" on a 7R
    arm without a start — its held joint's closed form serves a batch and a start's nearest branch, but from no
    start it searches the held joint for a branch within the limits, about 20× FRDM's one compiled call
    (docs/route.md): FRDM answers."""
    route = resolved(robot, solver, task, collisions, has_options)
    kind = registry.capabilities(solver)
    if kind.picks and registry.capabilities(route).closed_form and not start_given \
            and holds_a_joint(robot):
        return kind.request_solver(solver)  # what the picking solver runs: FRDM
    return route


def holds_a_joint(robot: Chain) -> bool:
    """True for a 7R arm whose six are in closed form with an end joint held (kept on the robot)."""
    return bool(robot.derived("auto: held", held.applies))


def closed_form_serves(robot: Chain) -> bool:
    """True when the chain's closed form (or its held-joint form) answers a pose."""
    def closed(r: Chain) -> bool:
        arm = classify_module.classify(r).arm
        return arm is not None and arm.kind < kernel.SEARCH_6R

    def serves(r: Chain) -> bool:
        return closed(r) or (held.applies(r) and closed(held.held_robot(r)))

    return robot.derived("auto: closed form serves", serves)
