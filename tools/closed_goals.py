"""The closed-chain goals' figures (#69) on the bundled robots with loops: assemblies against the closed forms, the
loops held over a long run of steps, converged solves on reachable targets. Correctness counts, not times (those are
``kinelab bench``'s); run ``python tools/closed_goals.py [--quick]`` and read docs/closures.md for the last figures.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time

import numpy as np

import kinelab
from kinelab import AssemblyError, FrameTask, Limits, WholeBody
from kinelab.report.closed_checks import CLOSED_FORMS, loops_of


def assemblies(robot: kinelab.Robot, n: int, seed: int) -> str:
    """n random motor configurations from the home pose: claimed and refused against the closed form."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    home = robot.assemble(robot.neutral())
    index = [robot.model.joints[robot.model.getJointId(a)].idx_q for a in robot.actuated]
    claimed = wrong = disagree = 0
    for _ in range(n):
        q = home.copy()
        q[index] = robot.random_q(rng)[index]
        try:
            found: np.ndarray | None = robot.assemble(q)
        except AssemblyError:
            found = None
        claimed += found is not None
        wrong += found is not None and loops_of(robot, data, found) > 1e-10
        disagree += not CLOSED_FORMS[robot.name](robot, q[index], found)
    return f"assemblies: {claimed}/{n} claimed, {wrong} not closed to 1e-10, {disagree} against the closed form"


def held(robot: kinelab.Robot, steps: int, seed: int) -> str:
    """steps of 10 ms with the file's velocity limits toward targets that move every 200 steps; every 1,000 steps a
    start knocked off the loops (passive joints moved by up to 0.05 rad) to be brought back."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    hand, home = robot.hands[0], robot.assemble(robot.neutral())
    index = [robot.model.joints[robot.model.getJointId(a)].idx_q for a in robot.actuated]
    passive = np.setdiff1d(np.arange(robot.nq), index)
    problem = WholeBody(robot, [FrameTask(hand, robot.frame_placement(home, hand).translation, task="position")],
                        limits=Limits())
    q, worst, unsolved, knocked = home, 0.0, 0, 0
    for k in range(steps):
        if k % 200 == 0:
            target = home.copy()
            target[index] = robot.random_q(rng)[index]
            with contextlib.suppress(AssemblyError):
                problem.set_target(0, robot.frame_placement(robot.assemble(target), hand).translation)
        if k % 1000 == 500:
            q = q.copy()
            q[passive] += rng.uniform(-0.05, 0.05, passive.size)
            knocked += 1
        result = problem.step(q, 0.01)
        unsolved += not result.solved
        q = result.q
        worst = max(worst, loops_of(robot, data, q))
    return f"held: {steps} steps, {knocked} starts knocked off, worst loop {worst:.2e}, {unsolved} not solved"


def solves(robot: kinelab.Robot, n: int, seed: int) -> str:
    """Converged solves of the first hand's position from n random motor draws (each that assembles poses a
    reachable target), each re-judged."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    hand, home = robot.hands[0], robot.assemble(robot.neutral())
    index = [robot.model.joints[robot.model.getJointId(a)].idx_q for a in robot.actuated]
    met = false = posed = 0
    t0 = time.perf_counter()
    for k in range(n):
        q = home.copy()
        q[index] = robot.random_q(rng)[index]
        try:
            target = robot.frame_placement(robot.assemble(q), hand).translation
        except AssemblyError:
            continue  # no assembly at these motor angles: no target
        posed += 1
        res = kinelab.solve(robot, FrameTask(hand, target, task="position"), q0=home, seed=k)
        ok = (np.linalg.norm(robot.frame_placement(res.q, hand).translation - target) <= 1e-6
              and loops_of(robot, data, res.q) <= 1e-10 and robot.within_limits(res.q))
        met += res.success
        false += res.success and not ok
    return (f"solves: {met}/{posed} reachable targets met ({n} motor draws), {false} false successes "
            f"({(time.perf_counter() - t0) / max(posed, 1) * 1e3:.1f} ms a solve on a shared machine)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="a tenth of every count")
    parser.add_argument("--robots", default="fourbar,delta,ankle", help="robots with loops (default: the three)")
    parser.add_argument("--figures", default="assemblies,held,solves", help="which figures (default: all three)")
    args = parser.parse_args()
    scale = 10 if args.quick else 1
    for name in args.robots.split(","):
        robot = kinelab.load(name)
        for figure, count, seed in ((assemblies, 10_000, 1), (held, 100_000, 2), (solves, 10_000, 3)):
            if figure.__name__ not in args.figures.split(","):
                continue
            if figure is assemblies and name not in CLOSED_FORMS:
                print(f"{name}: assemblies: no closed form to hold them to (the loops' error is held below)")
                continue
            print(f"{name}: {figure(robot, count // scale, seed)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
