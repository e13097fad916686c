"""One route through the compiled core (#32): every entry point of a solve — ``kinelab.solve``, a prepared
``kinelab.IK``, a row of ``solve_batch`` — runs the same compiled multistart on the same start with the same
generator, so for the same seed they give the same answer, bit for bit, with the same diagnostics."""

import numpy as np
import pytest

import kinelab

FIELDS = ("sweeps", "attempts", "stalls", "polished", "newton_steps", "accelerated_sweeps", "path")


@pytest.mark.parametrize("name", ["ur5", "panda", "youbot", "kinova"])
def test_solve_the_prepared_solver_and_a_batch_row_take_the_same_route(name):
    robot = kinelab.load(name)
    ik = kinelab.IK(robot, solver="frdm", time_budget=None)
    rng = np.random.default_rng(17)
    for k in range(12):
        q = robot.random_q(rng)
        target = robot.fk(q)
        q0 = np.clip(q + rng.normal(0, 0.2, q.size), robot.lower, robot.upper) if k % 2 else None
        plain = kinelab.solve(robot, target, q0=q0, seed=k, time_budget=None, solver="frdm")
        prepared = ik.solve(target, q0=q0, seed=k)
        row = kinelab.solve_batch(robot, [target], q0=None if q0 is None else [q0], seed=k, solver="frdm")
        np.testing.assert_array_equal(plain.q, prepared.q)
        np.testing.assert_array_equal(plain.q, row.q[0])
        assert plain.status == prepared.status and plain.status.value == row.status[0]
        assert plain.iterations == prepared.iterations == row.iterations[0]
        assert plain.restarts == prepared.restarts == row.restarts[0]
        assert plain.mode == prepared.mode
        for field in FIELDS:
            assert getattr(plain.diagnostics, field) == getattr(prepared.diagnostics, field), field
        assert plain.diagnostics.path == "compiled"


def test_a_batch_row_is_the_single_solve_with_seed_plus_its_index():
    robot = kinelab.load("panda")
    rng = np.random.default_rng(3)
    targets = [robot.fk(robot.random_q(rng)) for _ in range(20)]
    batch = kinelab.solve_batch(robot, targets, seed=100, solver="frdm")
    for b, target in enumerate(targets):
        one = kinelab.solve(robot, target, seed=100 + b, time_budget=None, solver="frdm")
        np.testing.assert_array_equal(one.q, batch.q[b])
        assert one.iterations == batch.iterations[b] and one.restarts == batch.restarts[b]


def test_the_biquaternion_solver_takes_one_route_too():
    robot = kinelab.load("stanford")
    ik = kinelab.IK(robot, solver="biquat", time_budget=None)
    rng = np.random.default_rng(5)
    for k in range(8):
        target = robot.fk(robot.random_q(rng))
        plain = kinelab.solve(robot, target, solver="biquat", seed=k, time_budget=None)
        prepared = ik.solve(target, seed=k)
        np.testing.assert_array_equal(plain.q, prepared.q)
        assert plain.status == prepared.status and plain.iterations == prepared.iterations
        assert plain.diagnostics.steps == prepared.diagnostics.steps
        assert plain.diagnostics.attempts == prepared.diagnostics.attempts


def _general_route(robot, target, q0, seed, solver="frdm"):
    """The driver's route (checks, the compiled multistart, Pinocchio-side verdict in Python): what every solve
    took before the one compiled call."""
    from dataclasses import replace

    from kinelab.ik.driver import solve_one
    from kinelab.ik.request import make_request

    req = make_request(solver, None, 1e-6, 1e-6, None, 1000, "project", None, "pose", "z", {})
    return solve_one(robot, target, q0, replace(req, seed=seed))


ENGINES = [("frdm", name) for name in ("ur5", "panda", "kinova", "stanford", "youbot")] + \
    [("biquat", name) for name in ("ur5", "panda", "kinova", "stanford", "z1", "youbot")]


@pytest.mark.parametrize(("solver", "name"), ENGINES)
def test_the_one_compiled_call_gives_the_driver_s_answers(solver, name):
    """Same q, status, counters, errors and diagnostics as the general route, on seeded targets from random,
    warm and no starts (kinova has continuous joints: FRDM's wrap happens inside the compiled call too; the youBot's
    base joints draw their restarts in windows that follow the target), for each solver with an engine."""
    robot = kinelab.load(name)
    ik = kinelab.IK(robot, solver=solver, time_budget=None)
    assert ik.engine is not None, "the robot's compiled FK is certified: the one-call engine serves it"
    rng = np.random.default_rng(40)
    for k in range(24):
        q = robot.random_q(rng)
        target = robot.fk(q)
        q0 = [None, robot.random_q(rng), np.clip(q + rng.normal(0, 0.2, q.size), robot.lower, robot.upper)][k % 3]
        one, general = ik.solve(target, q0=q0, seed=k), _general_route(robot, target, q0, k, solver)
        np.testing.assert_array_equal(one.q, general.q)
        assert (one.status, one.success, one.iterations, one.restarts, one.message) == \
            (general.status, general.success, general.iterations, general.restarts, general.message)
        assert (one.position_error, one.rotation_error, one.mode, one.judge) == \
            (general.position_error, general.rotation_error, general.mode, general.judge)
        assert one.diagnostics.to_dict() == general.diagnostics.to_dict()
        assert one.singular_events == general.singular_events


def test_a_result_s_diagnostics_are_built_only_when_read(monkeypatch):
    import copy
    import pickle

    from kinelab.ik.frdm.solver import _Context

    robot = kinelab.load("panda")
    ik = kinelab.IK(robot, solver="frdm", time_budget=None)
    built, made_by = [], _Context.diagnostics
    monkeypatch.setattr(_Context, "diagnostics", lambda ctx, st: built.append(1) or made_by(ctx, st))
    q = robot.random_q(3)
    res = ik.solve(robot.fk(q), q0=q, seed=0)
    assert res.success and built == []
    assert res.diagnostics.path == "compiled" and res.diagnostics.attempts == 1
    assert res.diagnostics is res.diagnostics and built == [1]  # made once, then kept
    later = ik.solve(robot.fk(q), q0=q, seed=0)
    assert pickle.loads(pickle.dumps(later)).diagnostics == res.diagnostics and built == [1, 1]
    assert copy.deepcopy(ik.solve(robot.fk(q), q0=q, seed=0)).diagnostics == res.diagnostics and len(built) == 3


@pytest.mark.parametrize("name", ["ur5", "kinova", "crx10ia"])
def test_every_branch_in_one_call_holds_the_compiled_form_s_rows_and_builds_them_when_read(name, monkeypatch):
    """solve_all's usual call hands the compiled form's arrays straight to a lazily built set: the rows equal
    ``ClosedForm.solve``'s, the results equal the general route's, and none is built before the set is read."""
    from kinelab.ik.analytic import branches as analytic

    robot = kinelab.load(name)
    rng = np.random.default_rng(11)
    built = []
    filled = analytic.filled
    monkeypatch.setattr(analytic, "filled", lambda *a, **k: built.append(1) or filled(*a, **k))
    for _ in range(20):
        target = robot.fk(robot.random_q(rng))
        fast = kinelab.solve_all(robot, target)
        (entry,) = robot.derived("usual closed forms", None).values()  # the one kept for solve_all's defaults
        form = entry.form
        q, dp, dr, merged, continuum, _ = form.solve(target.homogeneous, None)
        assert built == [] and fast.method == ("search" if name == "crx10ia" else "closed form")
        np.testing.assert_array_equal(fast.q, q)
        np.testing.assert_array_equal(fast.position_error, dp)
        np.testing.assert_array_equal(fast.rotation_error, dr)
        general = kinelab.solve_all(robot, target, q_ref=np.zeros(robot.n) + 1e-300)  # takes the general route
        assert len(general) == len(fast) > 0
        for res in fast:
            dp_k, dr_k = robot.tool_error(res.q, target)
            assert dp_k <= 1e-6 and dr_k <= 1e-6 and robot.within_limits(res.q) and res.diagnostics.branches == len(q)
        assert len(built) == len(fast)
        built.clear()


@pytest.mark.parametrize(("name", "solver"), [("ur5", "auto"), ("kinova", "analytic"), ("stanford", "frdm"),
                                              ("ur5", "dls")])
def test_every_branch_from_a_prepared_solver_is_kinelab_s(name, solver):
    """#40.3: ``IK.solve_all`` never took the closed form that ``kinelab.solve_all`` takes; both now read the route
    from the solver's capabilities. The multistart's rounds are seeded alike and stop by the same rule (the budget
    is far from spent), so its sets are equal too."""
    robot = kinelab.load(name)
    ik = kinelab.IK(robot, solver=solver, time_budget=2.0)
    rng = np.random.default_rng(5)
    for k in range(2):
        target = robot.fk(robot.random_q(rng))
        mine = ik.solve_all(target, seed=k)
        theirs = kinelab.solve_all(robot, target, solver=solver, seed=k, time_budget=2.0)
        assert mine.method == theirs.method == ("multistart" if solver in ("frdm", "dls") else "closed form")
        assert len(mine) == len(theirs) > 0
        np.testing.assert_allclose(mine.q, theirs.q, rtol=0, atol=1e-12)
        for res in mine:
            dp, dr = robot.tool_error(res.q, target)
            assert dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(res.q)


def test_a_registered_solver_gets_no_capability_it_did_not_declare(monkeypatch):
    """The entry points read what a solver can do, not its name: a copy of FRDM registered under another name
    answers ``solve`` (through the one-call engine its module offers, the result named after it), but ``track``
    (FRDM's path follower) refuses it until it declares that it follows paths."""
    from kinelab.ik import register, registry
    from kinelab.ik.frdm import solver as frdm

    monkeypatch.setattr(registry, "SOLVERS", dict(registry.SOLVERS))
    monkeypatch.setattr(registry, "CAPABILITIES", dict(registry.CAPABILITIES))
    robot = kinelab.load("ur5")
    q = robot.random_q(3)
    register("twin", frdm)
    res = kinelab.solve(robot, robot.fk(q), solver="twin", seed=1, time_budget=None)
    assert res.success and res.solver == "twin" and kinelab.IK(robot, solver="twin").engine is not None
    with pytest.raises(kinelab.OptionError, match="solver"):
        kinelab.track(robot, [robot.fk(q)], q0=q, solver="twin")
    register("twin", frdm, registry.Capabilities(follows_paths=True))
    assert kinelab.track(robot, [robot.fk(q)], q0=q, solver="twin").reached.all()


def test_no_entry_point_compares_a_solver_s_name():
    """#40 goal 6: the solve route and the CLI ask the registry what a solver can do (comparisons of a solver's
    name to a literal crept back in one by one before)."""
    import ast
    from pathlib import Path

    import kinelab.cli
    import kinelab.ik

    names = {"frdm", "biquat", "dls", "analytic", "auto"}
    found = []
    for package in (kinelab.ik, kinelab.cli):
        for path in Path(package.__file__).parent.glob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Compare):
                    literals = [c.value for c in ast.walk(node) if isinstance(c, ast.Constant)]
                    if names & {v for v in literals if isinstance(v, str)}:
                        found.append(f"{path.name}:{node.lineno}")
    assert found == []

