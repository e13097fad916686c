"""The 1-D search on poses at the edge of a singular surface: ``python tools/search_hard_poses.py [ROBOT ...]``.

For each arm (default xarm6 and crx10ia), random configurations are moved along joint 2, 3 or 5 onto a zero of
det J (bisection on a sign change of det J over the joint's range, to rounding) and then off it by a uniform
amount of at most 1e-7 rad; those within the limits are solved by ``kinelab.solve_all``. Printed per arm: the
poses tried and how many have their own configuration farther than 1e-6, 1e-4 and 1e-3 rad (each joint modulo
2π, the largest difference) from every answer, and the five farthest with their configurations. Seeded: the
same poses on every run.
"""

from __future__ import annotations

import sys

import numpy as np

import kinelab
from kinelab.ik.limits import distance

PER_JOINT = 150  # configurations moved onto a singular surface, per joint


def on_a_singular_surface(robot: kinelab.Robot, q: np.ndarray, joint: int,
                          rng: np.random.Generator) -> np.ndarray | None:
    """q with ``joint`` moved onto a zero of det J (then off it by at most 1e-7 rad), or None when det J keeps its
    sign along that joint."""
    values = np.linspace(robot.lower[joint], robot.upper[joint], 721)

    def det(x: float) -> float:
        moved = q.copy()
        moved[joint] = x
        return float(np.linalg.det(robot.jacobian_world(moved)))

    dets = np.array([det(x) for x in values])
    changes = np.flatnonzero(np.sign(dets[:-1]) != np.sign(dets[1:]))
    if changes.size == 0:
        return None
    k = rng.choice(changes)
    a, b, fa = values[k], values[k + 1], dets[k]
    for _ in range(60):
        mid = 0.5 * (a + b)
        fm = det(mid)
        a, b, fa = (mid, b, fm) if np.sign(fm) == np.sign(fa) else (a, mid, fa)
    out = q.copy()
    out[joint] = 0.5 * (a + b) + rng.uniform(-1e-7, 1e-7)
    return out


def main() -> int:
    for name in sys.argv[1:] or ["xarm6", "crx10ia"]:
        robot, rng = kinelab.load(name), np.random.default_rng(7)
        far: list[tuple[float, int, list[float]]] = []
        tried = 0
        for joint in (1, 2, 4):
            for _ in range(PER_JOINT):
                q = on_a_singular_surface(robot, robot.random_q(rng), joint, rng)
                if q is None or not robot.within_limits(q):
                    continue
                tried += 1
                found = kinelab.solve_all(robot, robot.fk(q))
                d = min((distance(robot, x, q) for x in found.q), default=np.inf)
                far.append((d, joint + 1, np.round(q, 6).tolist()))
        d = np.array([f[0] for f in far])
        print(f"{name}: {tried} poses; own configuration farther than 1e-6 rad: {int((d > 1e-6).sum())}, "
              f"1e-4: {int((d > 1e-4).sum())}, 1e-3: {int((d > 1e-3).sum())}")
        for dist, joint, q in sorted(far)[-5:]:
            print(f"  {dist:.3g} rad (singular along joint {joint}) q = {q}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
