# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.7
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 07 · Whole-body kinematics
#
# A humanoid places both hands while standing on both feet; a two-armed robot holds a box with both grippers.
# Neither is one tool of one chain: the whole tree moves at once, several frames have targets, the centre of
# mass must stay over the feet, and every joint stays within its limits. kinelab loads the whole robot
# (`kinelab.load("talos")`), states what it wants as tasks (`FrameTask`, `RelativeFrameTask`, `ComTask`,
# `PostureTask`), and meets them with one of two solvers: the iterated differential step (a QP per
# iteration, the limits as its bounds) or FRDM carried to the tree (docs/wholebody.md). Every answer is
# judged again here with Pinocchio's own `framesForwardKinematics` and `centerOfMass`.
#
# Units: metres and radians.

# %%
import numpy as np
import pinocchio as pin

import kinelab
from kinelab.view.teach.whole import inside_polygon, support_polygon
from kinelab.wholebody import ComTask, FrameTask, Limits, PostureTask, RelativeFrameTask

talos = kinelab.load("talos")
print(f"{talos.name}: nq = {talos.nq}, nv = {talos.nv}, free-flyer: {talos.floating}")
print("hands:", talos.hands, " feet:", talos.feet)

# %% [markdown]
# ## TALOS places both hands, its feet where they stand
#
# The start is the SRDF's `half_sitting` with the soles on the floor. Each hand's target is 12 cm forward and
# 8 cm up from where it is, turned 20° about the vertical; the soles are held where they stand (their full
# poses), the centre of mass over its start on the floor plane (x and y; its height is free), and a posture
# toward the start at the second priority (it acts only in what the other tasks leave free).

# %%
q0 = kinelab.standing(talos)  # the SRDF's half_sitting, the soles on the floor
feet = talos.frame_placements(q0, talos.feet)
hands = talos.frame_placements(q0, talos.hands)
turn = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, np.deg2rad(20.0)), np.zeros(3))
goals = [pin.SE3(turn.rotation @ M.rotation, M.translation + np.array([0.12, 0.0, 0.08])) for M in hands]
com0 = talos.com(q0)
tasks = ([FrameTask(h, G) for h, G in zip(talos.hands, goals, strict=True)]
         + [FrameTask(f, M) for f, M in zip(talos.feet, feet, strict=True)]
         + [ComTask(com0, axes="xy"), PostureTask(q0, priority=2)])
print(f"start: half_sitting on the floor; {len(tasks)} tasks")

results = {solver: kinelab.solve(talos, tasks, q0=q0, solver=solver, seed=0, time_budget=5.0)
           for solver in ("step", "frdm")}
for solver, res in results.items():
    print(f"{solver:>4}: {res.status.value}, success {res.success}, {res.iterations} iterations, "
          f"{res.restarts} restarts, {res.wall_time * 1e3:.0f} ms")

# %% [markdown]
# Pinocchio's verdict on the step's answer: every hand and sole against its target, the centre of mass on the
# floor plane against its start, every joint within its limits.

# %%
q = results["step"].q
model, data = talos.model, talos.model.createData()
pin.framesForwardKinematics(model, data, q)
for name, goal in [*zip(talos.hands, goals, strict=True), *zip(talos.feet, feet, strict=True)]:
    gap = pin.log6(data.oMf[model.getFrameId(name)].actInv(goal)).vector
    print(f"{name:<26} position {np.linalg.norm(gap[:3]):.1e} m, rotation {np.linalg.norm(gap[3:]):.1e} rad")
com = pin.centerOfMass(model, data, q)
polygon = support_polygon(feet)
print(f"centre of mass moved {np.linalg.norm(com[:2] - com0[:2]):.1e} m on the floor plane; "
      f"over the support polygon: {inside_polygon(com[:2], polygon)}")
print(f"within the limits: {talos.within_limits(q)}")

# %% [markdown]
# Seen from above: the support polygon (the hull of a 0.20 × 0.10 m sole under each foot), the centre of mass
# before and after, and each hand where it started and where it went.

# %%
import matplotlib.pyplot as plt

fig, ax = plt.subplots(figsize=(6, 5))
loop = np.vstack([polygon, polygon[:1]])
ax.fill(loop[:, 0], loop[:, 1], color="tab:green", alpha=0.2, label="support polygon")
ax.plot(*com0[:2], "o", color="0.5", label="centre of mass, start")
ax.plot(*com[:2], "x", color="tab:red", ms=10, label="centre of mass, answer")
placed = talos.frame_placements(q, talos.hands)
for k, (a, b) in enumerate(zip(hands, placed, strict=True)):
    ax.annotate("", b.translation[:2], a.translation[:2], arrowprops={"arrowstyle": "->", "color": "tab:blue"})
    ax.plot(*a.translation[:2], "s", color="tab:blue", label="hands: start → answer" if k == 0 else None)
ax.set_aspect("equal")
ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]")
ax.legend(loc="upper left", fontsize=8)
ax.set_title("TALOS from above: both hands moved, the centre of mass held")
fig.tight_layout()

# %% [markdown]
# ## Baxter holds a box with both grippers
#
# The box is 36 cm wide, 70 cm in front of the robot. The left gripper takes one side (a full pose); the right
# gripper is asked for its pose *in the left gripper's frame* (`RelativeFrameTask`): what a rigid box fixes is
# the grippers' relative placement, wherever the box is.

# %%
baxter = kinelab.load("baxter")
box = pin.SE3(np.eye(3), np.array([0.7, 0.0, 0.15]))  # the box's frame, base frame
left = box * pin.SE3(pin.rpy.rpyToMatrix(np.pi / 2, 0.0, 0.0), np.array([0.0, 0.18, 0.0]))
right = box * pin.SE3(pin.rpy.rpyToMatrix(-np.pi / 2, 0.0, 0.0), np.array([0.0, -0.18, 0.0]))
lMr = left.actInv(right)  # the right gripper in the left's frame
hold = RelativeFrameTask("right_gripper", "left_gripper", lMr)
held = kinelab.solve(baxter, [FrameTask("left_gripper", left), hold, PostureTask(priority=2)], seed=0,
                     time_budget=5.0)
print(f"{held.status.value}, success {held.success}, {held.wall_time * 1e3:.0f} ms")
for verdict in held.tasks:
    print(f"  {verdict.label:<44} {verdict.position_error:.1e} m, {verdict.rotation_error:.1e} rad")

# %% [markdown]
# Now the box moves: it is lifted 10 cm and set down again in 4 s, followed at 200 Hz by `kinelab.step` (one QP
# a step, the file's position and velocity limits as its bounds). Holding the box comes first (the relative task
# at the first priority); the left gripper follows the box at the second, with a light posture toward where the
# box was taken. Pinocchio measures at every step how far the grippers' relative placement is from the box's,
# how far the left gripper lags, and whether any joint left its limits or moved faster than its velocity limit.
# (Sideways, the same box soon brings Baxter's right wrist to its limits: the step then holds the limits and
# the box, and the left gripper lags behind its target, as it must.)

# %%
dt, steps = 0.005, 800
q, bdata = held.q.copy(), baxter.model.createData()
follow_left, worst, outside, too_fast = FrameTask("left_gripper", left, priority=2), 0.0, 0, 0
lag, stay = 0.0, PostureTask(held.q, weight=1e-6, priority=2)  # a light pull toward where the box was taken
vmax = baxter.velocity_limit
for k in range(steps):
    a = 2 * np.pi * (k + 1) * dt / 4.0
    moved = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.05 * (1 - np.cos(a))])) * box
    result = kinelab.step(baxter, q, [follow_left.moved(moved * box.actInv(left)), hold, stay], dt, limits=Limits())
    q = result.q
    pin.framesForwardKinematics(baxter.model, bdata, q)
    oMl, oMr = (bdata.oMf[baxter.model.getFrameId(f)] for f in ("left_gripper", "right_gripper"))
    worst = max(worst, np.linalg.norm(pin.log6(oMl.actInv(oMr).actInv(lMr)).vector))
    lag = max(lag, np.linalg.norm(oMl.translation - (moved * box.actInv(left)).translation))
    outside += int(not baxter.within_limits(q))
    too_fast += int(np.any(np.abs(result.v) > vmax * (1 + 1e-9)))
print(f"{steps} steps: the grippers' relative placement within {worst:.1e} (m and rad, log6) of the box's; "
      f"the left gripper at most {lag * 1e3:.1f} mm behind the box's side; steps outside the limits: {outside}; "
      f"steps over a velocity limit: {too_fast}")
