"""The defects a fault and fuzz run found (#23), each reproduced: raw errors, allocations sized by nonsense,
files reached outside what the user pointed at. Each must now end in one clear error (a KinelabError, at the
CLI one line and exit 2) or an honest result."""

import numpy as np
import pytest

import kinelab
from kinelab import KinelabError, cli, maps
from kinelab.robot.meshes import resolve_uri


@pytest.mark.parametrize("argv", [
    ["singular", "ur5", "--sweep", "10", "--seed", "-1"],
    ["validate", "--robots", "ur5", "--n", "2", "--seed", "-1", "--json"],
    ["bench", "--robots", "ur5", "--n", "2", "--seed", "-1", "--json"],
    ["map", "singular", "ur5", "--samples", "10", "--seed", "-1"],
    ["map", "reach", "ur5", "--voxel", "1e-9"],
    ["map", "reach", "ur5", "--voxel", "0.006"],
    ["map", "base", "youbot", "--grasp", "1", "1", "0.3", "0", "0", "0", "--step", "1e-4"],
    ["map", "reach", "ur5", "--scheduler", ""],
    ["map", "reach", "ur5", "--scheduler", "abc"],
])
def test_nonsense_at_the_cli_is_one_line_and_exit_2_before_any_allocation(capsys, argv):
    try:
        code = cli.main(argv)
    except SystemExit as stop:  # refused by the parser itself (an empty value), as the command line exits
        code = stop.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("kinelab: error:"), err


@pytest.mark.parametrize("where", ["folder", "missing"])
def test_an_html_page_that_cannot_be_written_is_named(capsys, tmp_path, where):
    out = tmp_path if where == "folder" else tmp_path / "no" / "such" / "view.html"
    assert cli.main(["view", "ur5", "--html", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write the page" in err


def test_map_guards_run_before_the_grid_is_built():
    ur5 = kinelab.load("ur5")
    with pytest.raises(KinelabError, match="about 1.28e\\+29 targets"):
        maps.reachability(ur5, voxel=1e-9)
    with pytest.raises(KinelabError, match="lattice"):  # even with force: the lattice itself is refused
        maps.reachability(ur5, voxel=1e-4, force=True)


def test_a_package_uri_cannot_climb_out_of_its_package_and_only_meshes_resolve(tmp_path):
    package = tmp_path / "ws" / "arm"
    (package / "meshes").mkdir(parents=True)
    (package / "meshes" / "link.stl").write_text("solid x\nendsolid x\n")
    secret = tmp_path / "secret.stl"
    secret.write_text("solid secret\nendsolid secret\n")
    dirs = [str(tmp_path / "ws")]
    assert resolve_uri("package://arm/meshes/link.stl", package, dirs) == package / "meshes" / "link.stl"
    assert resolve_uri("package://arm/../../secret.stl", package, dirs) is None
    assert resolve_uri("package://arm/meshes/../../../secret.stl", package, dirs) is None
    assert resolve_uri("/etc/passwd", package, dirs) is None  # an absolute path, but no mesh
    assert resolve_uri(str(secret), package, dirs) == secret  # an absolute mesh the file's author named
    # "package:///" (an empty host, as TALOS's full URDF writes it) names the same package, and climbs no higher
    assert resolve_uri("package:///arm/meshes/link.stl", package, dirs) == package / "meshes" / "link.stl"
    assert resolve_uri("package:////../secret.stl", package, dirs) is None


def test_talos_full_urdf_draws_every_visual_mesh():
    talos_left = kinelab.load("talos_left")  # its URDF names its meshes "package:///example-robot-data/..."
    assert talos_left.missing_meshes() == []
    assert talos_left.visual_model().ngeoms >= 50


def test_an_unknown_solver_is_listed_once():
    with pytest.raises(kinelab.SolverNotFoundError) as err:
        kinelab.solve(kinelab.load("ur5"), kinelab.target_from_xyz_rpy([0.3, 0.1, 0.4]), solver="x")
    assert str(err.value).count("frdm") == 1 and str(err.value).count("biquat") == 1


def test_a_batch_keeps_its_budget_whatever_its_size(no_tolerance_floor):
    """kinelab 0.1: a batch of ≤ 512 rows never looked at the clock (5 ms → 4.2 s). Behaviour, not speed:
    an unattainable tolerance ends at the budget, with every row honest (the bench measures the overrun)."""
    youbot = kinelab.load("youbot")
    targets = youbot.fk_batch(youbot.random_qs(256, 0))
    kinelab.solve_batch(youbot, targets[:2], time_budget=0.01)  # compile outside the measurement
    res = kinelab.solve_batch(youbot, targets, seed=0, time_budget=0.02, tol_pos=1e-300, tol_rot=1e-300)
    assert res.wall_time < 10.0 and res.status.tolist().count("time_budget") >= 250
    for b in np.flatnonzero(res.success):  # met to 1e-300: to the last bit, log3's own rounding (1e-16) aside
        import pinocchio as pin

        dp, dr = youbot.tool_error(res.q[b], pin.SE3(targets[b]))
        assert dp <= 1e-300 and dr <= 1e-15
    started = ~np.isnan(res.q).any(axis=1)
    assert youbot.within_limits_batch(res.q[started]).all()


def test_a_target_too_far_for_floating_point_gets_a_finite_answer_from_every_solver():
    import pinocchio as pin

    ur5 = kinelab.load("ur5")
    target = pin.SE3(np.eye(3), np.array([1e200, 0.0, 0.0]))
    for solver in ("frdm", "biquat", "dls"):
        res = kinelab.solve(ur5, target, solver=solver, seed=0, time_budget=0.1)
        assert not res.success and res.status.value == "unreachable" and np.all(np.isfinite(res.q)), solver
        assert ur5.within_limits(res.q)


def test_an_orientation_task_ignores_the_point_it_is_given():
    """kinelab 0.1 declared task 'orientation' unreachable because of the ignored translation."""
    import pinocchio as pin

    ur5 = kinelab.load("ur5")
    R = pin.rpy.rpyToMatrix(0.3, 0.2, 0.1)
    target = pin.SE3(R, np.array([5.0, 0.0, 0.0]))  # 5 m out: beyond the UR5's reach, and irrelevant
    for res in (kinelab.solve(ur5, target, task="orientation", seed=0),
                kinelab.solve_batch(ur5, [target] * 2, task="orientation", seed=0)):
        q = np.atleast_2d(res.q)[0]
        assert bool(np.atleast_1d(res.success)[0])
        assert np.linalg.norm(pin.log3(R.T @ ur5.fk(q).rotation)) <= 1e-6


def test_each_round_of_solve_all_and_the_prefer_fallback_get_only_what_is_left(monkeypatch, no_tolerance_floor):
    """kinelab 0.1: solve_all ran every round unbounded (a whole round past the budget) and solve(prefer=) then
    started a fresh budget for its fallback (12× at 5 ms). Checked on the budgets handed down, not on a clock."""

    from kinelab.ik import branches, routes

    ur5 = kinelab.load("ur5")
    target = ur5.fk(ur5.random_q(5))

    class Clock:  # a clock that moves 7.5 ms per reading: no scheduler hiccup can fail the check
        now = 100.0
        first: float | None = None

        def perf_counter(self) -> float:
            self.now += 0.0075
            self.first = self.now if self.first is None else self.first
            return self.now

    clock = Clock()
    given: list[tuple[float, float]] = []  # (budget handed to a round, time left on the clock when it was handed)
    real_batch = branches.run_batch

    def spy_batch(robot, targets, q0, req):
        assert clock.first is not None
        given.append((req.time_budget, 0.05 - (clock.now - clock.first)))
        return real_batch(robot, targets, q0, req)

    monkeypatch.setattr(branches, "time", clock)
    monkeypatch.setattr(branches, "run_batch", spy_batch)
    kinelab.solve_all(ur5, target, solver="frdm", time_budget=0.05, tol_pos=1e-300, tol_rot=1e-300, seed=0)
    # kinelab 0.1 handed every round None; 0.05 s at 7.5 ms per reading leaves room for 6 rounds
    assert len(given) == 6 and all(budget is not None and budget <= left + 1e-12 for budget, left in given)
    monkeypatch.undo()

    fallback: list[float | None] = []
    real_one = routes.solve_one  # the fallback's one solve (through solve_clear_of, with no collision check)
    monkeypatch.setattr(routes, "solve_one", lambda robot, t, q0, req: fallback.append(req.time_budget)
                        or real_one(robot, t, q0, req))
    monkeypatch.setattr(routes, "time", Clock())  # the branch search took one reading's 7.5 ms of the 50 ms
    res = kinelab.solve(ur5, target, solver="frdm", prefer=np.zeros(6), time_budget=0.05, tol_pos=1e-300,
                        tol_rot=1e-300, seed=0)
    assert not res.success and fallback == [pytest.approx(0.05 - 0.0075, abs=1e-12)]


# --- #31: the fault and fuzz run of the core-issue round -------------------------------------------------------


def _honest(robot, q, status, oMtarget, tol=1e-6):
    """A row's status is what Pinocchio says of its q: converged means met within the limits, outside_limits met
    beyond one; no row of a started solve holds NaN."""
    assert np.isfinite(q).all(), q
    dp, dr = robot.tool_error(q, oMtarget)
    if status == "converged":
        assert dp <= tol and dr <= tol and robot.within_limits(q)
    elif status == "outside_limits":
        assert dp <= tol and dr <= tol and not robot.within_limits(q)


@pytest.mark.parametrize("name", ["ur5", "youbot"])
def test_use_limits_false_works_on_every_path(name):
    """#31.3: the compiled batch drew its starts between ±inf limits (NaN) and failed on every robot naming a Q
    the caller never passed; IK(use_limits=False).solve_batch spent its budget and returned nothing."""
    import pinocchio as pin

    robot = kinelab.load(name)
    targets = robot.fk_batch(robot.random_qs(12, 5))
    for batch in (kinelab.solve_batch(robot, targets, use_limits=False, seed=0),
                  kinelab.IK(robot, use_limits=False).solve_batch(targets, seed=0)):
        assert np.isin(batch.status, ["converged", "outside_limits"]).mean() >= 0.5, batch.status
        for b in range(len(targets)):
            _honest(robot, batch.q[b], str(batch.status[b]), pin.SE3(targets[b]))
    one = pin.SE3(targets[0])
    for res in [*kinelab.solve_all(robot, one, solver="frdm", use_limits=False, seed=0),
                *kinelab.solve_all(robot, one, use_limits=False, seed=0),  # "auto" with an FRDM option: FRDM
                kinelab.IK(robot, use_limits=False).solve(one, seed=1)]:
        _honest(robot, res.q, res.status.value, one)
    path = kinelab.track(robot, targets[:1], use_limits=False)
    _honest(robot, path.q[0], path.status[0], one)
    with pytest.raises(kinelab.OptionError, match="use_limits"):  # the closed form has no such setting: named
        kinelab.solve_all(robot, one, solver="analytic", use_limits=False)


def test_an_obstacle_file_is_bounded_in_size_depth_and_count(tmp_path):
    """#31.5: Environment.from_file("/dev/zero") read until memory ran out; a deeply nested JSON gave a
    RecursionError; 20,000 obstacles took > 150 s (Pinocchio's geometry model keeps an n × n pair table)."""
    import json

    from helpers import no_hang

    from kinelab.collision.obstacles import MAX_OBSTACLES, Environment, Obstacle, ObstacleError

    with no_hang(20), pytest.raises(ObstacleError, match="not a regular file"):
        Environment.from_file("/dev/zero")
    deep = tmp_path / "deep.json"
    for text in ("[" * 100_000 + "]" * 100_000, '{"obstacles": [' + "[" * 50 + "]" * 50 + "]}"):
        deep.write_text(text)
        with pytest.raises(ObstacleError, match="nested at most 4 deep"):
            Environment.from_file(deep)
    many = tmp_path / "many.json"
    many.write_text(json.dumps({"obstacles": [{"shape": "sphere", "size": [0.05], "xyz": [2, 0, 0]}] * 20_000}))
    with no_hang(20), pytest.raises(ObstacleError, match=f"lists 20000 obstacles; an environment holds at most "
                                                         f"{MAX_OBSTACLES}"):
        Environment.from_file(many)
    with pytest.raises(ObstacleError, match="at most"):
        Environment(tuple([Obstacle("sphere", (0.05,), (2.0, 0.0, 0.0))] * (MAX_OBSTACLES + 1)))
    many.write_text(json.dumps({"obstacles": [{"shape": "sphere", "size": [0.05], "xyz": [2, 0, k * 0.2]}
                                              for k in range(MAX_OBSTACLES)]}))
    ur5 = kinelab.load("ur5")
    with no_hang(120):  # the most an environment may hold is checked, not refused
        res = kinelab.solve(ur5, ur5.fk(ur5.random_q(0)), collisions=Environment.from_file(many), seed=0)
    assert res.status.value in ("converged", "collision")


def test_map_workers_are_capped_by_the_cores(capsys):
    """#31.5: map reach --workers 1000 started 1,000 processes and computed nothing."""
    from kinelab.maps import cluster

    assert cli.main(["map", "reach", "ur5", "--workers", "1000"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--workers must be 1 to {cluster.cores()}" in err
    with pytest.raises(KinelabError, match="workers must be 1 to"):
        cluster.client_for(None, cluster.cores() + 1)


def test_three_thousand_nested_srdf_groups_neither_recurse_nor_take_seconds(tmp_path):
    """#31.5: 3,000 nested SRDF groups still recursed (and the joint check was quadratic)."""
    from helpers import no_hang

    from kinelab.robot.srdf import read_srdf

    n = 3000
    groups = "".join(f'<group name="g{i}"><group name="g{i + 1}"/></group>' for i in range(n))
    path = tmp_path / "nested.srdf"
    path.write_text(f'<robot name="r">{groups}<group name="g{n}"><joint name="j1"/></group></robot>')
    with no_hang(20):
        srdf = read_srdf(path)
        assert srdf.group_joints("g0") == ["j1"]
        srdf.check_joints(["j1"])
        with pytest.raises(kinelab.SRDFError, match="names joint 'j1', which the robot does not have"):
            srdf.check_joints(["j2"])
    path.write_text(f'<robot name="r">{groups}<group name="g{n}"><group name="g0"/></group></robot>')
    with no_hang(20), pytest.raises(kinelab.SRDFError, match=r"group 'g0' includes itself \(g0 -> g1 -> g2"):
        read_srdf(path).check_joints(["j1"])


@pytest.mark.parametrize("where", ["/dev/zero", "folder"])
def test_a_robot_file_that_is_not_a_regular_file_is_refused_before_reading(tmp_path, where):
    from helpers import no_hang

    with no_hang(20), pytest.raises(kinelab.URDFError, match="not a regular file"):
        kinelab.load(where if where != "folder" else tmp_path)


def test_the_multistart_after_a_closed_form_that_found_nothing_gets_only_what_is_left(monkeypatch):
    """solve(prefer=) on crx10ia: the 1-D search found nothing at unmeetable tolerances and the multistart after
    it then counted a budget of its own from zero (p99 7.9 ms at 5 ms). Checked on a clock that moves 1 ms per
    reading: the multistart's budget starts where the closed form's time began, not after it."""
    from kinelab.ik import branches
    from kinelab.ik.request import make_request

    class Clock:
        now = 100.0

        def perf_counter(self) -> float:
            self.now += 0.001
            return self.now

    clock = Clock()
    monkeypatch.setattr(branches, "time", clock)

    def closed_form_spending_3_ms(*args, **kwargs):
        for _ in range(3):
            clock.perf_counter()
        return None  # "the multistart is to answer instead"

    seen: list[float] = []

    def spy_search(robot, target, req, max_solutions, stop_below, t0):
        seen.append(clock.now - t0)
        return [], 0

    monkeypatch.setattr(branches, "_closed_form_all", closed_form_spending_3_ms)
    monkeypatch.setattr(branches, "_search", spy_search)
    crx = kinelab.load("crx10ia", prepare=False)  # its readying would be spied on too
    req = make_request("frdm", 0, 1e-6, 1e-6, 0.005, 0, "refuse", None, "pose", "z", {})
    branches.find_all(crx, crx.fk(crx.random_q(0)), req, method=branches.Route.EITHER)
    assert len(seen) == 1 and seen[0] >= 0.004 - 1e-12  # the 3 ms spent and the closing reading, counted
