# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 01 · Robots and the reference
#
# kinelab loads a URDF into **Pinocchio**, keeps the serial chain from the base to a tool frame, and
# uses Pinocchio as the ground truth for forward kinematics (FK) and Jacobians. This notebook shows the
# robots, their joints and limits, and checks Pinocchio against a second, independent URDF reader
# (**yourdfpy**) and against finite differences.
#
# Units: metres and radians everywhere inside kinelab; degrees only where we print them for people.

# %%
import matplotlib.pyplot as plt
import numpy as np

import kinelab
from kinelab.analysis import oracles as checks
from kinelab.analysis.oracles import YourdfpyFK

print(kinelab.robots())

# %% [markdown]
# ## The three bundled robots
#
# * **stanford** — the Stanford arm (RRPRRR) in the frames of Lomovtseva & Chelnokov (seed paper 001).
# * **era** — the European Robotic Arm, 7 revolute joints, about 11.3 m (approximate geometry).
# * **youbot** — the KUKA youBot arm on its platform; the platform's x, y and yaw are joints, so the
#   coordinates are Kapustina's Q = (X_C, Y_C, θ, θ1..θ5).
#
# Each robot lists its joints with their type and limits. Continuous joints (like the youBot platform
# yaw) are stored by Pinocchio as a (cos, sin) pair, so `nq` can exceed the number of joints `n`.

# %%
def joint_table(robot):
    print(f"{robot.name}: n = {robot.n}, nq = {robot.nq}, nv = {robot.nv}, tool frame = {robot.tool!r}")
    for j in robot.joints:
        if j.kind == "prismatic":
            print(f"   {j.name:<14} {j.kind:<11} [{j.lower:8.3f}, {j.upper:8.3f}] m")
        else:
            print(f"   {j.name:<14} {j.kind:<11} [{np.rad2deg(j.lower):8.1f}, {np.rad2deg(j.upper):8.1f}] deg")

robots = {name: kinelab.load(name) for name in ["stanford", "era", "youbot", "panda", "ur5"]}
for robot in robots.values():
    joint_table(robot)

# %% [markdown]
# ## Forward kinematics: Pinocchio next to yourdfpy
#
# `robot.fk(q)` returns a `pin.SE3`: the pose of the tool frame in the base frame (`oMtool`). yourdfpy
# reads the same URDF with its own parser and its own transform chain. At the same random q the two
# poses must agree to rounding error.

# %%
rng = np.random.default_rng(0)
stanford = robots["stanford"]
q = stanford.random_q(rng)
print("q =", np.round(q, 4))
print("Pinocchio:\n", stanford.fk(q))
print("yourdfpy:\n", YourdfpyFK(stanford).fk(q))

# %%
for name, robot in robots.items():
    a = checks.fk_vs_yourdfpy(robot, count=200, seed=1)
    print(f"{name:<9} max position gap {a.max_position:.1e} m, max rotation gap {a.max_rotation:.1e} rad")

# %% [markdown]
# ## Jacobians, with the frame in the name
#
# `jacobian_local` (tool frame), `jacobian_world` (base frame, velocity of the point at the base origin)
# and `jacobian_local_world_aligned` (base axes at the tool). Rows are Pinocchio's [linear; angular].
# We check all three against central finite differences of FK, stepping the joints with
# `pin.integrate` so that continuous joints are handled correctly.

# %%
q = robots["ur5"].random_q(rng)
print(np.round(robots["ur5"].jacobian_local(q), 3))
for name, robot in robots.items():
    a = checks.jacobians_vs_fd(robot, count=20, seed=2)
    print(f"{name:<9} max |J - J_fd| = {a.max_rotation:.1e}")

# %% [markdown]
# ## The youBot at the paper's zero
#
# All of θ1..θ5 at zero is the "candle": the arm straight up. We draw the joint origins from Pinocchio
# and from yourdfpy's tool pose side by side (a side view, x–z plane).

# %%
youbot = robots["youbot"]
fig, axes = plt.subplots(1, 2, figsize=(9, 4))
for ax, theta2 in zip(axes, [0.0, 0.6], strict=False):
    q = np.zeros(8)
    q[4] = theta2
    pts = np.array([m.translation for m in youbot.joint_placements(q).values()] + [youbot.fk(q).translation])
    ax.plot(pts[3:, 0], pts[3:, 2], "o-", label="Pinocchio joint origins")
    tool = YourdfpyFK(youbot).fk(q).translation
    ax.plot(tool[0], tool[2], "rx", ms=12, label="yourdfpy tool point")
    ax.set_title(f"θ2 = {theta2} rad"); ax.set_xlabel("x [m]"); ax.set_ylabel("z [m]"); ax.axis("equal")
axes[0].legend(loc="lower right")
plt.tight_layout()

# %% [markdown]
# ## In the browser
#
# `kinelab.view.scene.Scene` draws a robot with meshcat (its server listens on 127.0.0.1 only; `scene.url` is
# the live viewer). Here the youBot at a random configuration, embedded as a static page: it stays visible
# when the notebook is saved or exported, caption included.

# %%
from kinelab.view import scene as viz

scene = viz.Scene(youbot).show(youbot.random_q(rng))
scene.notebook_html()

# %% [markdown]
# To move a robot by hand — a slider per joint, a target to drag that it follows by IK, its branches and the
# velocity ellipsoid — run `kinelab teach youbot` in a terminal, or in a live notebook:
#
# ```python
# from kinelab.view.teach import teach
# page = teach(youbot)  # the page in the cell, served by this kernel on 127.0.0.1; page.close() stops it
# ```
#
# It is not run here: a saved or exported notebook has no kernel left to serve the page (docs/teach.md).
