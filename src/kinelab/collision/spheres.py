"""The sphere test (compiled: :mod:`kinelab.core._spheres`): the joint frames at q from the model's placements
and axes, each object's sphere centre carried by its joint, and the pairs whose spheres are not farther apart
than the margin.

A plane obstacle's test is the sphere's height above it. The frames follow Pinocchio's model (a joint's frame
is its parent's, times its placement, times its motion); the test is conservative by construction and is
held against Pinocchio's exact test in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinelab.core._spheres import candidates as candidates

PLANE = -1.0  # radius marker of a plane obstacle
PRISMATIC = 1


@dataclass(frozen=True, eq=False)
class Frames:
    """What the compiled test needs of the model: per joint (index 0 the universe) its parent, placement,
    axis, kind (0 rotary, 1 prismatic) and the index of its value in kinelab's q."""

    parents: np.ndarray
    place_R: np.ndarray
    place_t: np.ndarray
    axis: np.ndarray
    kind: np.ndarray
    q_index: np.ndarray
