"""The voxel grid of a reachability map and the target orientations in each voxel.

Orientations are spread over SO(3) by a super-Fibonacci spiral (Alexa, CVPR 2022): unit quaternions
whose angles advance by irrational fractions of a turn, so that any count covers the rotations evenly
without a random draw. Tool-axis directions (task "axis") use the Fibonacci sphere. Units: metres, base
frame.
"""

from __future__ import annotations

import numpy as np

from kinelab.errors import KinelabError
from kinelab.ik.targets import reach_bound
from kinelab.robot import Chain
from kinelab.values import is_real

PHI = np.sqrt(2.0)
PSI = 1.533751168755204288118041  # the root of ψ⁴ = ψ + 4 the spiral uses
GOLDEN = (1.0 + np.sqrt(5.0)) / 2.0
MAX_LATTICE = 20_000_000  # lattice points of a voxel grid (about 1.5 GB while the sphere is cut out of it)


def estimated_voxels(robot: Chain, voxel: float) -> int:
    """About how many voxels :func:`voxel_centres` returns (the reach sphere's volume over a voxel's), computed
    without building the grid: the size guards run before anything is allocated."""
    _, radius = reach_bound(robot)
    with np.errstate(over="ignore", divide="ignore"):
        count = 4.0 / 3.0 * np.pi * (np.float64(radius) / voxel + np.sqrt(3) / 2) ** 3
    return int(min(count, 1e30)) + 1


def voxel_centres(robot: Chain, voxel: float) -> np.ndarray:
    """(V, 3) centres [m] of the voxels of side ``voxel`` [m] whose centre lies within the reach bound
    (the sphere every reachable tool point lies in), on a lattice aligned with the base frame.

    Raises:
        KinelabError: a voxel side that is not a positive finite number.
    """
    if not is_real(voxel, 0, above=True):
        raise KinelabError(f"the voxel side must be a positive length in metres, got {voxel!r}")
    anchor, radius = reach_bound(robot)
    side = 2 * int(min(np.ceil(radius / voxel), 1e9)) + 1
    if side**3 > MAX_LATTICE:
        raise KinelabError(f"a {voxel:g} m voxel over {robot.name}'s reach ({radius:.3g} m) is a lattice of {side}³ = "
                           f"{side**3:.3g} points, over the {MAX_LATTICE:.0e} kinelab allocates; take a larger voxel")
    steps = np.arange(-np.ceil(radius / voxel), np.ceil(radius / voxel) + 1) * voxel
    grid = np.stack(np.meshgrid(steps, steps, steps, indexing="ij"), axis=-1).reshape(-1, 3) + np.asarray(anchor)
    return grid[np.linalg.norm(grid - np.asarray(anchor), axis=1) <= radius + voxel * np.sqrt(3) / 2]


def rotations(count: int) -> np.ndarray:
    """(count, 3, 3) rotation matrices spread evenly over SO(3) (a super-Fibonacci spiral)."""
    s = np.arange(count) + 0.5
    r, R = np.sqrt(s / count), np.sqrt(1.0 - s / count)
    alpha, beta = 2 * np.pi * s / PHI, 2 * np.pi * s / PSI
    w, x, y, z = r * np.sin(alpha), r * np.cos(alpha), R * np.sin(beta), R * np.cos(beta)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)


def axis_rotations(count: int) -> np.ndarray:
    """(count, 3, 3) rotations whose z axes are spread evenly over the sphere (a Fibonacci sphere); the roll
    about z is arbitrary (task "axis" leaves it free)."""
    k = np.arange(count) + 0.5
    z = np.stack([np.sqrt(1 - (1 - 2 * k / count) ** 2) * np.cos(2 * np.pi * k / GOLDEN),
                  np.sqrt(1 - (1 - 2 * k / count) ** 2) * np.sin(2 * np.pi * k / GOLDEN),
                  1 - 2 * k / count], axis=-1)
    helper = np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    return np.stack([x, np.cross(z, x), z], axis=-1)
