"""A cheap, certain test that a target position is out of reach."""

from __future__ import annotations

import math

import numpy as np

from kinelab.robot import Robot


def _reach(robot: Robot) -> tuple[tuple[float, float, float], float]:
    q = robot.neutral()
    oMi = list(robot.joint_placements(q).values())
    anchor = robot.model.jointPlacements[1].translation  # where joint 1 sits, fixed in the base
    points = [anchor] + [m.translation for m in oMi] + [robot.fk(q).translation]
    # each distance between consecutive points is rigid, except along a prismatic joint's slide
    rigid = sum(float(np.linalg.norm(b - a)) for a, b in zip(points, points[1:], strict=False))
    slides = sum(
        max(abs(j.upper - q[i]), abs(j.lower - q[i])) for i, j in enumerate(robot.joints) if j.kind == "prismatic"
    )
    return tuple(np.asarray(anchor, dtype=float).tolist()), rigid + slides


def reach_bound(robot: Robot) -> tuple[tuple[float, float, float], float]:
    """(anchor [m], radius [m]): every reachable tool position lies within the radius of the anchor."""
    return robot.derived("reach_bound", _reach)


def out_of_reach(robot: Robot, position: np.ndarray) -> float:
    """How far [m] a position lies beyond the reach bound (≤ 0 when it may be reachable)."""
    anchor, radius = robot.derived("reach_bound", _reach)
    return math.dist(np.asarray(position, dtype=float).tolist(), anchor) - radius


def beyond_reach(robot: Robot, position: np.ndarray) -> str:
    """Why no configuration can reach ``position`` [m] (base frame) when it lies beyond the reach bound, in words;
    "" when it may be reachable."""
    beyond = out_of_reach(robot, position)
    return f"the target point is at least {beyond:.4g} m beyond the robot's reach" if beyond > 0 else ""
