"""Writes urdf/fourbar.urdf and its closures declaration: a planar crank-rocker four-bar (kinelab's own, #69)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
A, B, C, D = 0.10, 0.28, 0.22, 0.30  # crank, coupler, rocker, ground [m]
LIMIT = 6.283185307179586  # [rad] +-2 pi: never met by the mechanism

HEADER = f"""<?xml version="1.0"?>
<!--
  fourbar: kinelab's own planar crank-rocker four-bar (#69), kinematics and a stick figure only. Ground pivots
  A = (0, 0, 0) and D = ({D}, 0, 0) in base_link; crank AB = {A} m driven by crank_joint, coupler BC = {B} m,
  rocker DC = {C} m; every joint turns about z. Grashof: s + l = {A} + {D} = {A + D:.2f} <= p + q = {B} + {C} =
  {B + C:.2f}, the shortest link next to the ground: the crank turns fully, the rocker rocks (Grashof's condition,
  docs/closures.md). The loop is cut at C: frames coupler_tip (end of the coupler) and rocker_tip (end of the
  rocker) must meet in the plane; closures in fourbar.closures.yaml. C's closed form (two circles' intersection)
  is in tests/robot/test_closures.py. Rods 0.1 kg, uniform; joint limits +-2 pi (never met by the mechanism).
  Written by tools/make_fourbar.py.
-->
<robot name="fourbar">
  <link name="base_link"/>
"""

DECLARATION = """# fourbar's loop (kinelab's closures declaration, docs/closures.md): the coupler's end on the
# rocker's, in the plane (x and y of coupler_tip's axes; z is the joints' common axis, held by the tree itself)
closures:
  - {frame_a: coupler_tip, frame_b: rocker_tip, kind: [1, 1, 0, 0, 0, 0]}
actuated: [crank_joint]
"""


def rod(name: str, length: float, color: str = "0.6 0.6 0.6 1", mass: float = 0.1) -> str:
    """A uniform rod along x from its joint: inertia and a cylinder to draw."""
    i = mass * length**2 / 12
    inertia = f'ixx="1e-6" iyy="{i:.6g}" izz="{i:.6g}" ixy="0" ixz="0" iyz="0"'
    shape = f'<cylinder radius="0.008" length="{length}"/>'
    return (f'  <link name="{name}">\n'
            f'    <inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/><inertia {inertia}/></inertial>\n'
            f'    <visual><origin xyz="{length / 2} 0 0" rpy="0 1.5707963267948966 0"/><geometry>{shape}</geometry>'
            f'<material name="{name}_m"><color rgba="{color}"/></material></visual>\n'
            f'  </link>\n')


def joint(name: str, parent: str, child: str, x: float) -> str:
    """A revolute joint about z at (x, 0, 0) of its parent."""
    return (f'  <joint name="{name}" type="revolute">\n'
            f'    <parent link="{parent}"/><child link="{child}"/>\n'
            f'    <origin xyz="{x} 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>\n'
            f'    <limit lower="{-LIMIT}" upper="{LIMIT}" effort="10" velocity="6.0"/>\n'
            f'  </joint>\n')


def tip(name: str, parent: str, x: float) -> str:
    """A frame at (x, 0, 0) of its parent (a fixed joint and an empty link)."""
    return (f'  <link name="{name}"/>\n'
            f'  <joint name="{name}_fixed" type="fixed"><parent link="{parent}"/><child link="{name}"/>'
            f'<origin xyz="{x} 0 0" rpy="0 0 0"/></joint>\n')


def main() -> None:
    body = (rod("crank", A, "0.85 0.3 0.2 1") + joint("crank_joint", "base_link", "crank", 0.0)
            + rod("coupler", B) + joint("coupler_joint", "crank", "coupler", A) + tip("coupler_tip", "coupler", B)
            + rod("rocker", C, "0.2 0.4 0.85 1") + joint("rocker_joint", "base_link", "rocker", D)
            + tip("rocker_tip", "rocker", C))
    (ROOT / "urdf" / "fourbar.urdf").write_text(HEADER + body + "</robot>\n")
    (ROOT / "urdf" / "fourbar.closures.yaml").write_text(DECLARATION)


if __name__ == "__main__":
    main()
