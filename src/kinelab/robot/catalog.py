"""Registered robot names: the URDFs bundled in ``urdf/`` and the serial arms of example-robot-data.

example-robot-data 6 ships its URDFs and meshes as data files (under ``share/example-robot-data``)
but no Python loader, so the ``robots/`` directory is found from the installed package's file list.
"""

from __future__ import annotations

import functools
import sys
from dataclasses import dataclass
from pathlib import Path

from kinelab.errors import RobotNotFoundError


@dataclass(frozen=True)
class Entry:
    """One registered robot: where its URDF is, which frames are its tool and base (or which SRDF group
    gives them), and where the choice comes from."""

    name: str
    source: str  # "kinelab" (bundled) or "example-robot-data"
    relpath: str  # below the bundled urdf/ directory or the example-robot-data robots/ directory
    tool: str | None
    description: str
    base: str | None = None  # None: the URDF root
    srdf: str | None = None  # below the same directory as relpath
    group: str | None = None  # the SRDF group that gives base and tool
    display: tuple[float, ...] | None = None  # a well-conditioned pose to show [rad, m] (None: computed)
    whole: bool = False  # the name loads the whole robot (a humanoid, a two-armed robot, a quadruped), not a chain
    floating: bool = False  # the whole robot's base floats (a free-flyer at its root)
    hands: tuple[str, ...] = ()  # a whole robot's frames a user moves first (teach's targets, the notebook's)
    feet: tuple[str, ...] = ()  # a whole robot's frames that stand on the floor (held where they are)
    closures: str | None = None  # its closures declaration, below the same directory as relpath

    @property
    def chain(self) -> str:
        """Where the chain comes from, in words (``kinelab robots``); a whole robot's base."""
        if self.whole:
            return "the whole robot, " + ("free-flyer base" if self.floating else "fixed base")
        if self.group:
            return f"SRDF group {self.group!r} of {Path(self.srdf or '').name}"
        return f"{self.base or 'root'} → {self.tool}"


BUNDLED = (
    # display poses: the paper's target (stanford), an arm bent at every joint (era), the youBot's arm bent
    # forward on its platform at the origin; σ_min/σ_max of the scaled Jacobian 0.11, 0.12 and 0.045
    Entry("stanford", "kinelab", "stanford.urdf", "tool",
          "Stanford arm RRPRRR, in the frames of Lomovtseva & Chelnokov's biquaternion paper",
          display=(0.34906585, 0.6981317, 0.3, -0.61086524, 1.04719755, -0.78539816)),
    Entry("era", "kinelab", "era.urdf", "tool",
          "European Robotic Arm, 7R symmetric, approximate geometry (Danilov et al.'s FRDM paper)",
          display=(0.3, 0.5, -0.6, -1.3, 0.6, 0.4, 0.2)),
    Entry("youbot", "kinelab", "youbot.urdf", "tool",
          "KUKA youBot arm on its planar base: platform_x, platform_y, platform_yaw, arm_joint_1..5 (Kapustina's "
          "X_C, Y_C, theta, theta1..theta5)",
          display=(0.0, 0.0, 0.0, 0.3, 0.5, 0.9, 0.7, 0.0)),
    Entry("xarm6", "kinelab", "xarm6.urdf", "link_eef",
          "UFACTORY xArm6, 6R without three axes meeting, from the maker's DH table"),
    Entry("crx10ia", "kinelab", "crx10ia.urdf", "flange",
          "FANUC CRX-10iA, 6R cuspidal cobot (up to 16 branches), from its published dimensions"),
    Entry("ur10e_calibrated", "kinelab", "ur10e_calibrated.urdf", "flange",
          "UR10e with a factory-size calibration (axes off parallel by mrad): a general 6R, no closed form"),
    Entry("general6r", "kinelab", "general6r.urdf", "flange",
          "kinelab's own general 6R arm: no two axes parallel or meeting (every branch by the elimination)"),
)

CLOSED = (  # bundled robots that close loops (kinelab.robot.closures): whole robots, their loops declared beside
    Entry("fourbar", "kinelab", "fourbar.urdf", None,
          "planar crank-rocker four-bar, one loop (closed at the coupler's end), the crank driven",
          whole=True, closures="fourbar.closures.yaml", hands=("coupler_tip",)),
    Entry("delta", "kinelab", "delta.urdf", None,
          "delta robot in Clavel's geometry: three motors, forearms on ball joints, the platform kept parallel",
          whole=True, closures="delta.closures.yaml", hands=("platform_centre",)),
    Entry("ankle", "kinelab", "ankle.urdf", None,
          "two-rod parallel ankle: pitch and roll of the foot driven by two motors on the shin through two rods",
          whole=True, closures="ankle.closures.yaml", hands=("sole",)),
    Entry("cassie", "kinelab", "cassie.xml", None,
          "Agility Robotics Cassie, both legs (MuJoCo Menagerie's MJCF, reduced): five motors a leg, the achilles "
          "and plantar rods closing two loops a leg (MJCF <connect> equalities), the springs passive",
          whole=True, floating=True, hands=("left-foot",), feet=("right-foot",)),
)

ERD_ARMS = (
    Entry("panda", "example-robot-data", "panda_description/urdf/panda.urdf", "panda_hand_tcp",
          "Franka Emika Panda, 7R, fingers locked"),
    Entry("ur3", "example-robot-data", "ur_description/urdf/ur3_robot.urdf", "tool0", "Universal Robots UR3, 6R"),
    Entry("ur5", "example-robot-data", "ur_description/urdf/ur5_robot.urdf", "tool0", "Universal Robots UR5, 6R"),
    Entry("ur10", "example-robot-data", "ur_description/urdf/ur10_robot.urdf", "tool0", "Universal Robots UR10, 6R"),
    Entry("kinova", "example-robot-data", "kinova_description/robots/kinova.urdf", "j2s6s200_end_effector",
          "Kinova Jaco j2s6s200, 6R with three continuous joints, fingers locked"),
    Entry("xarm7", "example-robot-data", "xarm_description/urdf/xarm7.urdf", "link_eef", "UFACTORY xArm7, 7R"),
    Entry("z1", "example-robot-data", "z1_description/urdf/z1.urdf", "gripperStator",
          "Unitree Z1, 6R, gripper locked"),
    Entry("so101", "example-robot-data", "so_arm_description/urdf/so101.urdf", "gripper_frame_link",
          "SO-101 arm, 5R, gripper locked"),
    Entry("finger_edu", "example-robot-data", "finger_edu_description/robots/finger_edu.urdf", "finger_tip_link",
          "TriFinger EDU finger, 3R"),
    Entry("baxter_left", "example-robot-data", "baxter_description/urdf/baxter.urdf", "left_gripper",
          "Rethink Baxter, left arm from the torso, 7R", base="torso"),
    Entry("baxter_right", "example-robot-data", "baxter_description/urdf/baxter.urdf", "right_gripper",
          "Rethink Baxter, right arm from the torso, 7R", base="torso"),
    Entry("pr2_left", "example-robot-data", "pr2_description/urdf/pr2.urdf", None,
          "PR2, left arm from the torso lift link, 7R", srdf="pr2_description/srdf/pr2_manipulation.srdf",
          group="left_arm"),
    Entry("pr2_right", "example-robot-data", "pr2_description/urdf/pr2.urdf", None,
          "PR2, right arm from the torso lift link, 7R", srdf="pr2_description/srdf/pr2_manipulation.srdf",
          group="right_arm"),
    Entry("talos_left", "example-robot-data", "talos_data/robots/talos_full_v2.urdf", None,
          "PAL TALOS humanoid, left arm from the torso, 7R", srdf="talos_data/srdf/talos.srdf", group="l_arm"),
    Entry("talos_right", "example-robot-data", "talos_data/robots/talos_full_v2.urdf", None,
          "PAL TALOS humanoid, right arm from the torso, 7R", srdf="talos_data/srdf/talos.srdf", group="r_arm"),
    Entry("tiago", "example-robot-data", "tiago_description/robots/tiago.urdf", "arm_tool_link",
          "PAL TIAGo, arm from the torso lift link, 7R", base="torso_lift_link"),
    Entry("tiago_pro", "example-robot-data", "tiago_pro_description/robots/tiago_pro.urdf", "arm_right_tool_link",
          "PAL TIAGo Pro, right arm from the torso lift link, 7R", base="torso_lift_link"),
)


def _whole(name: str, relpath: str, description: str, srdf: str | None = None, floating: bool = True,
           hands: tuple[str, ...] = (), feet: tuple[str, ...] = (), paws: tuple[str, ...] = ()) -> Entry:
    """A whole robot's entry; a quadruped's ``paws``: its first moved (a hand), the other three on the floor."""
    if paws:
        hands, feet = paws[:1], paws[1:]
    return Entry(name, "example-robot-data", relpath, None, description, srdf=srdf, whole=True, floating=floating,
                 hands=hands, feet=feet)


# the whole robots of example-robot-data: humanoids and quadrupeds on a free-flyer, two-armed robots on a fixed base
ERD_WHOLE = (
    _whole("talos", "talos_data/robots/talos_reduced.urdf", "PAL TALOS humanoid, 32 joints (reduced: no fingers)",
           "talos_data/srdf/talos.srdf", hands=("gripper_left_base_link", "gripper_right_base_link"),
           feet=("left_sole_link", "right_sole_link")),
    _whole("g1", "g1_description/urdf/g1_29dof_rev_1_0.urdf", "Unitree G1 humanoid, 29 joints",
           hands=("left_wrist_yaw_link", "right_wrist_yaw_link"),
           feet=("left_ankle_roll_link", "right_ankle_roll_link")),
    _whole("romeo", "romeo_description/urdf/romeo.urdf", "Aldebaran Romeo humanoid",  # its SRDF: other joints
           hands=("LWristYawLink", "RWristYawLink"), feet=("l_sole", "r_sole")),
    _whole("icub", "icub_description/robots/icub_reduced.urdf", "iCub humanoid (reduced)",
           "icub_description/srdf/icub.srdf", hands=("l_hand", "r_hand"), feet=("l_sole", "r_sole")),
    _whole("baxter", "baxter_description/urdf/baxter.urdf", "Rethink Baxter, both arms and the head, fixed base",
           floating=False, hands=("left_gripper", "right_gripper")),
    _whole("pr2", "pr2_description/urdf/pr2.urdf", "PR2, both arms, torso and head, fixed base",
           "pr2_description/srdf/pr2.srdf", floating=False, hands=("l_gripper_tool_frame", "r_gripper_tool_frame")),
    _whole("solo12", "solo_description/robots/solo12.urdf", "Solo-12 quadruped",  # its SRDF names missing groups
           paws=("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")),
    _whole("anymal", "anymal_b_simple_description/robots/anymal.urdf", "ANYmal B quadruped",
           "anymal_b_simple_description/srdf/anymal.srdf", paws=("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT")),
    _whole("go2", "go2_description/urdf/go2.urdf", "Unitree Go2 quadruped", "go2_description/srdf/go2.srdf",
           paws=("FL_foot", "FR_foot", "RL_foot", "RR_foot")),
    _whole("hyq", "hyq_description/robots/hyq_no_sensors.urdf", "IIT HyQ quadruped",
           paws=("lf_foot", "rf_foot", "lh_foot", "rh_foot")),
)

ENTRIES = {e.name: e for e in BUNDLED + ERD_ARMS + ERD_WHOLE + CLOSED}


def bundled_urdf_dir() -> Path:
    """The directory holding kinelab's own URDFs (inside the wheel, or ``urdf/`` of a checkout)."""
    package = Path(__file__).resolve().parents[1]  # src/kinelab (a checkout) or site-packages/kinelab
    for candidate in (package / "urdf", package.parents[1] / "urdf"):
        if (candidate / "stanford.urdf").is_file():
            return candidate
    raise FileNotFoundError(f"kinelab's bundled URDFs are missing (looked in {package / 'urdf'})")


@functools.cache
def erd_share_dir() -> Path | None:
    """``.../share`` that holds ``example-robot-data/robots``, or None if the package is absent."""
    for entry in sys.path:  # where its wheel puts it (cmeel's prefix): a few stat calls, not its file list
        share = Path(entry or ".") / "cmeel.prefix" / "share"
        if (share / "example-robot-data" / "robots").is_dir():
            return share
    import importlib.metadata  # elsewhere (another installer's layout): its file list says

    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in files:
        parts = Path(str(f)).parts
        if "example-robot-data" in parts and "robots" in parts:
            full = Path(f.locate()).resolve()
            i = len(full.parts) - 1 - full.parts[::-1].index("example-robot-data")
            return Path(*full.parts[:i])
    return None


def erd_robots_dir() -> Path | None:
    """The example-robot-data ``robots/`` directory, or None if the package is not installed."""
    share = erd_share_dir()
    return share / "example-robot-data" / "robots" if share else None


def package_dirs() -> list[str]:
    """Directories under which ``package://NAME/...`` mesh paths resolve (for Pinocchio and yourdfpy)."""
    dirs = []
    share = erd_share_dir()
    if share:
        dirs += [str(share), str(share / "example-robot-data" / "robots")]
    return dirs


def closures_path(entry: Entry) -> Path | None:
    """The entry's closures declaration (YAML), or None."""
    if entry.closures is None:
        return None
    root = bundled_urdf_dir() if entry.source == "kinelab" else erd_robots_dir()
    return None if root is None else root / entry.closures


def srdf_path(entry: Entry) -> Path | None:
    """The entry's SRDF file, or None."""
    if entry.srdf is None:
        return None
    root = bundled_urdf_dir() if entry.source == "kinelab" else erd_robots_dir()
    return None if root is None else root / entry.srdf


def _maker_words() -> dict[str, str]:
    """Words of the descriptions that name one robot alone ("franka", "jaco", "xarm7") → that robot."""
    seen: dict[str, set[str]] = {}
    for e in ENTRIES.values():
        for word in e.description.replace(",", " ").lower().split():
            seen.setdefault(word, set()).add(e.name)
    return {word: next(iter(robots)) for word, robots in seen.items() if len(robots) == 1 and len(word) > 3}


def names() -> list[str]:
    """All registered robot names, bundled ones first."""
    return list(ENTRIES)


MAX_PATH = 4096  # [characters] a path longer than Linux's PATH_MAX names no file


def resolve(name_or_path: str | Path) -> tuple[Path, Entry | None]:
    """Turn a registered name or a URDF path into (urdf path, catalogue entry or None); an entry's SRDF
    lies below the same directory as its URDF (:func:`srdf_path`)."""
    key = str(name_or_path)
    entry = ENTRIES.get(key)
    if entry is not None:
        root = bundled_urdf_dir() if entry.source == "kinelab" else erd_robots_dir()
        if root is None:
            raise RobotNotFoundError(key + " (example-robot-data is not installed)", names())
        return root / entry.relpath, entry
    path = Path(key)
    try:
        exists = path.exists()
    except OSError:  # a name longer than the system takes for a file (ENAMETOOLONG)
        exists = False
    if (path.suffix.lower() in {".urdf", ".xml"} or exists or "/" in key) and len(key) <= MAX_PATH:
        return path, None
    raise RobotNotFoundError(key, names(), _maker_words())
