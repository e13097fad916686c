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
# # 08 · Closed loops: a four-bar, a delta robot and Cassie
#
# A URDF describes a tree, so a robot whose links close loops is written as one — every loop cut at a joint — and
# the cuts are declared as **closures**, two frames that must meet (docs/closures.md). kinelab assembles such a
# robot (the passive joints moved until every loop closes, the motors held), holds its loops in every whole-body
# step and solve, and finds its two kinds of singular configurations. Each figure below is checked against a
# closed form: the four-bar's joint C is the intersection of two circles, the delta's platform that of three
# spheres.
#
# Units: metres and radians.

# %%
import matplotlib.pyplot as plt
import numpy as np

import kinelab
from kinelab import FrameTask
from kinelab.analysis import closed_singular as cs

fourbar, delta = kinelab.load("fourbar"), kinelab.load("delta")
for robot in (fourbar, delta):
    print(f"{robot.name}: {robot.nq} joints, motors {robot.actuated}, loops:",
          "; ".join(c.label for c in robot.closures))

# %% [markdown]
# ## The four-bar: its coupler curve and its dead points
#
# The crank (0.10 m) turns fully; the rocker (0.22 m) swings. Turning the crank in small steps and assembling
# each configuration from the one before follows one assembly mode. The rocker stops and turns back where crank
# and coupler lie in line (|AC| = 0.38 m or 0.18 m): there the motor cannot move the output — a type I
# singularity, σ_I = 0.

# %%
a, b, c, d = 0.10, 0.28, 0.22, 0.30
cranks = np.linspace(-np.pi, np.pi, 361)
q = fourbar.assemble(np.array([cranks[0], 0.0, 0.0]))
tips, mids, sigma_i, worst_loop, worst_circle = [], [], [], 0.0, 0.0
for theta in cranks:
    start = q.copy()
    start[0] = theta
    q = fourbar.assemble(start)
    tip = fourbar.frame_placement(q, "rocker_tip").translation[:2]
    B = a * np.array([np.cos(theta), np.sin(theta)])
    worst_circle = max(worst_circle, abs(np.linalg.norm(tip - B) - b), abs(np.linalg.norm(tip - [d, 0.0]) - c))
    worst_loop = max(worst_loop, np.abs(fourbar.closure_error(q)).max())
    tips.append(tip)
    mids.append((B + tip) / 2)  # the coupler's midpoint: it traces the coupler curve
    sigma_i.append(cs.analyze(fourbar, q, "rocker_tip").sigma_serial)
tips, mids, sigma_i = np.array(tips), np.array(mids), np.array(sigma_i)
print(f"largest loop error {worst_loop:.1e} m; C off its two circles by at most {worst_circle:.1e} m")
dead = [cranks[i] for i in range(1, len(cranks) - 1) if sigma_i[i] < sigma_i[i - 1] and sigma_i[i] < sigma_i[i + 1]]
print("σ_I's minima near crank angles [deg]:", np.round(np.rad2deg(dead), 1))
for length, sign in ((a + b, 1.0), (b - a, -1.0)):  # C where |AC| = a ± b meets the rocker's circle
    x = (length**2 - c**2 + d**2) / (2 * d)
    y = np.sqrt(length**2 - x**2)
    theta = np.arctan2(sign * y, sign * x)  # the crank along C (stretched) or away from it (folded)
    print(f"closed form, crank and coupler in line (|AC| = {length:.2f} m): crank at ±{abs(np.rad2deg(theta)):.1f} deg "
          "(one of each on this assembly mode)")

# %%
fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
left.plot(tips[:, 0], tips[:, 1], "b-", lw=1, label="C (the rocker's end)")
left.plot(mids[:, 0], mids[:, 1], "g-", lw=1, label="the coupler's midpoint")
left.plot([0, d], [0, 0], "k^", ms=9, label="ground pivots A, D")
left.set_aspect("equal")
left.legend(fontsize=8)
left.set_xlabel("x [m]")
left.set_ylabel("y [m]")
left.set_title("C rocks on an arc; the coupler's midpoint loops")
right.semilogy(np.rad2deg(cranks), np.maximum(sigma_i, 1e-17))
right.set_xlabel("crank [deg]")
right.set_ylabel("σ_I [m/rad]")
right.set_title("type I at the rocker's dead points")
plt.tight_layout()
plt.show()

# %% [markdown]
# ## The delta robot: its workspace, checked against the closed form
#
# Three motors turn three upper arms; the forearms (parallelograms, kept as their centre lines on ball joints)
# carry a platform that stays parallel to the base. For each motor triple on a grid, the assembly's platform is
# compared with the closed form (the lower intersection of three spheres), and both singularity measures read.

# %%
R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04
PHI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)


def platform_closed_form(theta):
    """The platform centre below the base for motor angles theta (three spheres' intersection)."""
    centres = np.array([(R + LA * np.cos(t) - RP) * np.array([np.cos(p), np.sin(p), 0.0])
                        + np.array([0.0, 0.0, -LA * np.sin(t)]) for p, t in zip(PHI, theta, strict=True)])
    A, rhs = 2 * (centres[1:] - centres[0]), (centres[1:] ** 2).sum(1) - (centres[0] ** 2).sum()
    n = np.cross(A[0], A[1])
    p0 = np.linalg.lstsq(A, rhs, rcond=None)[0]
    qa, qb, qc = n @ n, 2 * (p0 - centres[0]) @ n, (p0 - centres[0]) @ (p0 - centres[0]) - LB**2
    s = (-qb + np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    candidates = [p0 + s * n, p0 + (-qb - np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa) * n]
    return min(candidates, key=lambda p: p[2])


motors = [delta.model.joints[delta.model.getJointId(m)].idx_q for m in delta.actuated]
home = delta.assemble(delta.neutral())
grid = np.linspace(-0.5, 1.3, 9)
points, s1, s2, worst = [], [], [], 0.0
for t1 in grid:
    for t2 in grid:
        for t3 in grid:
            q = home.copy()
            for w in (0.25, 0.5, 0.75, 1.0):  # from home in four moves: the assembly stays in home's mode
                q[motors] = (1 - w) * home[motors] + w * np.array([t1, t2, t3])
                q = delta.assemble(q)
            P = delta.frame_placement(q, "platform_centre").translation
            worst = max(worst, np.abs(P - platform_closed_form((t1, t2, t3))).max())
            s = cs.analyze(delta, q, "platform_centre")
            points.append(P)
            s1.append(s.sigma_serial)
            s2.append(s.sigma_parallel)
points = np.array(points)
print(f"{len(points)} assemblies; platform against the closed form: at most {worst:.1e} m apart")
print(f"σ_I from {min(s1):.3g} to {max(s1):.3g} m/rad, σ_II from {min(s2):.3g} to {max(s2):.3g}: "
      "no singularity of either type within the motors' range")

# %%
fig = plt.figure(figsize=(10, 4))
ax = fig.add_subplot(1, 2, 1, projection="3d")
shown = ax.scatter(points[:, 0], points[:, 1], points[:, 2], c=np.log10(s1), s=6, cmap="viridis")
fig.colorbar(shown, ax=ax, shrink=0.7, pad=0.12, label="log10 σ_I")
ax.set_xlabel("x [m]")
ax.set_ylabel("y [m]")
ax.set_zlabel("z [m]")
ax.set_title("the platform's workspace (motors on a grid)")
side = fig.add_subplot(1, 2, 2)
side.scatter(np.hypot(points[:, 0], points[:, 1]), points[:, 2], c=np.log10(s1), s=6, cmap="viridis")
side.set_xlabel("distance from the axis [m]")
side.set_ylabel("z [m]")
side.set_title("σ_I falls toward the workspace's rim")
plt.tight_layout()
plt.show()

# %% [markdown]
# ## The platform moved by the whole-body step, the loops held
#
# A position task on the platform's centre follows a 5 cm circle, one step of 10 ms at a time; every step holds
# the loops as equalities of its QP and projects out what is left (docs/closures.md). The loops' error after each
# step is measured here from Pinocchio's frame placements.

# %%
q = home.copy()
centre = delta.frame_placement(q, "platform_centre").translation
problem = kinelab.WholeBody(delta, [FrameTask("platform_centre", centre, task="position")])
trace, loops = [], 0.0
for k in range(400):
    angle = 2 * np.pi * min(k, 300) / 300
    problem.set_target(0, centre + 0.05 * np.array([np.cos(angle) - 1.0, np.sin(angle), 0.0]))
    q = problem.step(q, 0.01).q
    loops = max(loops, np.abs(delta.closure_error(q)).max())
    trace.append(delta.frame_placement(q, "platform_centre").translation)
trace = np.array(trace)
print(f"400 steps: largest loop error {loops:.1e}; the platform back at its start within "
      f"{np.linalg.norm(trace[-1] - centre):.1e} m")
plt.figure(figsize=(4, 4))
plt.plot(trace[:, 0], trace[:, 1])
plt.gca().set_aspect("equal")
plt.xlabel("x [m]")
plt.ylabel("y [m]")
plt.title("the platform's path")
plt.show()

# %% [markdown]
# ## Cassie: a biped whose legs close four loops
#
# `cassie` is MuJoCo Menagerie's model of Agility Robotics' Cassie reduced to its kinematics (urdf/cassie.xml): an
# MJCF file whose four `<connect>` equalities — each leg's achilles rod to its heel spring, its plantar rod to its
# foot — are its loops, read through Pinocchio 4's loader, and whose motors are its actuated joints (five a leg).
# The pelvis floats. Here the left foot goes where the left hip pitched 0.35 rad and the knee bent 0.45 rad further
# put it (assembled: 17 cm forward, 5 cm up) while the right foot and the pelvis hold their poses; every step
# holds the four loops.

# %%
cassie = kinelab.load("cassie")
q = cassie.standing()  # the file's "home" keyframe, its loops closed
print(f"{cassie.name}: nq = {cassie.nq}, nv = {cassie.nv}, {len(cassie.closures)} loops, "
      f"actuated: {', '.join(cassie.actuated)}")
lifted = q.copy()
for joint, turn in (("left-hip-pitch", 0.35), ("left-knee", -0.45)):
    lifted[cassie.model.joints[cassie.model.getJointId(joint)].idx_q] += turn
goal = cassie.frame_placement(cassie.assemble(lifted), "left-foot")
start = cassie.frame_placement(q, "left-foot").translation
print(f"the left foot's goal: {100 * (goal.translation - start).round(3)} cm from where it stands")
walker = kinelab.WholeBody(cassie, [FrameTask("left-foot", goal),
                                    FrameTask("right-foot", cassie.frame_placement(q, "right-foot")),
                                    FrameTask("cassie-pelvis", cassie.frame_placement(q, "cassie-pelvis"))])
path, loops = [], 0.0
for _ in range(150):
    q = walker.step(q, 0.01).q
    loops = max(loops, np.abs(cassie.closure_error(q)).max())
    path.append(cassie.frame_placement(q, "left-foot").translation)
path = np.array(path)
print(f"150 steps: largest loop error {loops:.1e}; the left foot {np.linalg.norm(path[-1] - goal.translation):.1e} m "
      "from its goal")
plt.figure(figsize=(5, 3))
plt.plot(path[:, 0], path[:, 2])
plt.xlabel("x [m] (forward)")
plt.ylabel("z [m]")
plt.title("Cassie's left foot, seen from the side")
plt.show()
