"""Writes urdf/delta.urdf and its closures declaration: a delta robot in Clavel's geometry (kinelab's own, #69).

Each leg i (at φ_i = 0, 120, 240 deg about z): the motor's revolute joint at radius R on the base, axis tangent (y
of the leg's frame); the upper arm of length LA along x, turned down by the motor's angle; the forearm — the centre
line of the real parallelogram, length LB — hung from the elbow by a ball joint (three revolutes: y, x, then z along
the forearm, its idle spin). Leg 1 carries the platform by a second ball joint at its wrist; legs 2 and 3 end in a
point that a closure holds on the platform's joint. What the parallelograms do — keep the platform parallel to the
base — is a closure of its own (the platform's orientation on the base's). 15 joints, 9 closure equations, the 3
motors driven, 3 idle spins: the platform's position is the three spheres' intersection of the closed form.
"""

from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
R, LA, LB, RP = 0.10, 0.20, 0.45, 0.04  # base radius, upper arm, forearm, platform radius [m]
PHI = (0.0, 2 * np.pi / 3, 4 * np.pi / 3)
MOTOR = (-0.6, 1.4)  # [rad] the motors' range (0: the upper arm horizontal, positive: down)
PASSIVE = 6.283185307179586  # ±2π: an ideal ball joint has no stop, and one at ±π cuts off branches across it

HEADER = f"""<?xml version="1.0"?>
<!--
  delta: kinelab's own delta robot in Clavel's geometry (#69), kinematics and a stick figure only. Three legs at
  0, 120 and 240 deg about z: the motor at radius R = {R} m (axis tangent), upper arm LA = {LA} m, forearm LB = {LB} m
  (the parallelogram's centre line, hung by ball joints: three revolutes each, the last its idle spin), the platform's
  joints at radius r = {RP} m. Leg 1 carries the platform; legs 2 and 3 end in points held on the platform's
  joints, and the platform's orientation is held on the base's (the parallelograms' work): closures in
  delta.closures.yaml, 15 joints, 9 closure equations, the 3 motors driven, 3 idle spins. The
  platform's position has a closed form (three spheres' intersection, docs/closures.md), the reference of
  tests/robot/test_delta.py. Motors {MOTOR[0]}..{MOTOR[1]} rad (0: arm horizontal, positive: down); passive joints
  +-2 pi (ball joints have no stop; a stop at +-pi would cut off the assemblies across it). Links 0.05-0.2 kg.
  Written by tools/make_delta.py.
-->
<robot name="delta">
  <link name="base_link">
    <visual><geometry><cylinder radius="{R + 0.02}" length="0.01"/></geometry>
      <material name="base_m"><color rgba="0.3 0.3 0.3 1"/></material></visual>
  </link>
"""


def link(name: str, length: float = 0.0, axis: str = "x", mass: float = 0.05, color: str = "0.6 0.6 0.6 1") -> str:
    """A link with a small inertia and, with a length, a rod to draw along +x or -z from its joint."""
    rod = ""
    if length:
        xyz, rpy = (f"{length / 2} 0 0", "0 1.5707963267948966 0") if axis == "x" else (f"0 0 {-length / 2}", "0 0 0")
        rod = (f'    <visual><origin xyz="{xyz}" rpy="{rpy}"/><geometry><cylinder radius="0.006" length="{length}"/>'
               f'</geometry><material name="{name}_m"><color rgba="{color}"/></material></visual>\n')
    return (f'  <link name="{name}">\n'
            f'    <inertial><mass value="{mass}"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
            f'</inertial>\n{rod}  </link>\n')


def revolute(name: str, parent: str, child: str, xyz: str, axis: str, limits: tuple[float, float],
             rpy: str = "0 0 0") -> str:
    """A revolute joint."""
    return (f'  <joint name="{name}" type="revolute">\n'
            f'    <parent link="{parent}"/><child link="{child}"/>\n'
            f'    <origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>\n'
            f'    <limit lower="{limits[0]}" upper="{limits[1]}" effort="20" velocity="8.0"/>\n'
            f'  </joint>\n')


def fixed(name: str, parent: str, child: str, xyz: str, rpy: str = "0 0 0") -> str:
    """A fixed joint and its empty child link (a frame)."""
    return (f'  <link name="{child}"/>\n  <joint name="{name}" type="fixed"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/></joint>\n')


def ball(prefix: str, parent: str, child: str, xyz: str, axes: tuple[str, str, str]) -> str:
    """Three revolutes about ``axes`` at one point: a ball joint (its last axis the child's spin)."""
    passive = (-PASSIVE, PASSIVE)
    names = [f"{prefix}_{s}" for s in "abc"]
    links = [f"{prefix}_1", f"{prefix}_2", child]
    text = link(links[0]) + revolute(names[0], parent, links[0], xyz, axes[0], passive)
    text += link(links[1]) + revolute(names[1], links[0], links[1], "0 0 0", axes[1], passive)
    return text + revolute(names[2], links[1], child, "0 0 0", axes[2], passive)


def leg(i: int) -> str:
    """Leg i+1: the motor, the upper arm, the elbow's ball, the forearm; leg 1 then its wrist's ball and the
    platform, the others a point at the forearm's end."""
    n, phi = i + 1, PHI[i]
    text = (link(f"upper_arm_{n}", LA, "x", 0.2, "0.85 0.3 0.2 1")
            + revolute(f"motor_{n}", "base_link", f"upper_arm_{n}", f"{R * np.cos(phi)} {R * np.sin(phi)} 0", "0 1 0",
                       MOTOR, f"0 0 {phi}")
            + link(f"forearm_{n}", LB, "z", 0.1)
            + ball(f"elbow_{n}", f"upper_arm_{n}", f"forearm_{n}", f"{LA} 0 0", ("0 1 0", "1 0 0", "0 0 1")))
    if n == 1:
        return text + link("platform", mass=0.1) + ball("wrist_1", "forearm_1", "platform", f"0 0 {-LB}",
                                                        ("1 0 0", "0 1 0", "0 0 1"))
    return text + fixed(f"leg_end_{n}_fixed", f"forearm_{n}", f"leg_end_{n}", f"0 0 {-LB}")


def platform() -> str:
    """The platform's centre frame (leg 1's wrist sits at its first joint) and its joints for legs 2 and 3."""
    text = (f'  <link name="platform_centre">\n    <visual><geometry><cylinder radius="{RP + 0.01}" length="0.008"/>'
            f'</geometry>\n      <material name="platform_m"><color rgba="0.9 0.6 0.1 1"/></material></visual>\n'
            f'  </link>\n  <joint name="platform_centre_fixed" type="fixed"><parent link="platform"/>'
            f'<child link="platform_centre"/><origin xyz="{-RP} 0 0" rpy="0 0 0"/></joint>\n')
    for i in (1, 2):
        phi = PHI[i]
        text += fixed(f"platform_joint_{i + 1}_fixed", "platform_centre", f"platform_joint_{i + 1}",
                      f"{RP * np.cos(phi)} {RP * np.sin(phi)} 0", f"0 0 {phi}")
    return text


DECLARATION = """# delta's loops (kinelab's closures declaration, docs/closures.md): legs 2 and 3 end on the
# platform that leg 1 carries, and the platform stays parallel to the base (the parallelograms' work);
# the three motors driven
closures:
  - {frame_a: platform_joint_2, frame_b: leg_end_2, kind: point}
  - {frame_a: platform_joint_3, frame_b: leg_end_3, kind: point}
  - {frame_a: base_link, frame_b: platform_centre, kind: [0, 0, 0, 1, 1, 1]}
actuated: [motor_1, motor_2, motor_3]
"""


def main() -> None:
    body = "".join(leg(i) for i in range(3)) + platform()
    (ROOT / "urdf" / "delta.urdf").write_text(HEADER + body + "</robot>\n")
    (ROOT / "urdf" / "delta.closures.yaml").write_text(DECLARATION)


if __name__ == "__main__":
    main()
