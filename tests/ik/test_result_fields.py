"""One vocabulary on every result type: the same field names, and Status members (integer codes inside)."""

import dataclasses
import json

import numpy as np
import pytest

import kinelab
from kinelab import load
from kinelab.ik.batch import BatchIKResult
from kinelab.ik.result import IKResult, Status, TrackResult

SHARED = ("q", "success", "status", "position_error", "rotation_error", "iterations", "wall_time")


def names(cls):
    return {f.name for f in dataclasses.fields(cls)} | {n for n in dir(cls) if isinstance(getattr(cls, n), property)}


@pytest.mark.parametrize("cls", [IKResult, BatchIKResult, TrackResult])
def test_every_result_type_has_the_shared_fields(cls):
    assert set(SHARED) <= names(cls)


def test_codes_and_members_round_trip_and_print_as_their_names():
    codes = np.arange(len(Status), dtype=np.int8)
    members = Status.of_codes(codes)
    assert [m.code for m in members] == codes.tolist()
    np.testing.assert_array_equal(Status.codes([m.value for m in members]), codes)
    assert [f"{m}" for m in members] == [m.value for m in Status] == [str(m) for m in members]
    assert json.dumps(list(members)) == json.dumps([m.value for m in Status])
    with pytest.raises(ValueError, match="nonsense"):
        Status.codes(["nonsense"])


def test_batch_rows_carry_the_single_solves_status_member():
    robot = load("ur5")
    rng = np.random.default_rng(8)
    targets = [robot.fk(q) for q in robot.random_qs(6, rng)]
    far = targets[2].copy()
    far.translation = np.array([9.0, 0.0, 0.0])
    targets[2] = far
    batch = kinelab.solve_batch(robot, targets, seed=4)
    assert batch.status_code.dtype == np.int8
    for b, target in enumerate(targets):
        one = kinelab.solve(robot, target, seed=4 + b, time_budget=60.0)
        assert batch.status[b] is one.status  # the member itself, not a string that looks like it
    assert batch.status[2] is Status.UNREACHABLE
    assert batch.summary()["status"] == {"converged": 5, "unreachable": 1}


def test_a_track_carries_status_members_and_iterations():
    robot = load("panda")
    rng = np.random.default_rng(3)
    q0 = robot.random_qs(1, rng)[0]
    path = [robot.fk(q0 + 0.01 * k) for k in range(12)]
    track = kinelab.track(robot, path, q0=q0)
    assert all(isinstance(s, Status) for s in track.status)
    np.testing.assert_array_equal(track.reached, track.status == Status.CONVERGED)
    np.testing.assert_array_equal(track.sweeps, track.iterations)
    assert track.iterations.shape == (12,) and track.iterations.min() >= 0
    counts = track.summary()["status"]
    assert sum(counts.values()) == 12 and counts.get("converged", 0) == int(track.reached.sum())


def test_each_solver_s_diagnostics_are_its_own_record():
    """FRDM's and the biquaternion run's fields live on their own records; a closed-form branch has the shared
    one: no result carries another solver's empty fields."""
    robot = load("ur5")
    q = robot.random_q(2)
    target = robot.fk(q)
    frdm = kinelab.solve(robot, target, solver="frdm", seed=1, time_budget=None).diagnostics
    biquat = kinelab.solve(robot, target, solver="biquat", seed=1, time_budget=None).diagnostics
    branch = kinelab.solve_all(robot, target)[0].diagnostics
    assert type(frdm) is kinelab.FRDMDiagnostics and frdm.sweeps >= 1 and not hasattr(frdm, "model_time")
    assert type(biquat) is kinelab.BiquatDiagnostics and biquat.steps >= 1 and biquat.model_time > 0
    assert not hasattr(biquat, "sweeps")
    assert type(branch) is kinelab.Diagnostics and branch.branches == len(kinelab.solve_all(robot, target))
    assert not hasattr(branch, "sweeps") and not hasattr(branch, "steps")
    assert "sweeps" in frdm.to_dict() and "steps" in biquat.to_dict() and repr(biquat).startswith("BiquatDiagnostics(")


def test_a_result_is_frozen_and_its_copies_keep_their_diagnostics():
    """#58: one result family, frozen; the compiled routes' factory builds the same type as the general route."""
    import copy
    import pickle

    robot = kinelab.load("ur5")
    q = np.array([0.3, -1.2, 1.4, -0.5, 0.9, 0.2])
    compiled = kinelab.solve(robot, robot.fk(q), seed=0)  # the engine's fast factory
    branch = kinelab.solve_all(robot, robot.fk(q))[0]  # the closed form's rows, the same factory
    general = kinelab.solve(robot, robot.fk(q), seed=0, solver="dls")  # the general route's constructor
    for res in (compiled, branch, general):
        assert type(res) is kinelab.IKResult and res.success
        with pytest.raises(dataclasses.FrozenInstanceError):
            res.success = False
        changed = dataclasses.replace(res, message="edited")
        assert changed.message == "edited" and res.message != "edited" and changed.diagnostics == res.diagnostics
        for again in (pickle.loads(pickle.dumps(res)), copy.deepcopy(res)):
            assert np.array_equal(again.q, res.q) and again.diagnostics == res.diagnostics


def test_how_branches_were_found_and_how_complete_they_are_are_enums_that_read_as_words():
    import kinelab.ik.result as result

    ur5, panda = load("ur5"), load("panda")
    closed = kinelab.solve_all(ur5, ur5.fk(np.array([0.3, -1.2, 1.4, -0.5, 0.9, 0.2])))
    multi = kinelab.solve_all(panda, panda.fk(panda.display_q()), seed=0)
    assert closed.method is result.Method.CLOSED_FORM and multi.method is result.Method.MULTISTART
    assert closed.complete in (result.Completeness.CERTIFIED, result.Completeness.SEARCH)
    assert multi.complete is result.Completeness.ESTIMATE
    for word in (closed.method, multi.complete, Status.CONVERGED):  # a word: equal, hashed, printed as its string
        assert word == word.value and {word.value: 1}[word] == 1 and f"{word}" == str(word) == word.value
        assert json.loads(json.dumps({"w": word}))["w"] == word.value
    assert "method='closed form'" in repr(closed)
