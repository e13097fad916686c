"""The sphere test, compiled: the joint frames at q from the model's placements and axes, each object's
sphere centre carried by its joint, and the pairs whose spheres are not farther apart than the margin.

A plane obstacle's test is the sphere's height above it. The frames follow Pinocchio's model (a joint's frame
is its parent's, times its placement, times its motion); the test is conservative by construction and is
held against Pinocchio's exact test in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

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


@njit(cache=True, inline="always")
def _rot(k, angle, out):
    c, s = np.cos(angle), np.sin(angle)
    C = 1.0 - c
    x, y, z = k[0], k[1], k[2]
    out[0, 0], out[0, 1], out[0, 2] = c + x * x * C, x * y * C - z * s, x * z * C + y * s
    out[1, 0], out[1, 1], out[1, 2] = y * x * C + z * s, c + y * y * C, y * z * C - x * s
    out[2, 0], out[2, 1], out[2, 2] = z * x * C - y * s, z * y * C + x * s, c + z * z * C


@njit(cache=True)
def joint_frames(q, parents, place_R, place_t, axis, kind, q_index, R, t):
    """Every joint's frame in the base frame at q: R (J, 3, 3), t (J, 3) written (joint 0: identity)."""
    local = np.empty((3, 3))
    motion = np.empty((3, 3))
    R[0] = np.eye(3)
    t[0] = 0.0
    for j in range(1, parents.shape[0]):
        p = parents[j]
        v = q[q_index[j]]
        lt = place_t[j].copy()
        if kind[j] == PRISMATIC:
            for a in range(3):
                lt[a] += (place_R[j, a, 0] * axis[j, 0] + place_R[j, a, 1] * axis[j, 1]
                          + place_R[j, a, 2] * axis[j, 2]) * v
            local[:] = place_R[j]
        else:
            _rot(axis[j], v, motion)
            for a in range(3):
                for b in range(3):
                    local[a, b] = place_R[j, a, 0] * motion[0, b] + place_R[j, a, 1] * motion[1, b] \
                        + place_R[j, a, 2] * motion[2, b]
        for a in range(3):
            t[j, a] = t[p, a] + R[p, a, 0] * lt[0] + R[p, a, 1] * lt[1] + R[p, a, 2] * lt[2]
            for b in range(3):
                R[j, a, b] = R[p, a, 0] * local[0, b] + R[p, a, 1] * local[1, b] + R[p, a, 2] * local[2, b]


@njit(cache=True)
def candidates(q, parents, place_R, place_t, axis, kind, q_index, joints, centres, radii, normals, pairs, margin,
               out):
    """The indices of the pairs whose spheres the test cannot separate, written into ``out``; returns their
    count."""
    J = parents.shape[0]
    R, t = np.empty((J, 3, 3)), np.empty((J, 3))
    joint_frames(q, parents, place_R, place_t, axis, kind, q_index, R, t)
    G = joints.shape[0]
    world = np.empty((G, 3))
    for g in range(G):
        j = joints[g]
        for a in range(3):
            world[g, a] = t[j, a] + R[j, a, 0] * centres[g, 0] + R[j, a, 1] * centres[g, 1] + R[j, a, 2] * centres[g, 2]
    count = 0
    for k in range(pairs.shape[0]):
        a, b = pairs[k, 0], pairs[k, 1]
        dx, dy, dz = world[a, 0] - world[b, 0], world[a, 1] - world[b, 1], world[a, 2] - world[b, 2]
        if radii[b] == PLANE:
            gap = dx * normals[b, 0] + dy * normals[b, 1] + dz * normals[b, 2] - radii[a]
        else:
            gap = np.sqrt(dx * dx + dy * dy + dz * dz) - radii[a] - radii[b]
        if gap <= margin:
            out[count] = k
            count += 1
    return count
