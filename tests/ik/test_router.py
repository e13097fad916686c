"""One router (#58): the module functions are calls on a prepared ``kinelab.IK`` kept per robot and settings, so
every route — the multistart, the closed form, a 7R arm's held joint, a collision check — is chosen in one place.
Each case spies on ``IK`` and calls the module function as a user does, on a robot loaded with ``prepare=False`` (the
load's own warm-up would be counted)."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.ik import prepared as prepared_module


@pytest.fixture
def spy(monkeypatch):
    """Counts of IK objects built and of their methods called (the originals still run)."""
    counts = {"built": 0, "solve": 0, "solve_batch": 0, "solve_all": 0, "track": 0}
    IK = prepared_module.IK
    original_init = IK.__init__

    def init(self, *args, **kwargs):
        counts["built"] += 1
        original_init(self, *args, **kwargs)

    monkeypatch.setattr(IK, "__init__", init)
    for name in ("solve", "solve_batch", "solve_all", "track"):
        original = getattr(IK, name, None)
        if original is None:
            continue

        def wrapped(self, *args, _original=original, _name=name, **kwargs):
            counts[_name] += 1
            return _original(self, *args, **kwargs)

        monkeypatch.setattr(IK, name, wrapped)
    return counts


def _targets(robot, count, seed=3):
    rng = np.random.default_rng(seed)
    return np.stack([robot.fk(robot.random_q(rng)).homogeneous for _ in range(count)])


@pytest.mark.parametrize(("name", "solver", "extra"), [
    ("ur5", "frdm", {}), ("ur5", "analytic", {}), ("ur5", "auto", {}), ("panda", "analytic", {}),
    ("panda", "frdm", {"collisions": "self"}), ("kinova", "biquat", {}), ("crx10ia", "dls", {}),
])
def test_solve_batch_is_the_kept_prepared_solvers_call(spy, name, solver, extra):
    robot = kinelab.load(name, prepare=False)
    T = _targets(robot, 4)
    first = kinelab.solve_batch(robot, T, solver=solver, seed=5, **extra)
    again = kinelab.solve_batch(robot, T, solver=solver, seed=5, **extra)
    assert spy["solve_batch"] == 2 and spy["built"] == 1  # built once, kept for the same settings
    ours = kinelab.IK(robot, solver=solver, time_budget=None, start_outside_limits="refuse", **extra) \
        .solve_batch(T, seed=5)
    assert first.success.all() and again.success.all() and ours.success.all()
    for q in (first.q, again.q, ours.q):  # the judge's FK of each answer meets its target
        for b in range(len(T)):
            dp, dr = robot.tool_error(q[b], pin.SE3(T[b]))
            assert dp <= 1e-6 and dr <= 1e-6
    if solver != "dls" and "collisions" not in extra:  # same seed, same route: the same answers
        np.testing.assert_allclose(first.q, ours.q, atol=1e-12, rtol=0)


def test_solve_is_the_kept_prepared_solvers_call(spy):
    robot = kinelab.load("ur5", prepare=False)
    target = robot.fk(np.array([0.3, -1.2, 1.4, -0.5, 0.9, 0.2]))
    results = [kinelab.solve(robot, target, solver="frdm", seed=s) for s in range(3)]
    assert spy["built"] == 1 and spy["solve"] == 1  # later calls: the kept solver's compiled engine directly
    assert all(r.success for r in results)
    closed = [kinelab.solve(robot, target, solver="auto", seed=s) for s in range(3)]  # the closed form
    assert spy["built"] == 2 and all(r.success and r.solver == "analytic" for r in closed)


def _path(robot, q, count=30, step=0.01):
    """Tool poses along a straight joint-space line from q (every one reachable)."""
    direction = np.linspace(1.0, -1.0, robot.n)
    return [robot.fk(q + k * step * direction) for k in range(count)]


@pytest.mark.parametrize(("name", "extra"), [("panda", {}), ("ur5", {"restrict": ("intervals",)}),
                                             ("kinova", {"collisions": "self"})])
def test_track_is_the_kept_prepared_solvers_call(spy, name, extra):
    robot = kinelab.load(name, prepare=False)
    q = robot.display_q()
    targets = _path(robot, q)
    restrict = extra.get("restrict", ())
    settings = {k: v for k, v in extra.items() if k != "restrict"}
    if restrict:
        settings["intervals"] = {robot.joint_names[0]: (robot.lower[0], robot.upper[0])}
    first = kinelab.track(robot, targets, q0=q, seed=1, restrict=restrict, **settings)
    again = kinelab.track(robot, targets, q0=q, seed=1, restrict=restrict, **settings)
    assert spy["track"] == 2
    assert spy["built"] == (2 if restrict else 1)  # a dict setting cannot be a key: a new solver each call
    ours = kinelab.IK(robot, time_budget=None, **settings).track(targets, q0=q, seed=1, restrict=restrict)
    for path in (first, again, ours):
        assert path.reached.all()
        for k, target in enumerate(targets):
            dp, dr = robot.tool_error(path.q[k], target)
            assert dp <= 1e-6 and dr <= 1e-6
            assert np.all(path.q[k] >= robot.lower - 1e-9) and np.all(path.q[k] <= robot.upper + 1e-9)
    np.testing.assert_allclose(first.q, ours.q, atol=1e-12, rtol=0)


def test_track_without_a_start_begins_at_the_first_targets_answer_through_the_router(spy):
    robot = kinelab.load("ur5", prepare=False)
    targets = _path(robot, robot.display_q())
    path = kinelab.track(robot, targets, seed=4)
    assert path.reached.all() and spy["track"] == 1 and spy["solve"] == 1  # the first answer: a kept solver's solve
    with pytest.raises(kinelab.OptionError, match="'frdm' \\(track follows a path"):
        kinelab.track(robot, targets, solver="biquat")


@pytest.mark.parametrize(("name", "extra"), [
    ("ur5", {}), ("crx10ia", {}), ("panda", {}), ("panda", {"redundancy": 4}), ("kinova", {"solver": "frdm"}),
    ("ur5", {"collisions": "self", "drop_colliding": True}), ("ur10", {"solver": "analytic"}),
])
def test_solve_all_is_the_kept_prepared_solvers_call(spy, name, extra):
    robot = kinelab.load(name, prepare=False)
    q = robot.display_q()
    target = robot.fk(q)
    found = [kinelab.solve_all(robot, target, seed=2, **extra) for _ in range(2)]
    assert spy["solve_all"] == 2 and spy["built"] == 1
    for branches in found:
        assert len(branches) >= 1 and branches.status == kinelab.Status.CONVERGED
        for b in branches:  # every branch meets the target within the limits, by Pinocchio's FK
            dp, dr = robot.tool_error(b.q, target)
            assert dp <= 1e-6 and dr <= 1e-6 and np.all(b.q >= robot.lower - 1e-9) and np.all(b.q <= robot.upper + 1e-9)
    if name in ("ur5", "ur10", "crx10ia"):  # every branch in closed form or by the 1-D search: the pose's own too
        assert any(np.abs(b.q - q).max() < 1e-6 for b in found[0])


@pytest.mark.parametrize(("name", "solver"), [("ur5", "frdm"), ("ur5", "analytic"), ("panda", "frdm"),
                                              ("kinova", "auto")])
def test_solve_preferring_a_branch_is_the_kept_prepared_solvers_call(spy, name, solver):
    robot = kinelab.load(name, prepare=False)
    q = robot.display_q()
    target = robot.fk(q)
    near = q + 0.05  # the pose's own branch is the one nearest a reference beside it
    results = [kinelab.solve(robot, target, solver=solver, seed=3, prefer=near) for _ in range(2)]
    assert spy["solve"] == 2 and spy["built"] == 1
    ours = kinelab.IK(robot, solver=solver).solve(target, seed=3, prefer=near)
    for res in (*results, ours):
        assert res.success and max(robot.tool_error(res.q, target)) <= 1e-6
        # the branch nearest the reference: the pose's own (a 7R arm's continuum: the sampled one nearest it)
        assert np.abs(res.q - q).max() < (0.1 if robot.n > 6 else 1e-5)
    with pytest.raises(kinelab.OptionError, match="q0|prefer"):
        kinelab.solve(robot, target, solver=solver, q0=q, prefer=near)
