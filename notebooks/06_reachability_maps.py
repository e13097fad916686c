# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 06 · Reachability maps
#
# Where can the arm put its tool, in how many orientations, and how well-conditioned is it there? And for a
# mobile manipulator: where must the platform stand to reach a grasp? `kinelab.maps` answers both, every
# reached target checked by Pinocchio. The maps are computed chunk by chunk (each chunk a pure function of
# the robot, the spec and its index), so the same map comes out of one process, a resumed run or a Dask
# cluster (`kinelab map reach ur5 --workers 2`, extra `kinelab[cluster]`). The UR5 has a closed form
# (docs/analytic.md), so its map solves every branch of every pose and also counts, per voxel, the branches
# within the limits; arms without one get the FRDM batch, one answer per pose.
#
# Units: metres and radians; every position is in the robot's base frame.

# %%
import matplotlib.pyplot as plt
import numpy as np

import kinelab
from kinelab import maps
from kinelab.view import maps as view_maps

ur5 = kinelab.load("ur5")
spec = maps.MapSpec(voxel=0.1, orientations=8, restarts=5)
ur5_map = maps.reachability(ur5, spec)
reach = ur5_map.array("reachability")
branches = ur5_map.array("branches")
print(f"{len(reach)} voxels of {spec.voxel} m inside the reach bound, {spec.orientations} orientations each; "
      f"{(reach > 0).sum()} reached, {(reach == 1).sum()} in every orientation ({ur5_map.meta['solver']}); "
      f"{branches[reach > 0].mean():.2f} branches per pose within the limits in the reached voxels")

# %% [markdown]
# ## The map in 3-D
#
# Each reached voxel is a point coloured by its reachability index (the share of its eight orientations,
# spread evenly over SO(3), that the arm reaches): green inside, yellow and red towards the edge of the
# workspace, where only a few tool orientations remain.

# %%
cloud = view_maps.reachability_cloud(ur5, ur5_map, meshes=False)  # a stick figure: the page stays small
cloud.notebook_html()

# %% [markdown]
# ## A slice through the base
#
# The horizontal layer of voxels through the middle of the map.

# %%
ax = view_maps.reachability_slice(ur5_map)
plt.tight_layout()

# %% [markdown]
# ## What a table takes away
#
# The same map with the arm standing on a floor beside a table (a 0.6 m × 0.8 m top, 5 cm thick, 0.2 m up and
# 0.5 m in front), and the arm kept clear of itself: a pose counts only through a branch that collides with
# nothing (`MapSpec(collisions=...)`, docs/collisions.md). The floor removes everything below the base's
# height, the table the voxels it occupies and the poses that would reach through it: the 3-D view draws the
# two (grey) with the voxels still reached, and the slice above the table shows where orientations are lost.

# %%
from kinelab import Collisions, Environment, Obstacle
from kinelab.view.collisions import draw_obstacles

scene = Environment((Obstacle("plane", name="floor"),
                     Obstacle("box", size=(0.6, 0.8, 0.05), xyz=(0.5, 0.0, 0.2), name="table")))
walled_map = maps.reachability(ur5, maps.MapSpec(voxel=0.1, orientations=8, collisions=Collisions(environment=scene)))
walled = walled_map.array("reachability")
print(f"with the floor and the table: {(walled > 0).sum()} voxels reached of {(reach > 0).sum()}; "
      f"mean reachability {walled.mean():.3f} against {reach.mean():.3f}")
walled_cloud = draw_obstacles(view_maps.reachability_cloud(ur5, walled_map, meshes=False), scene)
walled_cloud.notebook_html()

# %%
fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
view_maps.reachability_slice(ur5_map, value=0.25, ax=axes[0])
axes[0].set_title("free, layer z ≈ 0.25 m")
view_maps.reachability_slice(walled_map, value=0.25, ax=axes[1])
axes[1].set_title("floor and table, layer z ≈ 0.25 m")
plt.tight_layout()

# %% [markdown]
# ## Where should the youBot stand?
#
# A grasp in front of the youBot's platform. The platform's x and y are gridded around the grasp; at each
# position the heading and the five arm joints are solved (six coordinates for the grasp's six components),
# and the reachable positions are ranked by the arm's manipulability.

# %%
youbot = kinelab.load("youbot")
grasp = youbot.fk(youbot.display_q())
base = maps.base_map(youbot, grasp, step=0.05)
print(f"reachable from {base.reachable.sum()} of {len(base.poses)} platform positions")
for i in base.ranked(3):
    x, y, yaw = base.poses[i]
    print(f"  x {x:+.3f} m, y {y:+.3f} m, heading {np.rad2deg(yaw):+7.1f}°, manipulability "
          f"{base.manipulability[i]:.3g}")

ok = base.reachable
plt.figure(figsize=(5.5, 4.5))
plt.scatter(base.poses[~ok, 0], base.poses[~ok, 1], s=6, c="lightgrey", label="not reachable")
art = plt.scatter(base.poses[ok, 0], base.poses[ok, 1], s=25, c=base.manipulability[ok], cmap="viridis",
                  label="reachable")
plt.quiver(base.poses[ok, 0], base.poses[ok, 1], np.cos(base.poses[ok, 2]), np.sin(base.poses[ok, 2]),
           scale=25, width=0.004, color="k")
plt.plot(*grasp.translation[:2], "r*", ms=14, label="grasp")
plt.colorbar(art, label="manipulability"); plt.gca().set_aspect("equal")
plt.xlabel("platform x [m]"); plt.ylabel("platform y [m]"); plt.legend(fontsize=8, loc="lower left")

# %% [markdown]
# Every reachable position was checked with the whole robot: Pinocchio's FK of (x, y, heading, arm q) meets
# the grasp to 1e-6 m and 1e-6 rad within the limits (the tests hold this for each one).

# %%
cloud.close()
walled_cloud.close()
