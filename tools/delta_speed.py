"""#69 goal 4, the delta's half: the general route's converged solve of the platform's position against the delta's
closed-form inverse kinematics (Clavel's: each motor angle from one leg's sphere, a cos t + b sin t = c), on the
same random reachable targets, interleaved per target. Both answers are judged by Pinocchio's FK of the assembled
configuration. Run ``python tools/delta_speed.py [--n 300]``; the figures go in the note and docs/closures.md.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import kinelab
from kinelab import AssemblyError, FrameTask
from kinelab.robot.assembly import actuated_indices

R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04  # base radius, upper arm, forearm, platform radius [m] (urdf/delta.urdf)
PHI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)
LOWER, UPPER = -0.6, 1.4  # the motors' limits [rad] (urdf/delta.urdf)


def closed_form(P: np.ndarray) -> np.ndarray | None:
    """The three motor angles [rad] (0: arm horizontal, positive: down) that put the platform centre at P [m], the
    elbows out; None where a leg cannot reach."""
    theta = np.empty(3)
    for i, phi in enumerate(PHI):
        c, s = np.cos(phi), np.sin(phi)
        x, y, z = c * P[0] + s * P[1] + RP - R, -s * P[0] + c * P[1], P[2]
        a, b = -2 * LA * x, 2 * LA * z
        rhs = LB**2 - x * x - y * y - z * z - LA**2
        r = np.hypot(a, b)
        if r == 0 or abs(rhs) > r:
            return None
        base, spread = np.arctan2(b, a), np.arccos(rhs / r)
        roots = [(t + np.pi) % (2 * np.pi) - np.pi for t in (base - spread, base + spread)]
        inside = [t for t in roots if LOWER <= t <= UPPER]  # the elbow-out root: the one within the motor's limits
        if not inside:
            return None
        theta[i] = inside[0]
    return theta


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=300)
    args = parser.parse_args()
    robot = kinelab.load("delta")
    hand, home = robot.hands[0], robot.standing()
    index = actuated_indices(robot)[0]
    rng = np.random.default_rng(5)
    general, formula, met_general, met_formula = [], [], 0, 0
    while len(general) < args.n:
        q = home.copy()
        q[index] = robot.random_q(rng)[index]
        try:
            target = robot.frame_placement(robot.assemble(q), hand).translation
        except AssemblyError:
            continue
        t0 = time.perf_counter()
        res = kinelab.solve(robot, FrameTask(hand, target, task="position"), q0=home, seed=len(general))
        general.append(time.perf_counter() - t0)
        met_general += res.success
        t0 = time.perf_counter()
        theta = closed_form(target)
        formula.append(time.perf_counter() - t0)
        if theta is not None:
            q = home.copy()
            q[index] = theta
            with np.errstate(all="ignore"):
                try:
                    placed = robot.frame_placement(robot.assemble(q), hand).translation
                    met_formula += bool(np.linalg.norm(placed - target) <= 1e-6)
                except AssemblyError:
                    pass
    g, f = np.median(general), np.median(formula)
    print(f"delta, {args.n} targets: general route (kinelab.solve, FrameTask position, loops held) median "
          f"{g * 1e3:.2f} ms, {met_general}/{args.n} met; closed form (NumPy, per target) median {f * 1e6:.1f} µs, "
          f"{met_formula}/{args.n} met when assembled; ratio {g / f:.0f}×")
    return 0


if __name__ == "__main__":
    sys.exit(main())
