"""#68 and #72: ``kinelab info`` of a whole robot describes its tree (hands, feet, free-flyer, mass, loops, folded
mimics) and says which whole-body step answers it and why; a chain of it is still one --tool away."""

import json

import pytest

import kinelab
from kinelab.cli.main import main


def info(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["info", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_talos_is_described_whole_with_the_compiled_step(capsys: pytest.CaptureFixture[str]) -> None:
    talos = kinelab.load("talos")
    out = info(capsys, "talos")
    assert out["floating"] and (out["nq"], out["nv"]) == (talos.nq, talos.nv)
    assert out["hands"] == list(talos.hands) and out["feet"] == list(talos.feet)
    assert abs(out["mass_kg"] - talos.mass) <= 1e-9 and "half_sitting" in out["named_poses"]
    assert out["step"].startswith("compiled:") and out["loops"] == []


def test_a_robot_with_loops_says_why_the_readable_step_answers(capsys: pytest.CaptureFixture[str]) -> None:
    out = info(capsys, "delta")
    assert len(out["loops"]) == 3 and out["actuated"] == ["motor_1", "motor_2", "motor_3"]
    assert out["step"] == "readable: the robot closes loops (the compiled step has no block for a closure yet)"


def test_a_file_is_described_whole_when_asked_and_a_chain_when_a_tool_is_named(
        capsys: pytest.CaptureFixture[str]) -> None:
    path = kinelab.load("fourbar").source
    whole = info(capsys, str(path), "--whole")
    assert whole["robot"] == "fourbar" and whole["loops"] == []  # a file alone declares no loops
    chain = info(capsys, "talos", "--tool", "gripper_left_base_link")
    assert chain["tool"] == "gripper_left_base_link" and "floating" not in chain


def test_romeo_s_folded_mimics_are_listed(capsys: pytest.CaptureFixture[str]) -> None:
    out = info(capsys, "romeo")
    assert len(out["mimics"]) == 22 and out["mimics"]["LFinger12"] == "1 × LHand + 0"


def test_a_whole_robot_asked_for_a_chain_names_the_option_and_its_hands(capsys: pytest.CaptureFixture[str]) -> None:
    """#72 item 2: `kinelab fk talos` names --tool (not Python syntax) and the robot's hands."""
    assert main(["fk", "talos"]) == 2
    err = capsys.readouterr().err
    assert "--tool on the command line" in err and "gripper_left_base_link, gripper_right_base_link" in err
    assert "pass tool=NAME" not in err


def test_an_ambiguous_file_names_three_likely_tools(tmp_path) -> None:
    """A tree with no registered tool: the error names --tool and the leaves named like a tool, deepest first."""
    from helpers import write_urdf

    body = "".join(f'<link name="{n}"/>' for n in ("base", "a", "b", "left_gripper", "camera", "right_hand"))
    for parent, child in (("base", "a"), ("a", "left_gripper"), ("base", "b"), ("b", "right_hand"),
                          ("base", "camera")):
        body += (f'<joint name="{child}_j" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                 '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    with pytest.raises(kinelab.ChainError, match="--tool on the command line.*likely left_gripper, right_hand, camera"):
        kinelab.load(write_urdf(tmp_path, body))


def test_the_robot_list_calls_a_whole_robot_whole(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robots"]) == 0
    out = capsys.readouterr().out
    assert "talos_reduced.urdf; the whole robot, free-flyer base" in out and "; chain the whole" not in out
