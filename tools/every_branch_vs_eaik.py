"""Every branch of a pose, kinelab against EAIK: ``python tools/every_branch_vs_eaik.py [ROBOT ...]``.

Needs the bench extra (``pip install -e '.[bench]'``, which brings EAIK). Two measures per arm, on poses made by the
FK of seeded random configurations:

- per pose: ``kinelab.solve_all(robot, pose)`` (every branch, each judged within the limits by the certified
  compiled FK, results built when read) against EAIK's fastest call on the same arm — ``DhRobot.IK`` where the arm
  has a standard DH model here (ur5, ur10), ``HPRobot.IK`` (EAIK's product-of-exponentials model, built from the
  same axes kinelab classifies) everywhere. EAIK gets its pose precomputed in its own frame and returns unchecked
  answers. 200 poses, 9 rounds alternating interleaved (both calls on each pose in turn) and blocked schedules.
- batch: ``kinelab.solve_all_batch`` (all cores, every branch judged) against EAIK's ``IK_batched`` on as many
  threads, 20,000 poses, 5 rounds.

Printed per arm: kinelab's median time, the peer's, and the ratio kinelab / peer as the median over rounds
[lowest–highest round]; for the batch, poses per second and the ratio peer-time / kinelab-time (above 1: kinelab
faster).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

import numpy as np

import kinelab
from kinelab.core import threads
from kinelab.ik.chain import chain_model

# standard DH parameters (d1, a2, a3, d4, d5, d6 [m]) of the UR arms in the example-robot-data files
UR_DH = {"ur5": (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
         "ur10": (0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922)}


def peers(robot: kinelab.Robot, Q: np.ndarray) -> tuple[dict[str, Callable[[int], object]], object, list]:
    """EAIK's calls on this arm (name → call on pose i), its HPRobot and its poses (EAIK's frame)."""
    from eaik.IK_DH import DhRobot
    from eaik.IK_HP import HPRobot

    v = chain_model(robot).vectors(np.zeros(robot.n))
    hp = HPRobot(v["e"], np.vstack([v["o"][0], np.diff(v["o"], axis=0), v["N"] - v["o"][-1]]))
    H = robot.fk_batch(Q)
    H[:, :3, :3] = H[:, :3, :3] @ v["R"].T  # EAIK's tool frame: the chain's at q = 0 is the identity
    poses = list(H)
    calls: dict[str, Callable[[int], object]] = {"EAIK HPRobot.IK": lambda i: hp.IK(poses[i])}
    if robot.name in UR_DH:
        d1, a2, a3, d4, d5, d6 = UR_DH[robot.name]
        dh = DhRobot(np.array([np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0]), np.array([0, a2, a3, 0, 0, 0]),
                     np.array([d1, 0, 0, d4, d5, d6]))
        dh_poses = [dh.fwdKin(q) for q in Q]
        calls["EAIK DhRobot.IK"] = lambda i: dh.IK(dh_poses[i])
    return calls, hp, poses


def per_pose(robot: kinelab.Robot, count: int = 200, rounds: int = 9) -> str:
    """The per-pose line of one arm."""
    Q = robot.random_qs(count, np.random.default_rng(0))
    targets = [robot.fk(q) for q in Q]
    calls, _, _ = peers(robot, Q)
    calls = {"kinelab.solve_all": lambda i: kinelab.solve_all(robot, targets[i]), **calls}
    for call in calls.values():
        for i in range(20):
            call(i)
    times: dict[str, list[float]] = {k: [] for k in calls}
    for r in range(rounds):
        spent = dict.fromkeys(calls, 0.0)
        if r % 2 == 0:  # interleaved: both calls on each pose in turn
            for i in range(count):
                for name, call in calls.items():
                    t0 = time.perf_counter()
                    call(i)
                    spent[name] += time.perf_counter() - t0
        else:  # blocked: each call over every pose
            for name, call in calls.items():
                t0 = time.perf_counter()
                for i in range(count):
                    call(i)
                spent[name] = time.perf_counter() - t0
        for name in calls:
            times[name].append(spent[name] / count * 1e6)
    mine = np.array(times["kinelab.solve_all"])
    out = [f"{robot.name}: kinelab.solve_all {np.median(mine):.1f} µs"]
    for name in list(calls)[1:]:
        ratio = mine / np.array(times[name])
        out.append(f"{name} {np.median(times[name]):.1f} µs, ratio {np.median(ratio):.2f} "
                   f"[{ratio.min():.2f}–{ratio.max():.2f}]")
    return "; ".join(out)


def batch(robot: kinelab.Robot, count: int = 20_000, rounds: int = 5) -> str:
    """The batch line of one arm."""
    Q = robot.random_qs(count, np.random.default_rng(1))
    H = robot.fk_batch(Q)
    _, hp, poses = peers(robot, Q)
    kinelab.solve_all_batch(robot, H[:10])
    mine, theirs = [], []
    for _ in range(rounds):
        t0 = time.perf_counter()
        kinelab.solve_all_batch(robot, H)
        mine.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        hp.IK_batched(poses, threads.count())
        theirs.append(time.perf_counter() - t0)
    ratio = np.array(theirs) / np.array(mine)
    return (f"{robot.name}: solve_all_batch {count / np.median(mine) / 1e3:.0f}k poses/s, EAIK IK_batched "
            f"({threads.count()} threads) {count / np.median(theirs) / 1e3:.0f}k/s, speed ratio "
            f"{np.median(ratio):.2f} [{ratio.min():.2f}–{ratio.max():.2f}]")


def main() -> int:
    names = sys.argv[1:] or ["ur5", "ur10", "kinova"]
    for name in names:
        robot = kinelab.load(name)
        print(per_pose(robot), flush=True)
        print(batch(robot), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
