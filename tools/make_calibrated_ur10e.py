"""Writes ``urdf/ur10e_calibrated.urdf``: ``python tools/make_calibrated_ur10e.py``.

The UR10e's nominal standard Denavit–Hartenberg table (Universal Robots' published kinematic parameters) with a
calibration of the size a factory calibration applies: every joint's zero offset and twist α changed by up to a few
milliradians, the lengths a and d by up to a few tenths of a millimetre (the numbers below, chosen by hand within
those sizes; not any one robot's). Such a calibration leaves no two axes exactly parallel and none meeting: no
closed form of docs/analytic.md and no 1-D search class fits the arm, which is the point of registering it (#41).
Each joint turns about the z axis of the frame before it; the fixed part of row i (Tz(d) Tx(a) Rx(α)) and the
next joint's offset Rz(θ offset) make the next joint's origin, as in urdf/xarm6.urdf.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

PI = np.pi
# nominal UR10e: (θ offset [rad], d [m], α [rad], a [m])
NOMINAL = [(0.0, 0.1807, PI / 2, 0.0), (0.0, 0.0, 0.0, -0.6127), (0.0, 0.0, 0.0, -0.57155),
           (0.0, 0.17415, PI / 2, 0.0), (0.0, 0.11985, -PI / 2, 0.0), (0.0, 0.11655, 0.0, 0.0)]
# the calibration: (δθ [rad], δd [m], δα [rad], δa [m]) per joint
DELTA = [(0.0, 0.18e-3, 0.6e-3, 0.12e-3), (2.1e-3, 0.0, 3.4e-3, 0.21e-3), (-1.7e-3, 0.0, -2.2e-3, -0.33e-3),
         (0.9e-3, -0.27e-3, 1.1e-3, -0.09e-3), (-1.2e-3, 0.15e-3, -1.9e-3, 0.14e-3), (0.0, 0.08e-3, 0.0, 0.0)]
LIMITS = [(-2 * PI, 2 * PI)] * 2 + [(-PI, PI)] + [(-2 * PI, 2 * PI)] * 3


def table() -> list[tuple[float, float, float, float]]:
    """The calibrated table: nominal plus delta, row by row."""
    return [tuple(n + d for n, d in zip(row, delta, strict=True)) for row, delta in zip(NOMINAL, DELTA, strict=True)]


def origin(fixed: tuple[float, float, float, float], offset: float) -> tuple[np.ndarray, np.ndarray]:
    """(xyz, rpy) of Tz(d)·Tx(a)·Rx(α)·Rz(offset): a row's fixed part followed by the next joint's zero offset."""
    _, d, alpha, a = fixed
    R = pin.utils.rotate("x", alpha) @ pin.utils.rotate("z", offset)
    return np.array([a, 0.0, d]), np.asarray(pin.rpy.matrixToRpy(R), dtype=float)


HEADER = """<?xml version="1.0"?>
<!--
  UR10e with a factory-size calibration, for kinelab (#41): kinematics only, written by
  tools/make_calibrated_ur10e.py from the UR10e's published standard DH table plus the calibration that script
  lists (zero offsets and twists changed by up to 3.4 mrad, lengths by up to 0.33 mm; chosen within a factory
  calibration's sizes, not any one robot's). Calibrated table (lengths in metres):

    i   theta offset [rad]   d [m]   alpha [rad]   a [m]
{rows}

  No two axes are exactly parallel (axes 2 and 3 of the nominal arm are off by 3.4 mrad, 3 and 4 by 2.2 mrad)
  and none meet (axes 1 and 2, 4 and 5, 5 and 6 pass 0.09-0.14 mm apart): neither a closed form nor the 1-D
  search fits; kinelab answers it by the general 6R elimination, certified (docs/analytic.md).
  tests/robot/test_dh_arms.py checks Pinocchio's FK of this file against the table. Limits: +-360 deg, the elbow
  +-180 deg. No meshes, no inertias.
-->
<robot name="{name}">
  <link name="base_link"/>
"""
JOINT = """  <link name="link{i}"/>
  <joint name="joint{i}" type="revolute">
    <parent link="{parent}"/><child link="link{i}"/>
    <origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="0 0 1"/>
    <limit lower="{lower!r}" upper="{upper!r}" effort="330" velocity="2.09"/>
  </joint>
"""
FLANGE = """  <link name="flange"/>
  <joint name="flange_joint" type="fixed">
    <parent link="link6"/><child link="flange"/>
    <origin xyz="{xyz}" rpy="{rpy}"/>
  </joint>
</robot>
"""


def _numbers(values: np.ndarray) -> str:
    return " ".join(repr(float(v)) for v in values)


def urdf(rows: list[tuple[float, float, float, float]] | None = None, header: str = HEADER,
         limits: list[tuple[float, float]] = LIMITS, name: str = "ur10e_calibrated") -> str:
    """The text of a URDF file of the standard DH table ``rows`` (default: the calibrated UR10e), its comment
    ``header`` (a format with {rows} and {name}), joint limits [rad] and robot name."""
    rows = table() if rows is None else rows
    lines = "\n".join(f"    {i}   {t:+.6f}   {d:.5f}   {al:+.7f}   {a:+.5f}" for i, (t, d, al, a) in enumerate(rows, 1))
    text = header.format(rows=lines, name=name)
    previous = (0.0, 0.0, 0.0, 0.0)
    for i, (row, (lower, upper)) in enumerate(zip(rows, limits, strict=True)):
        xyz, rpy = origin(previous, row[0])
        text += JOINT.format(i=i + 1, parent="base_link" if i == 0 else f"link{i}", xyz=_numbers(xyz),
                             rpy=_numbers(rpy), lower=lower, upper=upper)
        previous = row
    xyz, rpy = origin(previous, 0.0)
    return text + FLANGE.format(xyz=_numbers(xyz), rpy=_numbers(rpy))


if __name__ == "__main__":
    out = Path(__file__).resolve().parents[1] / "urdf" / "ur10e_calibrated.urdf"
    out.write_text(urdf())
    print(f"wrote {out}")
