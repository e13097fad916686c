CELLS = [
("md", """
# 02 · FRDM and the European Robotic Arm passing its singularities (seed paper 000)

The finite rotation and displacement method (FRDM, Danilov et al.) solves IK joint by joint: for each
joint it takes the **exact** finite rotation (or displacement) that brings the tool as close as possible
to the target, given the others. A sweep visits every joint; sweeps repeat until the target is reached.
Every step is optimal for its joint, so the error never increases.

Its **singularity monitor**: when a whole sweep moves nothing (Σ|Δq_i| = 0) while the target is not
reached, the arm sits at a singular point. The paper then applies **bypasses**: small signed kicks,
tighter intervals, or frozen joints.
"""),
("code", """
import numpy as np
import pinocchio as pin
import matplotlib.pyplot as plt
import kinelab
from kinelab.ik import solve
from kinelab.ik.frdm.solver import vector_model
from kinelab.studies import era_passages as ep

era = kinelab.load("era")
vm = vector_model(era)
v = vm.vectors(np.zeros(7))
print("joint axes e_i (base frame) at q = 0:\\n", np.round(v["e"], 3))
print("joint points o_i:\\n", np.round(v["o"], 3))
print("type flags p:", v["p"], "  limits L(2, n) [deg]:\\n", np.round(np.rad2deg(vm.limits), 1))
"""),
("md", """
## One solve, checked by Pinocchio

`kinelab.solve(robot, target)` runs FRDM from a start and then from seeded random starts; the answer
counts as a success only when Pinocchio's FK of the returned q is within 1e-6 m and 1e-6 rad.
"""),
("code", """
target = era.fk(era.random_q(3))
res = solve(era, target, seed=1)
print(res.status.value, "| position error", f"{res.position_error:.1e} m", "| rotation error", f"{res.rotation_error:.1e} rad",
      "|", res.iterations, "sweeps |", f"{res.wall_time * 1e3:.2f} ms", "| mode", res.mode)
"""),
("md", """
## Passage 1: the elbow reach (the paper's Fig. 6–8)

The tool rises along the vertical roll axis (the paper's x0, kinelab's z) until the elbow links align,
a little past full reach so that the arm ends exactly straight, and comes back down. Straight, with the
target on its own line, every exact step is zero: the monitor fires. We track the path twice, warm-started
sample by sample with no restarts: without bypass, and with the paper's bypass — a small δq on the
central (elbow) joint with a minus sign.
"""),
("code", """
passage = ep.elbow_passage(era)
run = ep.run(passage, era)
heights = np.array([t.translation[2] for t in passage.targets])
fig, axes = plt.subplots(1, 3, figsize=(15, 3.8), sharex=True)
for ax, res, title in ((axes[0], run.without, "without bypass (Fig. 7)"), (axes[1], run.with_bypass, "with bypass (Fig. 8)")):
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
"""),
("md", """
**What it shows.** Without bypass the arm straightens and stays straight: at every sample on the way
down the monitor fires (Σ|Δq| = 0) and the tool is left behind by the target — the error grows to
metres — until rounding finally folds it, with a jump of more than a radian. With the minus-sign kick
on the elbow the arm folds back the way it came: θ3, θ4, θ5 each stay in their own quadrant, as in the
paper's Fig. 8, every reachable sample is reached to 1e-6, and no joint moves more than about 0.2 rad
between samples (the largest step is right after the fold, where the joint rate is high by nature).

## Tracking cost: FRDM against the Pinocchio DLS reference

Both warm-started from the previous sample, no restarts, on the same path. The damped least-squares
reference needs no bypass here: its damping and the warm start carry it through the straight arm.
"""),
("code", """
dls = ep.dls_tracking(passage, era)
reach = ~passage.unreachable
print(f"FRDM: median {np.median(run.with_bypass.wall_time) * 1e6:6.0f} µs per sample, "
      f"max error {run.with_bypass.position_error[reach].max():.1e} m on reachable samples")
print(f"DLS : median {np.median(dls['wall_time']) * 1e6:6.0f} µs per sample, "
      f"max error {dls['position_error'][reach].max():.1e} m on reachable samples, "
      f"largest joint step {np.abs(np.diff(dls['q'], axis=0)).max():.3f} rad")
"""),
("md", """
## The three kinds of ERA singularity, by SVD

The same analysis as `kinelab singular`: a configuration of each kind, its rank, and the tool motion it
cannot make.
"""),
("code", """
from kinelab import singular
for kind, q in ep.singular_examples(era).items():
    a = singular.analyze(era, q)
    d = a.lost_directions[0]
    print(f"{kind:18s} rank {a.rank}, σ_min/σ_max = {a.singular_values[-1] / a.singular_values[0]:.1e}, "
          f"lost: {100 * d['translation_share']:.0f} % translation, {100 * d['rotation_share']:.0f} % rotation")
"""),
("md", """
The wrist (passage 2) and shoulder (passage 3) paths of the paper are not reproduced yet in kinelab:
see the issue tracker for where that stands.
"""),
]
