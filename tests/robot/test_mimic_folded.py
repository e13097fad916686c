"""#69 (loading): a whole robot whose mimic joints Pinocchio cannot build (romeo, talos_full_v2: a mimic's leader
outside the tree Pinocchio builds them in) loads with those joints as plain joints and their factors read from the
file (checked here against the XML itself), and every whole-body step holds them: a start off them is brought on,
and without the folded couplings the same step leaves them apart."""

import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import kinelab
from kinelab import FrameTask, PostureTask, WholeBody
from kinelab.robot import catalog

ERD = catalog.erd_robots_dir()
TALOS_FULL = (ERD / "talos_data" / "robots" / "talos_full_v2.urdf") if ERD else None


def file_mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    """follower → (leader, multiplier, offset) as the URDF's XML says (URDF's defaults 1 and 0)."""
    out = {}
    for joint in ET.parse(path).getroot().iter("joint"):
        m = joint.find("mimic")
        if m is not None:
            out[joint.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
    return out


def load_quietly(source: object, **kw: object) -> kinelab.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return kinelab.load(source, **kw)  # type: ignore[arg-type]


def index_q(robot: kinelab.Robot, name: str) -> int:
    return robot.model.joints[robot.model.getJointId(name)].idx_q


@pytest.mark.skipif(ERD is None, reason="example-robot-data is not installed")
@pytest.mark.parametrize("name, count", [("romeo", 22), ("talos_full", 12)])
def test_the_folded_mimics_are_the_files(name: str, count: int) -> None:
    robot = load_quietly(TALOS_FULL, floating=True) if name == "talos_full" else load_quietly(name)
    declared = file_mimics(Path(robot.source or ""))
    assert len(robot.mimics) == count
    for m in robot.mimics:
        assert declared[m.name] == (m.leader, m.multiplier, m.offset)
        joint = robot.model.joints[robot.model.getJointId(m.name)]
        assert joint.nq == 1 and (m.lower, m.upper) == (robot.lower[joint.idx_q], robot.upper[joint.idx_q])


def test_a_load_says_the_mimics_are_held() -> None:
    with pytest.warns(UserWarning, match="held as couplings by every whole-body step and solve"):
        kinelab.load(TALOS_FULL, floating=True)


@pytest.mark.skipif(ERD is None, reason="example-robot-data is not installed")
def test_the_step_holds_the_folded_mimics(monkeypatch: pytest.MonkeyPatch) -> None:
    """TALOS with its grippers' mimics: a start with both grippers' leaders moved (the followers left at zero) is
    brought on, and 50 steps with a posture pulling every gripper joint elsewhere keep each follower at multiplier ·
    leader + offset (1e-9). Without the folded couplings the posture pulls the followers off (> 0.05 rad)."""
    robot = load_quietly(TALOS_FULL, floating=True)
    mimics = robot.mimics
    q0 = robot.neutral()
    for leader in {m.leader for m in robot.mimics}:
        q0[index_q(robot, leader)] = -0.4
    pull = q0.copy()
    for m in robot.mimics:
        pull[index_q(robot, m.name)] = 0.5 * (m.lower + m.upper) + 0.1
    hand = "gripper_left_base_link"

    def run() -> float:
        problem = WholeBody(robot, [FrameTask(hand, robot.frame_placement(q0, hand)), PostureTask(pull, weight=1.0)])
        q, worst = q0, 0.0
        for _ in range(50):
            result = problem.step(q, 0.01)
            assert result.solved, result.status
            q = result.q
            worst = max(worst, max(abs(q[index_q(robot, m.name)] - m.multiplier * q[index_q(robot, m.leader)]
                                       - m.offset) for m in mimics))
        return worst

    assert run() <= 1e-9
    monkeypatch.setattr(robot, "mimics", ())
    assert run() > 0.05
