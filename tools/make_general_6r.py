"""Writes ``urdf/general6r.urdf``: ``python tools/make_general_6r.py``.

kinelab's own general 6R arm (#41): a standard Denavit–Hartenberg table chosen by hand so that no two joint axes
are parallel and none meet — twists α between 0.5 and 1.3 rad, every link with both a length a and an offset d —
while the arm keeps an industrial arm's proportions (a 1.3 m reach, a shoulder, an elbow and a compact wrist).
No closed form and no 1-D search class fits it: it is the arm the general 6R elimination (docs/analytic.md) is
shown on, and a 16-branch arm in the making (the count varies with the pose). Kinematics only.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from make_calibrated_ur10e import urdf

PI = np.pi
# (θ offset [rad], d [m], α [rad], a [m]) per joint
TABLE = [(0.0, 0.30, 1.10, 0.08), (0.35, 0.06, -0.55, 0.52), (-0.20, -0.04, 0.80, 0.42),
         (0.0, 0.24, -1.25, 0.05), (0.10, 0.07, 0.95, 0.06), (0.0, 0.11, 0.0, 0.02)]
LIMITS = [(-PI, PI)] * 6
HEADER = """<?xml version="1.0"?>
<!--
  general6r: kinelab's own general 6R arm (#41), kinematics only, written by tools/make_general_6r.py from the
  standard Denavit-Hartenberg table below (chosen by hand: twists between 0.5 and 1.3 rad, every link offset in
  both a and d, so that no two joint axes are parallel and none meet). No closed form and no 1-D search class
  fits it; kinelab answers every branch by the general 6R elimination, certified (docs/analytic.md).
  tests/robot/test_dh_arms.py checks Pinocchio's FK of this file against the table. Limits: +-180 deg. No
  meshes, no inertias.

    i   theta offset [rad]   d [m]   alpha [rad]   a [m]
{rows}
-->
<robot name="{name}">
  <link name="base_link"/>
"""

if __name__ == "__main__":
    out = Path(__file__).resolve().parents[1] / "urdf" / "general6r.urdf"
    out.write_text(urdf(TABLE, HEADER, LIMITS, "general6r"))
    print(f"wrote {out}")
