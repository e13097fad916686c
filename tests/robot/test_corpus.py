"""The corpus: every URDF example-robot-data ships. Each loads with a documented tool, or is refused with a
message naming the file or the element; every loaded chain agrees with yourdfpy and with finite differences.

The tool of a file whose tree branches is the leaf reached through the most movable joints with no mimic
joint among them (the arm of a mobile manipulator, a leg of a quadruped, a humanoid's longest limb);
``docs/robot-models.md`` lists the choice per file.
"""

from pathlib import Path

import pinocchio as pin
import pytest

import kinelab
from kinelab.analysis.oracles import fk_vs_yourdfpy, jacobians_vs_fd
from kinelab.robot import catalog
from kinelab.robot.urdf import read_tree

ERD = Path(catalog.erd_share_dir() or "/nonexistent") / "example-robot-data" / "robots"
CORPUS = sorted(ERD.rglob("*.urdf"))


def corpus_tool(path: Path) -> str | None:
    """None (the robot's own default) for a single leaf, else the leaf behind the most movable joints,
    none of them a mimic joint."""
    tree = read_tree(path)
    if len(tree.leaves) == 1:
        return None
    model = pin.buildModelFromUrdf(str(path))
    best: tuple[int, str] | None = None
    for leaf in tree.leaves:
        fid = model.getFrameId(leaf, pin.FrameType.BODY)
        chain = [model.names[j] for j in model.supports[model.frames[fid].parentJoint] if j != 0]
        if any(j in tree.mimic for j in chain):
            continue
        if best is None or len(chain) > best[0]:
            best = (len(chain), leaf)
    return best[1] if best else None


def load_corpus(path: Path):
    try:
        return kinelab.load(path, tool=corpus_tool(path)), None
    except kinelab.KinelabError as err:
        return None, err


@pytest.mark.skipif(not CORPUS, reason="example-robot-data not installed")
def test_at_least_60_of_the_corpus_load_and_every_refusal_is_specific():
    loaded, refused = [], []
    for path in CORPUS:
        robot, err = load_corpus(path)
        if robot is None:
            refused.append((path.name, str(err)))
        else:
            loaded.append(path.name)
    assert len(CORPUS) == 69 and len(loaded) >= 60, refused
    for name, message in refused:  # the file (by name or path) or the element is named
        assert Path(name).stem in message or "joint" in message or "frame" in message, (name, message)


@pytest.mark.skipif(not CORPUS, reason="example-robot-data not installed")
@pytest.mark.parametrize("path", CORPUS, ids=lambda p: str(p.relative_to(ERD)))
def test_every_loaded_chain_agrees_with_yourdfpy_and_finite_differences(path):
    robot, err = load_corpus(path)
    if robot is None:
        pytest.skip(f"refused: {err}")
    fk = fk_vs_yourdfpy(robot, count=100)
    assert fk.max_position <= 1e-9 and fk.max_rotation <= 1e-9
    assert jacobians_vs_fd(robot, count=20).max_rotation <= 1e-6


@pytest.mark.skipif(not CORPUS, reason="example-robot-data not installed")
def test_the_corpus_refusals_say_why_in_one_line():
    """#72 item 6: ANYmal C and B1 (a link and a joint, or a link and its fixed joint, of one name) load now, and
    agree with yourdfpy above; ur3.urdf (an empty <robot>) is refused naming what is missing."""
    names = {p.relative_to(ERD).as_posix(): p for p in CORPUS}
    for loads in ("anymal_c_simple_description/urdf/anymal.urdf", "b1_description/urdf/b1-z1.urdf"):
        robot, err = load_corpus(names[loads])
        assert robot is not None, err
    _, err = load_corpus(names["ur_description/urdf/ur3.urdf"])
    assert err is not None and "no <link> element" in str(err) and "\n" not in str(err)
