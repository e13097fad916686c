"""#71 goal 2: a process's first solve costs what later ones cost — ``kinelab.load`` readies the default calls of an
arm (kinelab.wholebody.ready). Nothing here reads a clock: the first default call after load must import no module
and build no prepared solver (what the first call used to pay for), checked in a fresh process; the times are
``kinelab bench --first-call``'s."""

import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.robot import catalog
from kinelab.wholebody import ready

FRESH = r"""
import json, sys, numpy as np, kinelab
out = {}
for name in sys.argv[1:]:
    arm = kinelab.load(name)
    qs = arm.random_qs(3, np.random.default_rng(71))
    targets = [arm.fk(q) for q in qs]
    table = arm.derived("prepared solvers", dict)
    kept, modules = set(table), set(sys.modules)
    one = kinelab.solve(arm, targets[0], seed=0)
    started = kinelab.solve(arm, targets[1], q0=qs[0], seed=0)
    batch = kinelab.solve_batch(arm, targets, seed=0)
    every = kinelab.solve_all(arm, targets[2], seed=0)
    out[name] = {"new_modules": sorted(set(sys.modules) - modules), "new_solvers": len(set(table) - kept),
                 "success": [bool(one.success), bool(started.success), bool(batch.success.all()), len(every) > 0]}
print(json.dumps(out))
"""


def test_the_first_default_calls_after_load_import_nothing_and_build_nothing():
    """ur5 (closed form), panda (a 7R arm: FRDM alone, the held joint with a start or in a batch, the multistart's
    every branch) and crx10ia (FRDM, the 1-D search): solve, solve with a start, solve_batch and solve_all."""
    done = subprocess.run([sys.executable, "-c", FRESH, "ur5", "panda", "crx10ia"], capture_output=True, text=True,
                          check=True, timeout=600)
    found = json.loads(done.stdout.strip().splitlines()[-1])
    for name, seen in found.items():
        assert seen["new_modules"] == [], (name, seen["new_modules"])
        assert seen["new_solvers"] == 0, name
        assert all(seen["success"]), name


def test_every_registered_arms_routes_are_those_its_warm_up_took():
    """What ``kinelab info`` says of the default routes (ready.routes, without solving) is what the calls took."""
    arms = [name for name in kinelab.robots() if not catalog.resolve(name)[1].whole]
    assert len(arms) >= 20
    for name in arms:
        arm = kinelab.load(name)
        record = ready.readied(arm)
        assert record is not None and record.refused == "", name
        assert record.routes == ready.routes(arm), name
        assert dict(record.routes)["solve_all"] in {"closed form", "search", "elimination", "multistart"}


def test_prepare_false_builds_nothing_and_answers_alike():
    lazy = kinelab.load("panda", prepare=False)
    assert ready.readied(lazy) is None
    assert lazy.derived("prepared solvers", lambda _: {}) == {}
    eager = kinelab.load("panda")
    target = eager.fk(eager.random_q(np.random.default_rng(4)))
    a, b = kinelab.solve(lazy, target, seed=3), kinelab.solve(eager, target, seed=3)
    assert a.success and b.success and a.solver == b.solver
    np.testing.assert_allclose(a.q, b.q, atol=1e-12)  # the same route from the same seed, in one process
    M = pin.SE3(eager.fk(b.q))
    assert np.linalg.norm(M.translation - target.translation) <= 1e-6


@pytest.mark.parametrize("bad", [None, "yes", 1])
def test_prepare_takes_a_bool(bad):
    with pytest.raises(kinelab.OptionError, match="prepare.*True or False"):
        kinelab.load("ur5", prepare=bad)



def test_info_says_the_routes_load_readies(capsys):
    from kinelab.cli import main
    assert main(["info", "panda"]) == 0
    line = [x for x in capsys.readouterr().out.splitlines() if x.startswith("default routes")]
    assert line and "solve → frdm, solve with q0 → analytic, solve_batch → analytic, solve_all → multistart" in line[0]


def test_a_readying_that_fails_leaves_the_load_whole_and_says_why(monkeypatch):
    """Readying is a saving: where it fails (a chain a solver refuses, or a fault of ours), the load still returns
    the robot, the record names the error, and the first call meets it as it would have."""
    def broken(robot):
        raise RuntimeError("the engine could not be built")

    monkeypatch.setattr(ready, "_warm", broken)
    arm = kinelab.load("ur5")
    record = ready.readied(arm)
    assert record.routes == () and record.refused == "RuntimeError: the engine could not be built"
    assert kinelab.solve(arm, arm.fk(arm.neutral()), seed=0).success


def test_kinelab_load_takes_every_argument_of_the_robot_layers_load_and_prepare():
    """``kinelab.load`` spells out the robot layer's loader's arguments (for editors and type checkers) plus
    ``prepare``: the two lists must not drift apart."""
    import inspect

    from kinelab.robot import loading

    ours = inspect.signature(kinelab.load).parameters
    theirs = inspect.signature(loading.load).parameters
    assert list(ours) == [*theirs, "prepare"]
    for name, p in theirs.items():
        assert (ours[name].kind, ours[name].default) == (p.kind, p.default), name
    assert ours["prepare"].default is True and ours["prepare"].kind is inspect.Parameter.KEYWORD_ONLY
