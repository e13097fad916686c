"""The collision goals' figures (#70): scenes where the tasks drive the robot through itself or an obstacle, stepped
with ``Limits(collisions=...)``, every monitored pair's distance checked by coal after every step; and converged
solves of targets taken from random collision-free configurations. Correctness counts (and the mean step time on
the machine it ran on, for scale; the side-by-side times are ``kinelab bench``'s). Run
``python tools/collision_goals.py [--steps N] [--solves N] [--scenes a,b]`` and read docs/collisions.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

import kinelab
from kinelab import Collisions, Environment, FrameTask, Limits, Obstacle, WholeBody
from kinelab.wholebody import clearance
from kinelab.wholebody.subject import as_robot

DT = 0.01
MARGIN = 0.01
PANDA_SCENE = Environment((Obstacle("box", (0.6, 0.6, 0.04), xyz=(0.5, 0.0, 0.2), name="table"),
                           Obstacle("capsule", (0.04, 0.5), xyz=(0.45, 0.3, 0.5), name="post")))


@dataclass(frozen=True)
class Scene:
    """A robot, its collisions, and the tasks at step k (targets that cross an obstacle or the robot itself)."""

    name: str
    robot: Callable[[], kinelab.Robot | kinelab.Chain]
    collisions: Collisions
    tasks: Callable[[kinelab.Robot, np.ndarray, int], list[FrameTask]]
    start: Callable[[kinelab.Robot], np.ndarray]


def swapped_hands(robot: kinelab.Robot, home: np.ndarray, k: int) -> list[FrameTask]:
    """Each hand sent to the other's start and back (a period of 8 s): the two cross."""
    left, right = robot.hands
    a, b = robot.frame_placement(home, left).translation, robot.frame_placement(home, right).translation
    s = 0.5 - 0.5 * np.cos(2 * np.pi * k * DT / 8.0)
    return [FrameTask(left, a + s * (b - a), task="position"), FrameTask(right, b + s * (a - b), task="position")]


def feet_held(robot: kinelab.Robot, home: np.ndarray) -> list[FrameTask]:
    return [FrameTask(foot, robot.frame_placement(home, foot)) for foot in robot.feet]


def through_the_torso(robot: kinelab.Robot, home: np.ndarray, k: int) -> list[FrameTask]:
    """TALOS: the feet held; the left hand to the right hand's start, the right hand into the torso's centre and
    back (8 s)."""
    torso = robot.frame_placement(home, "torso_2_link").translation
    s = 0.5 - 0.5 * np.cos(2 * np.pi * k * DT / 8.0)
    left, right = robot.hands
    start_r = robot.frame_placement(home, right).translation
    return [*feet_held(robot, home), swapped_hands(robot, home, k)[0],
            FrameTask(right, start_r + s * (torso - start_r), task="position")]


def arms_across(robot: kinelab.Robot, home: np.ndarray, k: int) -> list[FrameTask]:
    """G1: the feet held; both hands swung across the body in front of the chest, out of phase (6 s)."""
    chest = robot.frame_placement(home, "torso_link").translation + np.array([0.25, 0.0, 0.15])
    left, right = robot.hands
    phase = 2 * np.pi * k * DT / 6.0
    return [*feet_held(robot, home),
            FrameTask(left, chest + np.array([0.05 * np.sin(phase), -0.35 * np.sin(phase), 0.0]), task="position"),
            FrameTask(right, chest + np.array([-0.05 * np.sin(phase), 0.35 * np.sin(phase), 0.0]),
                      task="position")]


def table_and_post(robot: kinelab.Robot, home: np.ndarray, k: int) -> list[FrameTask]:
    """Panda: the hand sent 15 cm below the table top, then through the post, then back above (a new target every
    2 s, in a cycle of three)."""
    targets = (np.array([0.5, 0.0, 0.07]), np.array([0.45, 0.45, 0.5]), np.array([0.3, -0.2, 0.6]))
    return [FrameTask(robot.hands[0], targets[(k // 200) % 3], task="position")]


SCENES = {
    "baxter": Scene("baxter", lambda: kinelab.load("baxter"), Collisions(margin=MARGIN), swapped_hands,
                    lambda r: r.neutral()),
    "talos": Scene("talos", lambda: kinelab.load("talos"), Collisions(margin=MARGIN), through_the_torso,
                   lambda r: r.named_q("half_sitting")),
    "panda": Scene("panda", lambda: kinelab.load("panda"), Collisions(environment=PANDA_SCENE, margin=MARGIN),
                   table_and_post, lambda r: r.neutral()),
    "g1": Scene("g1", lambda: kinelab.load("g1"), Collisions(margin=MARGIN), arms_across, lambda r: r.standing()),
}


def monitored(found: clearance.StepCollisions, data: pin.Data, q: np.ndarray) -> float:
    """The least of every pair's distance less the margin at q (coal's, on every pair whose spheres — which hold
    its hulls — are nearer than the margin: the rest cannot be)."""
    pin.forwardKinematics(found.robot.model, data, q)
    near = found.near(data, found.spec.margin)
    if near.size == 0:
        return np.inf
    return min(r.min_distance for r in found.distances(data, near)) - found.spec.margin


def run_scene(scene: Scene, steps: int) -> str:
    """``steps`` steps of 10 ms with the file's velocity limits; the tasks' targets move every step."""
    subject = scene.robot()
    robot = as_robot(subject)
    found = clearance.step_collisions(robot, scene.collisions)
    data = robot.model.createData()
    home = scene.start(robot)
    problem = WholeBody(subject, scene.tasks(robot, home, 0), limits=Limits(collisions=scene.collisions))
    q, worst, unsolved, errors, spent = home.copy(), np.inf, 0, [], 0.0
    for k in range(steps):
        problem.retarget(scene.tasks(robot, home, k))
        t0 = time.perf_counter()
        result = problem.step(q, DT)
        spent += time.perf_counter() - t0
        unsolved += not result.solved
        q = result.q
        worst = min(worst, monitored(found, data, q))
        errors.append(max(e.position for e in result.errors))
    below = worst < -1e-4
    return (f"{scene.name}: {steps} steps, least distance less the margin {worst * 1e3:+.4f} mm "
            f"({'a penetration' if below else '0 penetrations'}), {unsolved} not solved, task error median "
            f"{np.median(errors) * 1e3:.1f} mm, p95 {np.percentile(errors, 95) * 1e3:.1f} mm; "
            f"{spent / steps * 1e3:.2f} ms a step; {found.summary}")


def solves(name: str, n: int, seed: int) -> str:
    """n converged solves of a hand's position, targets from random configurations clear of every pair."""
    scene = SCENES[name]
    subject = scene.robot()
    robot = as_robot(subject)
    found = clearance.step_collisions(robot, scene.collisions)
    data = robot.model.createData()
    rng = np.random.default_rng(seed)
    limits = Limits(collisions=scene.collisions)
    met = colliding = drawn = 0
    t0 = time.perf_counter()
    for k in range(n):
        while True:
            drawn += 1
            q = robot.random_q(rng)
            if monitored(found, data, q) >= 0.0:
                break
        target = robot.frame_placement(q, robot.hands[0]).translation
        res = kinelab.solve(subject, [FrameTask(robot.hands[0], target, task="position")], seed=k, limits=limits,
                            max_restarts=20, time_budget=None)
        met += res.success
        colliding += res.success and monitored(found, data, res.q) < 0.0
    return (f"{name} solves: {met}/{n} met ({100 * met / n:.2f} %), {colliding} colliding successes, "
            f"{n / drawn * 100:.0f} % of random configurations clear; "
            f"{(time.perf_counter() - t0) / n * 1e3:.1f} ms a solve on a shared machine")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--solves", type=int, default=10_000)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--solve-on", default="panda", help="the scenes whose robots' converged solves are counted")
    args = parser.parse_args()
    if args.steps > 0:
        for name in args.scenes.split(","):
            print(run_scene(SCENES[name], args.steps), flush=True)
    for name in args.solve_on.split(","):
        if args.solves > 0:
            print(solves(name, args.solves, 3), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
