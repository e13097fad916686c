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
# # 05 · Tasks and branches
#
# Two questions users ask of an IK solver that a full-pose, one-answer solver leaves open:
#
# 1. **What if the arm cannot meet a whole pose?** The SO-101 has 5 joints: it can meet at most 5 of a
#    pose's 6 components. Grasping, drilling, welding and pointing need less than a pose anyway: the tool
#    point (task `"position"`), or the tool point plus one tool axis with the roll about it free (task
#    `"axis"`). kinelab judges a result on exactly the components its task constrains, with Pinocchio's FK.
# 2. **Which answer?** The FRDM paper calls its answer unique; it is unique from one start. A UR5 reaches
#    most poses in 8 ways. `kinelab.solve_all` finds the distinct solutions within a time budget, and
#    `kinelab.solve(..., prefer=q_ref)` returns the one nearest a reference configuration.
#
# Units: metres and radians; degrees only where printed for people.

# %%
import numpy as np
import pinocchio as pin

import kinelab
from kinelab.ik.branches import distance
from kinelab.view import scene as viz

so101, ur5 = kinelab.load("so101"), kinelab.load("ur5")
print(f"so101: {so101.n} joints, tool frame {so101.tool!r}; ur5: {ur5.n} joints, tool frame {ur5.tool!r}")

# %% [markdown]
# ## A point for the SO-101
#
# A target given as a point, with the identity rotation, as a new user would write it. As a whole pose it
# is out of the arm's reach (its tool cannot point that way there); the result says so and names the
# tasks that fit. As a position it is met to well below a micrometre.

# %%
oMtarget = kinelab.target_from_xyz_rpy([0.2, 0.0, 0.15], [0.0, 0.0, 0.0])
for task in ("pose", "position"):
    res = kinelab.solve(so101, oMtarget, task=task, seed=0, time_budget=0.05)
    print(f"task {task:<8}: {res.status.value:<14} success {res.success}  position error "
          f"{res.position_error:.1e} m  rotation error {res.rotation_error:.1e} rad")
    if res.message:
        print("   ", res.message)

# %% [markdown]
# ## Every task on FK-generated targets
#
# Targets made from random configurations in the limits: for `"position"` the target's rotation is then
# replaced by a random one (only the point counts), for `"axis"` it is turned by a random roll about the
# tool z axis (the free one). The verdict is Pinocchio's, on the task's components, within the limits.

# %%
rng = np.random.default_rng(1)


def task_targets(robot, task, n):
    out = []
    for _ in range(n):
        oMtool = robot.fk(robot.random_q(rng))
        if task == "position":
            oMtool = pin.SE3(pin.exp3(rng.normal(size=3)), oMtool.translation)
        elif task == "axis":
            oMtool = pin.SE3(oMtool.rotation @ pin.exp3(np.array([0.0, 0.0, rng.uniform(-np.pi, np.pi)])),
                             oMtool.translation)
        out.append(oMtool)
    return out


for robot in (so101, ur5):
    for task in ("position", "axis", "orientation"):
        results = [kinelab.solve(robot, t, task=task, seed=k, time_budget=0.05)
                   for k, t in enumerate(task_targets(robot, task, 50))]
        solved = sum(r.success for r in results)
        worst_p = max(r.position_error for r in results if r.success)
        worst_r = max(r.rotation_error for r in results if r.success)
        print(f"{robot.name:<6} {task:<11} solved {solved}/50   worst position error {worst_p:.1e} m, "
              f"rotation error {worst_r:.1e} rad (counted: {results[0].task})")

# %% [markdown]
# (For `"position"` the rotation error is reported but not judged; for `"orientation"` the position.)
#
# ## All the branches of a UR5 target
#
# `solve_all` runs rounds of 64 seeded starts through the compiled batch solver until the budget is
# spent, keeps what Pinocchio confirms, and merges answers that are the same solution joint by joint
# (revolute joints modulo 2π). The UR5's closed-form inverse has up to 8 solutions; the tests hold
# `solve_all` against it on 40 random targets per arm.

# %%
q_true = ur5.random_q(np.random.default_rng(4))
oMgoal = ur5.fk(q_true)
branches = kinelab.solve_all(ur5, oMgoal, seed=0, time_budget=0.05, q_ref=q_true)
print(f"{len(branches)} distinct solutions in 50 ms; each checked by Pinocchio:")
for k, b in enumerate(branches):
    print(f"  {k}: q = {np.array2string(b.q, precision=3, suppress_small=True)}  "
          f"errors {b.position_error:.0e} m, {b.rotation_error:.0e} rad, reached by {b.diagnostics.found} starts")

# %% [markdown]
# This target has 6 real solutions within the limits by the closed form (the tests' oracle), and all 6 are
# found. Sorted by distance to `q_ref` (here the configuration the target was made from): the first is that
# configuration itself. `solve(..., prefer=q_ref)` returns exactly that one, where a plain solve returns
# whichever branch its start falls towards.

# %%
plain = kinelab.solve(ur5, oMgoal, seed=1)
preferred = kinelab.solve(ur5, oMgoal, seed=1, prefer=q_true, time_budget=0.05)
print(f"plain solve: distance to q_ref {distance(ur5, plain.q, q_true):.3f} rad")
print(f"prefer=q_ref: distance to q_ref {distance(ur5, preferred.q, q_true):.1e} rad "
      f"(among {preferred.diagnostics.branches} branches)")

# %% [markdown]
# The branches side by side (stick figures: joints as blue spheres, tool frames as x red, y green,
# z blue triads). The page is static HTML: it stays visible in a saved notebook. Drag to turn it.

# %%
view = viz.side_by_side(ur5, [b.q for b in branches])
view.notebook_html()

# %% [markdown]
# ## The SO-101's branches of an axis task
#
# Five joints, five constrained components (a point and a direction): a finite set of solutions again.

# %%
oMaxis = task_targets(so101, "axis", 1)[0]
axis_branches = kinelab.solve_all(so101, oMaxis, task="axis", seed=0, time_budget=0.05)
for k, b in enumerate(axis_branches):
    print(f"  {k}: q = {np.array2string(b.q, precision=3, suppress_small=True)}  "
          f"errors {b.position_error:.0e} m, {b.rotation_error:.0e} rad")
view_so101 = viz.side_by_side(so101, [b.q for b in axis_branches])
view_so101.notebook_html()

# %%
view.close()
view_so101.close()
