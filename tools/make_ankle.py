"""Writes urdf/ankle.urdf and its closures declaration: a two-rod parallel ankle (kinelab's own, #69).

The foot turns about the ankle's pitch (y) then roll (x) axes, both passive; two motors high on the shin turn
cranks about y, and a rod from each crank's end (a ball joint: three revolutes) to a point on the foot's heel drives
the foot — both motors together pitch it, against each other they roll it, as on most current humanoids' ankles.
Two point closures (each rod's end on its heel point); 10 joints, 6 closure equations, 2 motors, 2 idle rod spins.
"""

from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MOTOR = (-0.03, 0.04, 0.25)  # motor 1's axis point on the shin [m] (motor 2 at -y)
CRANK = 0.05  # [m] the crank, pointing back (-x) at zero
HEEL = (-0.05, 0.04, 0.0)  # rod 1's point on the foot, in the foot's frame at the ankle [m] (rod 2 at -y)
ROD = float(np.linalg.norm(np.array([MOTOR[0] - CRANK, MOTOR[1], MOTOR[2]]) - np.array(HEEL)))  # closed at zero
SOLE = 0.06  # [m] the sole below the ankle's axes
MOTOR_RANGE, PITCH, ROLL = 1.0, 0.6, 0.4  # [rad] each joint's range, symmetric

HEADER = f"""<?xml version="1.0"?>
<!--
  ankle: kinelab's own two-rod parallel ankle (#69), kinematics and a stick figure only. The foot turns about the
  ankle's pitch (y) then roll (x) axes at the shin's end (both passive, pitch +-{PITCH}, roll +-{ROLL} rad).
  Two motors on the shin at ({MOTOR[0]}, +-{MOTOR[1]}, {MOTOR[2]}) m turn cranks of {CRANK} m about y
  (+-{MOTOR_RANGE} rad, pointing back at zero); a rod of {ROD:.6f} m runs from each crank's end (a ball joint:
  three revolutes, the last its idle spin) to the heel point ({HEEL[0]}, +-{HEEL[1]}, {HEEL[2]}) m of the foot.
  Both motors together pitch the foot, against each other they roll it. Loops in ankle.closures.yaml (each rod's
  end on its heel point); the motors' angles for a pitch and roll have a closed form (docs/closures.md), the
  reference of tests/robot/test_ankle.py. Written by tools/make_ankle.py.
-->
<robot name="ankle">
  <link name="base_link">
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.03" length="0.4"/></geometry>
      <material name="shin_m"><color rgba="0.5 0.5 0.5 1"/></material></visual>
  </link>
"""


def link(name: str, visual: str = "", mass: float = 0.05) -> str:
    """A link with a small inertia and an optional visual."""
    return (f'  <link name="{name}">\n    <inertial><mass value="{mass}"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" '
            f'ixy="0" ixz="0" iyz="0"/></inertial>\n{visual}  </link>\n')


def revolute(name: str, parent: str, child: str, xyz: str, axis: str, limit: float) -> str:
    """A revolute joint with symmetric limits."""
    return (f'  <joint name="{name}" type="revolute">\n    <parent link="{parent}"/><child link="{child}"/>\n'
            f'    <origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="{axis}"/>\n'
            f'    <limit lower="{-limit}" upper="{limit}" effort="40" velocity="8.0"/>\n  </joint>\n')


def fixed(name: str, parent: str, xyz: str) -> str:
    """A frame (an empty link on a fixed joint)."""
    return (f'  <link name="{name}"/>\n  <joint name="{name}_fixed" type="fixed"><parent link="{parent}"/>'
            f'<child link="{name}"/><origin xyz="{xyz}" rpy="0 0 0"/></joint>\n')


def rod_visual(length: float, color: str) -> str:
    """A rod drawn down -z from its joint."""
    return (f'    <visual><origin xyz="0 0 {-length / 2}"/><geometry><cylinder radius="0.005" length="{length}"/>'
            f'</geometry><material name="rod_{color}"><color rgba="{color}"/></material></visual>\n')


def foot() -> str:
    """The ankle's two passive axes, the foot, its sole and heel points."""
    shape = ('    <visual><origin xyz="0.03 0 -0.06"/><geometry><box size="0.22 0.1 0.02"/></geometry>\n'
             '      <material name="foot_m"><color rgba="0.9 0.6 0.1 1"/></material></visual>\n')
    return (link("ankle_cross") + revolute("ankle_pitch", "base_link", "ankle_cross", "0 0 0", "0 1 0", PITCH)
            + link("foot", shape, 0.5) + revolute("ankle_roll", "ankle_cross", "foot", "0 0 0", "1 0 0", ROLL)
            + fixed("sole", "foot", f"0 0 {-SOLE}")
            + fixed("heel_1", "foot", f"{HEEL[0]} {HEEL[1]} {HEEL[2]}")
            + fixed("heel_2", "foot", f"{HEEL[0]} {-HEEL[1]} {HEEL[2]}"))


def drive(n: int, side: float) -> str:
    """Motor n, its crank and its rod on a ball joint."""
    crank = ('    <visual><origin xyz="-0.025 0 0" rpy="0 1.5707963267948966 0"/>\n'
             '      <geometry><cylinder radius="0.008" length="0.05"/></geometry>\n'
             '      <material name="crank_m"><color rgba="0.85 0.3 0.2 1"/></material></visual>\n')
    text = (link(f"crank_{n}", crank)
            + revolute(f"motor_{n}", "base_link", f"crank_{n}", f"{MOTOR[0]} {side * MOTOR[1]} {MOTOR[2]}", "0 1 0",
                       MOTOR_RANGE))
    links = [f"rod_{n}_ball_1", f"rod_{n}_ball_2", f"rod_{n}"]
    text += link(links[0]) + revolute(f"rod_{n}_a", f"crank_{n}", links[0], f"{-CRANK} 0 0", "0 1 0", np.pi)
    text += link(links[1]) + revolute(f"rod_{n}_b", links[0], links[1], "0 0 0", "1 0 0", np.pi)
    text += link(links[2], rod_visual(ROD, "0.6 0.6 0.6 1"))
    text += revolute(f"rod_{n}_c", links[1], links[2], "0 0 0", "0 0 1", np.pi)
    return text + fixed(f"rod_end_{n}", f"rod_{n}", f"0 0 {-ROD}")


DECLARATION = """# ankle's loops (kinelab's closures declaration, docs/closures.md): each rod's end on its heel point;
# the two motors driven
closures:
  - {frame_a: heel_1, frame_b: rod_end_1, kind: point}
  - {frame_a: heel_2, frame_b: rod_end_2, kind: point}
actuated: [motor_1, motor_2]
"""


def main() -> None:
    body = foot() + drive(1, 1.0) + drive(2, -1.0)
    (ROOT / "urdf" / "ankle.urdf").write_text(HEADER + body + "</robot>\n")
    (ROOT / "urdf" / "ankle.closures.yaml").write_text(DECLARATION)


if __name__ == "__main__":
    main()
