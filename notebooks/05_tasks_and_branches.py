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
# # 05 · Tasks and branches
#
# Two questions users ask of an IK solver that a full-pose, one-answer solver leaves open:
#
# 1. **What if the arm cannot meet a whole pose?** The SO-101 has 5 joints: it can meet at most 5 of a
#    pose's 6 components. Grasping, drilling, welding and pointing need less than a pose anyway: the tool
#    point (task `"position"`), or the tool point plus one tool axis with the roll about it free (task
#    `"axis"`). kinelab judges a result on exactly the components its task constrains, with Pinocchio's FK.
# 2. **Which answer?** The FRDM paper calls its answer unique; it is unique from one start. A UR5 reaches
#    most poses in 8 ways. `kinelab.solve_all` returns every one (in closed form for arms like the UR5,
#    by a seeded search for the others), and `kinelab.solve(..., prefer=q_ref)` the one nearest a reference
#    configuration.
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
# The UR5's axes 2, 3 and 4 are parallel and its axes 5 and 6 meet: `solve_all` recognises that class
# from the axes and computes every branch in closed form — up to 8, each angle moved to its copy within the
# limits, each checked by Pinocchio (docs/analytic.md; the tests hold it against an independent closed form
# and EAIK on 1000 poses per arm). `solver="frdm"` runs the numeric multistart instead, the path of arms
# without a closed form: rounds of 64 seeded starts through the compiled batch solver until a stopping rule
# says another start is unlikely to find a new branch.

# %%
q_true = ur5.random_q(np.random.default_rng(4))
oMgoal = ur5.fk(q_true)
branches = kinelab.solve_all(ur5, oMgoal, q_ref=q_true)
print(f"{branches[0].mode}: {branches[0].diagnostics.branches} branches within the limits, each checked by "
      "Pinocchio:")
for k, b in enumerate(branches):
    print(f"  {k}: q = {np.array2string(b.q, precision=3, suppress_small=True)}  "
          f"errors {b.position_error:.0e} m, {b.rotation_error:.0e} rad")
searched = kinelab.solve_all(ur5, oMgoal, solver="frdm", seed=0, q_ref=q_true)
same = all(min(distance(ur5, s.q, b.q) for s in searched) < 1e-3 for b in branches)
print(f"the multistart: {len(searched)} branches ({'the same set' if same else 'not the same set'}), "
      f"estimated chance of a missed one {searched[0].diagnostics.unseen:.3f}")

# %% [markdown]
# Sorted by distance to `q_ref` (here the configuration the target was made from): the first is that
# configuration itself. `solve(..., prefer=q_ref)` returns exactly that one, where a plain solve returns
# whichever branch its route finds first (the closed form's first without a start, FRDM's from its start).

# %%
plain = kinelab.solve(ur5, oMgoal, seed=1)
preferred = kinelab.solve(ur5, oMgoal, prefer=q_true)
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

# %% [markdown]
# ## A 7R arm's branches along its redundancy
#
# A 7-joint arm meets a pose along a one-parameter family of configurations. The Panda's first six joints
# have a spherical shoulder and axes 5 and 6 meeting: with joint 7 held at a value they have a closed form
# (docs/analytic.md), so `solve_all(..., redundancy=K)` returns every branch at K values of joint 7, each
# checked by Pinocchio on the whole arm. Plotted against the held joint, the answers trace the self-motion
# curves of the pose: where a curve ends, a joint limit (or the reach) cuts it.

# %%
import matplotlib.pyplot as plt  # noqa: E402

panda = kinelab.load("panda")
oMpanda = panda.fk(panda.random_q(np.random.default_rng(7)))
swept = kinelab.solve_all(panda, oMpanda, redundancy=64)
print(f"{len(swept)} answers at 64 values of joint 7: {swept[0].mode}")
print(f"worst error: {max(max(panda.tool_error(s.q, oMpanda)) for s in swept):.1e} (m or rad)")
Q = np.array([s.q for s in swept])
fig, axes = plt.subplots(2, 3, figsize=(11, 5.5), sharex=True)
for j, ax in enumerate(axes.flat):
    ax.scatter(Q[:, 6], Q[:, j], s=6)
    ax.axhline(panda.lower[j], color="0.6", lw=0.8)
    ax.axhline(panda.upper[j], color="0.6", lw=0.8)
    ax.set_ylabel(f"q{j + 1} [rad]")
for ax in axes[1]:
    ax.set_xlabel("q7, held [rad]")
fig.suptitle("Every branch of one Panda pose at 64 values of joint 7 (grey: joint limits)")
fig.tight_layout()

# %%
view.close()
view_so101.close()
