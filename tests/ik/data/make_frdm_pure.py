"""Record the answers of the paper's FRDM (kinelab 0.2, before the Newton finish) that the pure-FRDM option
must keep bit for bit: ``python tests/ik/data/make_frdm_pure.py`` wrote frdm_pure.npz with the code of the commit
that added both files, before the Newton finish existed. Not to be rerun since: the file pins what that code
computed (the test calls :func:`answers` with ``finish="none"``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import kinelab

ROBOTS = ("ur5", "panda", "stanford", "era")


def cases(robot: kinelab.Robot) -> tuple[list, np.ndarray]:
    """Six seeded targets and warm starts (σ = 0.2 rad) per robot."""
    rng = np.random.default_rng(7)
    qs = [robot.random_q(rng) for _ in range(6)]
    starts = np.array([np.clip(q + rng.normal(0, 0.2, q.size), robot.lower, robot.upper) for q in qs])
    return [robot.fk(q) for q in qs], starts


def path_targets(robot: kinelab.Robot, starts: np.ndarray) -> list:
    """The tracked path's 40 targets: FK along the straight joint-space segment between the first two starts."""
    return [robot.fk(starts[0] + s * (starts[1] - starts[0])) for s in np.linspace(0, 1, 40)]


def answers(finish: dict) -> dict[str, np.ndarray]:
    """Each path's answers: compiled single solves (warm and random starts), the monitored loop, a batch,
    a tracked path."""
    out: dict[str, np.ndarray] = {}
    for name in ROBOTS:
        robot = kinelab.load(name)
        targets, starts = cases(robot)
        opts = dict(time_budget=None, **finish)
        out[f"{name}/warm"] = np.array([kinelab.solve(robot, t, q0=q, seed=3, **opts).q
                                        for t, q in zip(targets, starts, strict=True)])
        out[f"{name}/random"] = np.array([kinelab.solve(robot, t, seed=k, **opts).q for k, t in enumerate(targets)])
        out[f"{name}/monitored"] = np.array([kinelab.solve(robot, t, q0=q, seed=3, policy=("auto_kick",), **opts).q
                                             for t, q in zip(targets, starts, strict=True)])
        out[f"{name}/batch"] = kinelab.solve_batch(robot, targets, q0=starts, seed=5, **opts).q
        path = path_targets(robot, starts)
        out[f"{name}/track"] = kinelab.track(robot, path, q0=starts[0], **finish).q
    return out


if __name__ == "__main__":
    np.savez_compressed(Path(__file__).with_name("frdm_pure.npz"), **answers({}))
