"""One vocabulary: every public IK entry point takes the robot and target(s) positionally, the rest by keyword,
and refuses the same bad values with the same message."""

import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab import Diagnostics, OptionError
from kinelab.ik.tasks import Task


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


def _target(robot, seed=3):
    return robot.fk(robot.random_q(np.random.default_rng(seed)))


def test_fk_targets_are_met_by_every_entry_point_with_the_test_s_own_check(ur5):
    """Each entry point's success is re-checked here with Pinocchio (the Robot's FK), not the solver's word."""
    target = _target(ur5)
    answers = [kinelab.solve(ur5, target, seed=1).q,
               kinelab.solve_batch(ur5, [target] * 4, seed=1).q[2],
               kinelab.solve_all(ur5, target, seed=1)[0].q,
               kinelab.track(ur5, [target, target], seed=1).q[1]]
    for q in answers:
        err = ur5.fk(q).actInv(target)
        assert np.linalg.norm(err.translation) <= 1e-6 and np.linalg.norm(pin.log3(err.rotation)) <= 1e-6
        assert ur5.within_limits(q)


def test_bypass_tables_with_a_task_no_longer_crash():
    """kinelab 0.1: the options were hashed for a cache although their tables are dicts (TypeError)."""
    era = kinelab.load("era")
    target = kinelab.target_from_xyz_rpy([4, 2, 6], [0, 1.2, 0])
    res = kinelab.solve(era, target, task="position", kicks={"joint4": -1e-2}, seed=0)
    assert res.success and res.task == "position"
    assert np.linalg.norm(era.fk(res.q).translation - [4, 2, 6]) <= 1e-6
    lists = kinelab.solve(era, target, task="axis", intervals={"joint4": [-3.0, 0.5]}, seed=0)
    assert lists.success and -3.0 <= lists.q[3] <= 0.5


def test_the_cli_takes_a_kick_with_a_task():
    proc = subprocess.run([sys.executable, "-m", "kinelab.cli", "ik", "era", "--target-xyz", "4", "2", "6", "--task",
                           "position", "--kick", "joint4=-0.01", "--json"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["success"] and out["task"] == "position" and "Traceback" not in proc.stderr


@pytest.mark.parametrize(("call", "keyword"), [
    (lambda r, t: kinelab.solve(r, t, "dls"), "solver='dls'"),
    (lambda r, t: kinelab.solve_batch(r, [t], np.zeros(6)), "q0=array"),
    (lambda r, t: kinelab.solve_all(r, t, "position"), "task='position'"),
    (lambda r, t: kinelab.track(r, [t], np.zeros(6)), "q0=array"),
])
def test_positional_arguments_after_the_target_name_their_keyword(ur5, call, keyword):
    with pytest.raises(TypeError, match=r"by keyword: pass " + keyword.replace("(", r"\(")):
        call(ur5, _target(ur5))


@pytest.mark.parametrize(("name", "value", "valid"), [
    ("tol_pos", -1.0, "a finite number > 0"), ("tol_rot", float("nan"), "a finite number > 0"),
    ("seed", -3, "an integer ≥ 0"), ("solver", "frdmm", "solvers are"), ("task", "pos", "one of pose"),
])
def test_every_entry_point_refuses_a_bad_value_with_the_same_message(ur5, name, value, valid):
    target = _target(ur5)
    messages = []
    for call in (lambda **kw: kinelab.solve(ur5, target, **kw), lambda **kw: kinelab.solve_batch(ur5, [target], **kw),
                 lambda **kw: kinelab.solve_all(ur5, target, **kw),
                 lambda **kw: kinelab.track(ur5, [target], q0=ur5.neutral(), **kw)):
        with pytest.raises(kinelab.KinelabError, match=valid) as err:
            call(**{name: value})
        messages.append(str(err.value))
    if name != "solver":  # track takes solver "frdm" only and says so
        assert len(set(messages)) == 1, messages


def test_an_unknown_solver_lists_each_solver_once():
    with pytest.raises(kinelab.SolverNotFoundError) as err:
        kinelab.solve(kinelab.load("ur5"), kinelab.target_from_xyz_rpy([0.3, 0.1, 0.4]), solver="nope")
    assert str(err.value).endswith("solvers are: analytic, auto, biquat, dls, frdm")


def test_prefer_refuses_what_it_would_ignore(ur5):
    with pytest.raises(OptionError, match="q0"):
        kinelab.solve(ur5, _target(ur5), prefer=np.zeros(6), q0=np.zeros(6))


def test_prefer_labels_the_task_as_solve_does(ur5):
    target = _target(ur5)
    plain = kinelab.solve(ur5, target, task="axis", axis="z", seed=0)
    preferred = kinelab.solve(ur5, target, task="axis", axis="z", seed=0, prefer=np.zeros(6), time_budget=None)
    assert plain.task == preferred.task == "axis z"
    assert preferred.diagnostics.branches >= 2


def test_results_carry_typed_diagnostics(ur5):
    res = kinelab.solve(ur5, _target(ur5), solver="frdm", seed=0)
    assert isinstance(res.diagnostics, Diagnostics) and res.diagnostics.path == "compiled"
    assert res.diagnostics.sweeps == res.iterations and res.diagnostics.attempts == res.restarts + 1
    loop = kinelab.solve(ur5, _target(ur5), seed=0, policy=("auto_kick",))
    assert loop.diagnostics.path == "" and isinstance(loop.diagnostics.answer_events, tuple)
    json.dumps(res.to_dict()) and json.dumps(loop.to_dict())
    found = kinelab.solve_all(ur5, _target(ur5), solver="frdm", seed=0, time_budget=None)  # no clock: load-proof
    assert sum(f.diagnostics.found for f in found) <= found[0].diagnostics.starts


def test_one_request_feeds_every_entry_point():
    """The request is the single place of validation: a task turns the options into that task's options."""
    from kinelab.ik.request import make_request

    kicks = {"kicks": {"joint4": 0.1}}
    req = make_request(task="axis", axis="x", solver_options=kicks)
    assert req.task == Task("axis", 0) and req.options.mode == "axis" and req.options.tool_axis == "x"
    assert hash(req.options) == hash(make_request(task="axis", axis="x", solver_options=dict(kicks)).options)


def test_the_prepared_solver_gives_kinelab_solve_s_answers(ur5):
    """ik.solve equals kinelab.solve for the same seed and settings (one driver under both), and checks per call
    only what changes."""
    ik = kinelab.IK(ur5, tol_pos=1e-7, task="axis", axis="x")
    rng = np.random.default_rng(9)
    for k in range(5):
        target = ur5.fk(ur5.random_q(rng))
        a = ik.solve(target, seed=k)
        b = kinelab.solve(ur5, target, seed=k, tol_pos=1e-7, task="axis", axis="x")
        np.testing.assert_array_equal(a.q, b.q)
        assert a.success == b.success and a.task == b.task == "axis x"
    warm = ik.solve(target, q0=b.q)
    assert warm.success and warm.restarts == 0
    batch = ik.solve_batch([target] * 3, seed=4)
    np.testing.assert_array_equal(batch.q, kinelab.solve_batch(ur5, [target] * 3, seed=4, tol_pos=1e-7,
                                                               task="axis", axis="x").q)
    with pytest.raises(OptionError, match="seed"):
        ik.solve(target, seed=-1)
    with pytest.raises(TypeError, match="by keyword"):
        kinelab.IK(ur5, "dls")
    with pytest.raises(OptionError, match="tol_pos"):
        kinelab.IK(ur5, tol_pos=0.0)


def test_roll_pitch_yaw_in_degrees_are_taken_by_name_and_caught_when_given_as_radians():
    deg = kinelab.target_from_xyz_rpy([0.4, 0.2, 0.5], [180, 0, 90], degrees=True)
    rad = kinelab.target_from_xyz_rpy([0.4, 0.2, 0.5], [np.pi, 0, np.pi / 2])
    np.testing.assert_allclose(deg.homogeneous, rad.homogeneous, atol=1e-12)
    with pytest.raises(kinelab.TargetError, match="looks like degrees.*degrees=True"):
        kinelab.target_from_xyz_rpy([0.4, 0.2, 0.5], [180, 0, 0])
