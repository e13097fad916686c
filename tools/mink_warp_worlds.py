"""mink-warp's CPU backend on ``kinelab bench --worlds``'s problems, for the many-worlds comparison.

The same scenarios as :mod:`kinelab.report.bench.worlds` (the Panda's tool with a posture at 1,024 worlds; G1's hands,
feet, centre of mass and posture at 256), on MuJoCo's model of the same URDF (the whole-body bench's
``mujoco_spec``), each world's moving frames shifted by the same seeded offsets; mink-warp's ``ConstrainedSolver``
with its default hard limits (the joints' position limits), costs 1 (frames, centre of mass) and 1e-3 (posture),
``solve_and_integrate`` at dt = 5 ms on device "cpu". Rounds of 20 calls; steps per second = worlds × calls / the
round's wall time, after one call that compiles Warp's kernels (cached in Warp's own folder).

    pip install -e '.[bench]' mink-warp
    python tools/mink_warp_worlds.py [panda|g1 ...]
"""

from __future__ import annotations

import sys
import time

import numpy as np

from kinelab.report.bench.steppers import SCENARIOS, mujoco_spec, start_of, whole
from kinelab.report.bench.worlds import CALLS, DT, WORLDS


def _configuration(mw, model, robot, q0, n):  # noqa: ANN001, ANN202 - mink-warp's types, imported late
    """mink-warp's batched configuration at the bench's start (kinelab's q mapped by joint name)."""
    from kinelab.report.bench.steppers import Maps

    qpos = Maps(robot, model).to_mujoco(q0)
    return mw.Configuration(model, q=np.repeat(qpos[None], n, axis=0), nworld=n, device="cpu")


def measure(name: str, rounds: int = 3) -> list[float]:
    """Steps per second of each round on one scenario."""
    import mink_warp as mw

    scenario, robot = SCENARIOS[name], whole(SCENARIOS[name].robot)
    model, q0, n = mujoco_spec(robot).compile(), start_of(robot), WORLDS[name]
    cfg = _configuration(mw, model, robot, q0, n)
    rng = np.random.default_rng(0)
    tasks = []
    for k, frame in enumerate(scenario.moving + scenario.held):
        task = mw.FrameTask(frame, "body", position_cost=1.0, orientation_cost=1.0)
        pose = cfg.get_transform_frame_to_world(frame, "body").numpy().copy()  # (N, 7): w x y z, x y z
        if k < len(scenario.moving):
            pose[:, 4:] += rng.uniform(-0.05, 0.05, (n, 3))
        task.set_target(pose)
        tasks.append(task)
    if scenario.com:
        com = mw.ComTask(cost=1.0)
        com.set_target_from_configuration(cfg)
        tasks.append(com)
    posture = mw.PostureTask(model, cost=1e-3)
    posture.set_target_from_configuration(cfg)
    solver = mw.ConstrainedSolver(cfg, limits=None)
    solver.solve_and_integrate([*tasks, posture], DT)  # Warp compiles its kernels here
    rates = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        for _ in range(CALLS):
            solver.solve_and_integrate([*tasks, posture], DT)
        rates.append(CALLS * n / (time.perf_counter() - t0))
    return rates


if __name__ == "__main__":
    for name in sys.argv[1:] or list(WORLDS):
        found = measure(name)
        print(f"{name}: {WORLDS[name]} worlds, mink-warp cpu {np.median(found):,.0f} steps/s "
              f"({min(found):,.0f}–{max(found):,.0f})")
