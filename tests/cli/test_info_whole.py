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
