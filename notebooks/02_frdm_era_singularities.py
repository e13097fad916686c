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
# # 02 · FRDM and the European Robotic Arm passing its singularities (seed paper 000)
#
# The finite rotation and displacement method (FRDM, Danilov et al.) solves IK joint by joint: for each
# joint it takes the **exact** finite rotation (or displacement) that brings the tool as close as possible
# to the target, given the others. A sweep visits every joint; sweeps repeat until the target is reached.
# Every step is optimal for its joint, so the error never increases.
#
# Its **singularity monitor**: when a whole sweep moves nothing (Σ|Δq_i| = 0) while the target is not
# reached, the arm sits at a singular point. The paper then applies **bypasses**: small signed kicks,
# tighter intervals, or frozen joints.

# %%
import matplotlib.pyplot as plt
import numpy as np

import kinelab
from kinelab.ik.chain import chain_model as vector_model
from kinelab.studies import paper000_era as ep

era = kinelab.load("era")
vm = vector_model(era)
v = vm.vectors(np.zeros(7))
print("joint axes e_i (base frame) at q = 0:\n", np.round(v["e"], 3))
print("joint points o_i:\n", np.round(v["o"], 3))
print("type flags p:", v["p"], "  limits L(2, n) [deg]:\n", np.round(np.rad2deg(vm.limits), 1))

# %% [markdown]
# ## One solve, checked by Pinocchio
#
# `kinelab.solve(robot, target, solver="frdm")` runs FRDM from a start and then from seeded random starts (without
# `solver=`, kinelab takes the fastest certified route for the arm, FRDM or a closed form); the answer counts as a
# success only when Pinocchio's FK of the returned q is within 1e-6 m and 1e-6 rad.

# %%
target = era.fk(era.random_q(3))
res = kinelab.solve(era, target, solver="frdm", seed=1)
print(res.status.value, "| position error", f"{res.position_error:.1e} m",
      "| rotation error", f"{res.rotation_error:.1e} rad",
      "|", res.iterations, "sweeps |", f"{res.wall_time * 1e3:.2f} ms", "| mode", res.mode)

# %% [markdown]
# ## Passage 1: the elbow reach (the paper's Fig. 6–8)
#
# The tool rises along the vertical roll axis (the paper's x0, kinelab's z) until the elbow links align,
# a little past full reach so that the arm ends exactly straight, and comes back down. Straight, with the
# target on its own line, every exact step is zero: the monitor fires. We track the path twice, warm-started
# sample by sample with no restarts: without bypass, and with the paper's bypass — a small δq on the
# central (elbow) joint with a minus sign.

# %%
passage = ep.elbow_passage(era)
run = ep.run(passage, era)
heights = np.array([t.translation[2] for t in passage.targets])
fig, axes = plt.subplots(1, 3, figsize=(15, 3.8), sharex=True)
for ax, res, title in ((axes[0], run.without, "without bypass (Fig. 7)"),
                       (axes[1], run.with_bypass, "with bypass (Fig. 8)")):
    for j in (2, 3, 4):
        ax.plot(np.rad2deg(res.q[:, j]), label=f"θ{j + 1}")
    ax.set_title(title); ax.set_xlabel("path sample"); ax.set_ylabel("deg"); ax.legend()
axes[2].plot(run.without.position_error, label="without bypass")
axes[2].plot(run.with_bypass.position_error, label="with bypass")
axes[2].plot(np.maximum(heights - ep.FULL_REACH, 0), "k:", label="beyond reach by")
axes[2].set_yscale("symlog", linthresh=1e-6); axes[2].set_title("tool position error [m]"); axes[2].legend()
plt.tight_layout()
for name, res in (("without", run.without), ("with", run.with_bypass)):
    s = res.summary()
    print(f"{name:8s} bypass: reached {s['reached']}/{s['samples']}, largest joint step {s['max_joint_step']:.3f} rad, "
          f"monitor events {s['monitor_events']}, quadrant violations {ep.quadrant_violations(res, passage)}")

# %% [markdown]
# **What it shows.** Without bypass the arm straightens and stays straight: at every sample on the way
# down the monitor fires (Σ|Δq| = 0) and the tool is left behind by the target — the error grows to
# metres — until rounding finally folds it, with a jump of more than a radian. With the minus-sign kick
# on the elbow the arm folds back the way it came: θ3, θ4, θ5 each stay in their own quadrant, as in the
# paper's Fig. 8, every reachable sample is reached to 1e-6, and no joint moves more than about 0.2 rad
# between samples (the largest step is right after the fold, where the joint rate is high by nature).
#
# ## Tracking cost: FRDM against the Pinocchio DLS reference
#
# Both warm-started from the previous sample, no restarts, on the same path. The damped least-squares
# reference needs no bypass here: its damping and the warm start carry it through the straight arm.

# %%
dls = ep.dls_tracking(passage, era)
reach = ~passage.unreachable
print(f"FRDM: median {np.median(run.with_bypass.wall_time) * 1e6:6.0f} µs per sample, "
      f"max error {run.with_bypass.position_error[reach].max():.1e} m on reachable samples")
print(f"DLS : median {np.median(dls.wall_time) * 1e6:6.0f} µs per sample, "
      f"max error {dls.position_error[reach].max():.1e} m on reachable samples, "
      f"largest joint step {dls.max_joint_step:.3f} rad")

# %% [markdown]
# ## The three kinds of ERA singularity, by SVD
#
# The same analysis as `kinelab singular`: a configuration of each kind, its rank, and the tool motion it
# cannot make.

# %%
from kinelab.analysis import singular

for kind, q in ep.singular_examples(era).items():
    a = singular.analyze(era, q)
    d = a.lost_directions[0]
    print(f"{kind:18s} rank {a.rank}, σ_min/σ_max = {a.singular_values[-1] / a.singular_values[0]:.1e}, "
          f"lost: {100 * d.translation_share:.0f} % translation, {100 * d.rotation_share:.0f} % rotation")

# %% [markdown]
# ## Passages 2 and 3: the two gimbal locks
#
# The ERA has seven joints, one more than a pose needs, so lining up two of its axes does not cost it a
# tool direction by itself. What the lock creates is a **spin**: a group of links can turn while the
# tool stays put. FRDM, warm-started sample after sample, drifts along that spin as the tool moves, and
# the angles add up — the paper's "summing of angles" (Fig. 10) and "linear increase of the angles in
# opposite joints" (Fig. 13). On this model a single straight pass through a lock is smooth (the wrist is
# not spherical: J5 and J7 are 0.34 m apart), so kinelab moves the tool round a closed path inside each
# lock, lap after lap. A lap that ends in the configuration it started from is the sign of a healthy
# passage; a joint path that does not close is the failure.
#
# **Passage 2, wrist gimbal lock (Fig. 9–11).** q6 = 90° puts the tool roll axis J7 parallel to J5 (and
# to J3, J4). The wrist circles 0.35 m in the arm's vertical plane — up and back down each lap — with the
# tool orientation fixed. The paper's bypass holds q5 and q6 below 80°.

# %%
def laps_plot(passage, run, joints, titles):
    fig, axes = plt.subplots(1, 2, figsize=(15, 3.8), sharey=True)
    for ax, res, title in zip(axes, (run.without, run.with_bypass), titles, strict=False):
        for j in joints:
            ax.plot(np.rad2deg(res.q[:, j]), "--" if j == 6 else "-", label=f"θ{j + 1}")
        for k in range(1, passage.samples // passage.lap + 1):
            ax.axvline(k * passage.lap, color="0.85", lw=0.8)
        ax.set_title(title); ax.set_xlabel("path sample (grey: end of a lap)"); ax.set_ylabel("deg"); ax.legend(ncol=4)
    plt.tight_layout()
    for name, res in (("without", run.without), ("with", run.with_bypass)):
        s = res.summary()
        change = np.rad2deg(ep.lap_changes(res, passage))
        print(f"{name:8s} bypass: reached {s['reached']}/{s['samples']}, "
              f"largest joint step {s['max_joint_step']:.3f} rad, "
              f"monitor events {s['monitor_events']}; per-lap change of "
              + ", ".join(f"θ{j + 1} {np.array2string(change[:, j], precision=1)}°" for j in joints))

wrist = ep.wrist_passage(era)
wrist_run = ep.run(wrist, era)
laps_plot(wrist, wrist_run, (2, 3, 4, 5, 6), ("without bypass (Fig. 10)", "with q5, q6 < 80° (Fig. 11)"))

# %% [markdown]
# **What it shows.** Without bypass every sample is reached — the tool is fine — but q5 winds down and
# q7 winds up by about 8–12° every lap, in opposite senses and by the same amount: the wrist links spin
# about the locked axis and their angles add up lap after lap. The monitor never fires (every sweep
# moves something), which is why the paper sets this bypass as a parameter rather than waiting for the
# monitor. With q5, q6 < 80° the first lap settles the arm off the lock (q1 and q2 tilt the arm plane by
# a few degrees) and from then on every lap ends exactly where it began. The paper's other option, q1
# frozen, does nothing on this model: q1 takes no part in the wrist spin (checked in the tests).
#
# **Passage 3, shoulder (Fig. 12–14).** The tool, pointing down, circles 0.5 m round the vertical roll
# axis J1 with the wrist above the base, so J7 lines up with J1. The bypass freezes q1 while passing.

# %%
shoulder = ep.shoulder_passage(era)
shoulder_run = ep.run(shoulder, era)
laps_plot(shoulder, shoulder_run, (0, 1, 2, 4, 6), ("without bypass (Fig. 13)", "with q1 frozen (Fig. 14)"))

# %% [markdown]
# **What it shows.** Without bypass the whole arm turns with the tool: θ1 and θ7 — the joints at
# opposite ends of the chain, drawn on top of each other (θ7 dashed) — climb together, about 81° per lap,
# the paper's linear increase in opposite
# joints, with links 3 and 4 turning in phase about the vertical. In the third lap θ1 meets its ±180°
# stop and the arm swings back a whole turn in one sample (the jump monitor fires). With q1 frozen the
# other joints carry the tool round the circle and every lap closes; freezing q7 instead does the same
# (tested).
#
# ## Tracking cost along the passages: FRDM against the Pinocchio DLS reference
#
# Both warm-started from the previous sample, no restarts, on the same paths, median time per sample and
# the largest joint step.

# %%
for name, p, r in (("wrist", wrist, wrist_run), ("shoulder", shoulder, shoulder_run)):
    d = ep.dls_tracking(p, era)
    print(f"{name:8s} FRDM with bypass: {np.median(r.with_bypass.wall_time) * 1e6:5.0f} µs/sample, "
          f"step {r.with_bypass.max_joint_step:.3f} rad | DLS: {np.median(d.wall_time) * 1e6:5.0f} µs/sample, "
          f"step {d.max_joint_step:.3f} rad, per-lap change {np.abs(ep.lap_changes(d, p)).max():.1e} rad, "
          f"worst error {d.position_error.max():.1e} m")
