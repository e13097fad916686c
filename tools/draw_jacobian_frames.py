"""Draw docs/jacobians.png: the Panda at one configuration, the base axes at the origin and the tool frame's at the
tool point, and for joint 3's unit velocity the two points whose velocities the Jacobians' linear parts are — the
tool point (local and local world-aligned) and the body point at the world's origin (world).

    python tools/draw_jacobian_frames.py [--out docs/jacobians.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import kinelab
from kinelab.view.scene import chain_points

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "jacobians.png"))
    args = parser.parse_args()
    panda = kinelab.load("panda")
    q = panda.random_q(7)
    oMtool = panda.fk(q)
    R, p = oMtool.rotation, oMtool.translation
    J = panda.jacobian_local_world_aligned(q)
    k = 2
    v_tool, omega = J[:3, k], J[3:, k]
    v_origin = v_tool - np.cross(omega, p)
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    pts = np.array(chain_points(panda, q))
    ax.plot(*pts.T, "-o", color="0.3", lw=3, ms=4, label="the Panda (joint origins)")
    for axis, colour in zip(np.eye(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
        ax.quiver(0, 0, 0, *(0.25 * axis), color=colour, lw=1.5)
        ax.quiver(*p, *(0.15 * (R @ axis)), color=colour, lw=1.5)
    ax.quiver(*p, *(0.3 * v_tool / np.linalg.norm(v_tool)), color="navy", lw=3,
              label="tool point's velocity: linear part of 'local_world_aligned' (base axes) and 'local' (tool axes)")
    ax.quiver(0, 0, 0, *(0.3 * v_origin / np.linalg.norm(v_origin)), color="crimson", lw=3,
              label="body point at the origin's velocity: linear part of 'world'")
    ax.text(0, 0, -0.08, "base (world) axes", fontsize=8)
    ax.text(*(p + np.array([0, 0, 0.08])), "tool frame axes", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_box_aspect((1, 1, 1))
    lim = np.abs(np.vstack([pts, [[0.3, 0.3, 0.3]]])).max()
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_zlim(0, 2 * lim)
    ax.set_title("Panda, joint 3 turning: where each Jacobian's linear part is measured", fontsize=10)
    ax.legend(loc="lower center", fontsize=7, bbox_to_anchor=(0.5, -0.12))
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
