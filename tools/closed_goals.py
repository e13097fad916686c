"""The closed-chain goals' figures (#69) on the bundled robots with loops: assemblies against the closed forms, the
loops held over a long run of steps, converged solves on reachable targets. Correctness counts, not times (those are
``kinelab bench``'s); run ``python tools/closed_goals.py [--quick]`` and read docs/closures.md for the last figures.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import pinocchio as pin

import kinelab
from kinelab import AssemblyError, FrameTask, Limits, WholeBody
from kinelab.report.bench import closed_step
from kinelab.report.closed_checks import CLOSED_FORMS, loops_of
from kinelab.robot.assembly import actuated_indices, passive_indices


def assemblies(robot: kinelab.Robot, n: int, seed: int) -> str:
    """n random motor configurations from the home pose: claimed and refused against the closed form."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    home = robot.standing()
    index = actuated_indices(robot)[0]
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


def tasks_at(robot: kinelab.Robot, q: np.ndarray) -> list[FrameTask]:
    """The goal's tasks with their targets where q puts them (the loop bench's: Cassie's two feet and pelvis as
    poses, another robot's first hand as a position)."""
    return [FrameTask(f, robot.frame_placement(q, f) if kind == "pose" else robot.frame_placement(q, f).translation,
                      task=kind) for f, kind in closed_step.frames(robot)]


def met(robot: kinelab.Robot, q: np.ndarray, tasks: list[FrameTask]) -> bool:
    """Every task within 1e-6 m / 1e-6 rad by Pinocchio's FK."""
    for task in tasks:
        reached = robot.frame_placement(q, task.frame)
        if task.task == "position":
            if np.linalg.norm(reached.translation - task.target.translation) > 1e-6:
                return False
        elif np.abs(pin.log6(task.target.actInv(reached)).vector).max() > 1e-6:
            return False
    return True


def draw(robot: kinelab.Robot, home: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
    """The motors drawn at random within their limits from ``home`` and assembled; None where none assembles."""
    index = actuated_indices(robot)[0]
    q = home.copy()
    q[index] = robot.random_q(rng)[index]
    try:
        return robot.assemble(q)
    except AssemblyError:
        return None


def held(robot: kinelab.Robot, steps: int, seed: int) -> str:
    """steps of 10 ms with the file's velocity limits toward targets that move every 200 steps; every 1,000 steps a
    start knocked off the loops (passive joints moved by up to 0.05 rad) to be brought back."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    home = robot.standing()
    passive = passive_indices(robot, robot.actuated)
    problem = WholeBody(robot, tasks_at(robot, home), limits=Limits())
    q, worst, unsolved, knocked = home, 0.0, 0, 0
    for k in range(steps):
        if k % 200 == 0:
            target = draw(robot, home, rng)
            if target is not None:
                for i, task in enumerate(tasks_at(robot, target)):
                    problem.set_target(i, task.target if task.task != "position" else task.target.translation)
        if k % 1000 == 500:
            knock = np.zeros(robot.nv)
            knock[passive] = rng.uniform(-0.05, 0.05, passive.size)
            q = robot.integrate(q, knock)
            knocked += 1
        result = problem.step(q, 0.01)
        unsolved += not result.solved
        q = result.q
        worst = max(worst, loops_of(robot, data, q))
    return f"held: {steps} steps, {knocked} starts knocked off, worst loop {worst:.2e}, {unsolved} not solved"


def solves(robot: kinelab.Robot, n: int, seed: int) -> str:
    """Converged solves of the goal's tasks from n random motor draws (each that assembles poses a reachable
    target), each re-judged."""
    rng = np.random.default_rng(seed)
    data = robot.model.createData()
    home = robot.standing()
    done = false = posed = 0
    times = []
    for k in range(n):
        pose = draw(robot, home, rng)
        if pose is None:
            continue  # no assembly at these motor angles: no target
        posed += 1
        tasks = tasks_at(robot, pose)
        t0 = time.perf_counter()
        res = kinelab.solve(robot, tasks, q0=home, seed=k)
        times.append(time.perf_counter() - t0)
        ok = met(robot, res.q, tasks) and loops_of(robot, data, res.q) <= 1e-10 and robot.within_limits(res.q)
        done += res.success
        false += res.success and not ok
    ms = np.array(times or [0.0]) * 1e3
    return (f"solves: {done}/{posed} reachable targets met ({n} motor draws), {false} false successes "
            f"(median {np.median(ms):.1f} ms, p95 {np.percentile(ms, 95):.1f} ms a solve on a shared machine)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="a tenth of every count")
    parser.add_argument("--robots", default="fourbar,delta,ankle", help="robots with loops (or cassie)")
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
