"""What a command loads before it answers (#43 item 9): the parsers need neither NumPy nor Pinocchio, a multistart
solve neither the collision model nor the closed forms nor SciPy's k-d tree, ``info`` no collision meshes unless
asked. Each case runs in a fresh interpreter and reads its ``sys.modules``; the times are in ``kinelab bench
--startup``, not here."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from kinelab.errors import KinelabError
from kinelab.report.bench import startup

UR5_Q = ["0", "-1.57", "1.57", "0", "0", "0"]
PROBE = """
import contextlib, io, json, sys
from kinelab.cli.main import main
with contextlib.redirect_stdout(io.StringIO()):
    try:
        code = main(sys.argv[1:])
    except SystemExit as stop:
        code = stop.code
print(json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def _loaded(*argv: str) -> tuple[int, set[str]]:
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, timeout=120,
                          check=True)
    out = json.loads(done.stdout.strip().splitlines()[-1])
    return out["code"], set(out["modules"])


def _under(modules: set[str], package: str) -> list[str]:
    return sorted(m for m in modules if m == package or m.startswith(package + "."))


@pytest.mark.parametrize("argv", [["--help"], ["robots"], ["ik", "--help"], ["nosuch"]])
def test_the_parsers_and_the_robot_list_load_neither_numpy_nor_pinocchio(argv):
    code, modules = _loaded(*argv)
    assert code in (0, 2)
    assert not _under(modules, "pinocchio") and not _under(modules, "numpy"), argv


def test_a_named_command_imports_only_its_own_command_module():
    _, modules = _loaded("robots")
    assert "kinelab.cli.robots" in modules
    assert not {"kinelab.cli.ik", "kinelab.cli.bench", "kinelab.cli.maps", "kinelab.cli.view"} & modules


def test_a_multistart_ik_loads_no_collision_model_closed_form_or_kd_tree():
    code, modules = _loaded("ik", "ur5", "--target-q", *UR5_Q, "--solver", "frdm")
    assert code == 0
    assert not _under(modules, "kinelab.collision"), _under(modules, "kinelab.collision")
    assert not _under(modules, "kinelab.ik.analytic")
    assert not _under(modules, "scipy.spatial")
    assert not {"kinelab.ik.clear", "kinelab.ik.starts", "kinelab.ik.frdm.tracking"} & modules


def test_the_closed_form_and_the_collision_model_still_load_when_asked_for():
    code, modules = _loaded("ik", "ur5", "--target-q", *UR5_Q, "--solver", "analytic", "--collisions")
    assert code == 0
    assert "kinelab.ik.analytic.branches" in modules and "kinelab.collision.model" in modules


def test_info_builds_the_collision_model_only_with_collisions():
    code, modules = _loaded("info", "ur5")
    assert code == 0 and not _under(modules, "kinelab.collision")
    code, modules = _loaded("info", "ur5", "--collisions")
    assert code == 0 and "kinelab.collision.model" in modules


def test_the_startup_table_calls_met_only_what_every_round_meets():
    rows = [{"command": "a", "best_ms": 50.0, "ratio": 0.4, "median_ratio": 0.42, "lowest": 0.35, "highest": 0.45,
             "goal": 1.3},
            {"command": "b", "best_ms": 160.0, "ratio": 1.25, "median_ratio": 1.35, "lowest": 1.2, "highest": 1.4,
             "goal": 1.3},
            {"command": "c", "best_ms": 230.0, "ratio": 1.7, "median_ratio": 1.75, "lowest": 1.65, "highest": 1.8,
             "goal": 1.6},
            {"command": "d", "best_ms": 150.0, "ratio": 1.1, "median_ratio": 1.2, "lowest": 1.05, "highest": 1.5,
             "goal": 1.3}]
    table = startup.markdown({"baseline": startup.BASELINE, "baseline_ms": 130.0, "rounds": 7, "commands": rows})
    verdicts = [line.rsplit("(", 1)[1].rstrip(") |") for line in table.splitlines() if line.startswith("| `")]
    assert verdicts == ["met", "best met", "missed", "best and median met"]


def test_a_command_that_fails_is_an_error_not_a_time():
    with pytest.raises(KinelabError, match="exited with 3"):
        startup._seconds([sys.executable, "-c", "import sys; sys.exit(3)"], {})


def test_the_subpackages_are_attributes_of_the_package_as_before():
    """``import kinelab`` then ``kinelab.robot.catalog`` (or ``kinelab.ik``, ``kinelab.maps``) worked while the
    package imported the robot eagerly; lazily, each is imported when first read."""
    probe = ("import kinelab, sys; assert 'pinocchio' not in sys.modules; "
             "print(kinelab.robot.catalog.names()[0], kinelab.ik.__name__, kinelab.maps.__name__, "
             "kinelab.robot.chain.Chain.__name__)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120, check=True)
    assert done.stdout.split() == ["stanford", "kinelab.ik", "kinelab.maps", "Chain"]  # the chain class, since #58
    with pytest.raises(AttributeError, match="has no attribute 'nosuch'"):
        import kinelab

        kinelab.nosuch  # noqa: B018


BLAS_PROBE = """
import sys
import numpy as np
import kinelab
from kinelab.core import _blas
{patch}
robot = kinelab.load("ur5")
q = np.array([0.3, -1.2, 1.4, -0.5, 0.9, 0.2])
r = kinelab.solve(robot, robot.fk(q), solver="frdm", seed=1)
err = float(np.linalg.norm(robot.fk(r.q).translation - robot.fk(q).translation))
print(_blas.source(), "scipy" in sys.modules, r.success, err < 1e-6)
"""


def _blas_run(patch: str = "") -> list[str]:
    done = subprocess.run([sys.executable, "-c", BLAS_PROBE.format(patch=patch)], capture_output=True, text=True,
                          timeout=120, check=True)
    return done.stdout.split()


def test_a_solve_takes_blas_from_scipys_bundled_openblas_without_importing_scipy():
    if _blas_run("print(_blas._bundled_library() is not None)")[0] != "True":
        pytest.skip("this SciPy bundles no OpenBLAS (the capsules serve: the next test)")
    assert _blas_run() == ["bundled", "OpenBLAS", "False", "True", "True"]


def test_without_a_bundled_openblas_the_capsules_serve_the_same_answers():
    assert _blas_run("_blas._bundled_library = lambda: None") == ["SciPy's", "capsules", "True", "True", "True"]


def test_the_router_table_calls_met_only_what_every_round_meets():
    from kinelab.report.bench import router

    rows = [{"robot": "ur5", "solver": "frdm", "entry": "solve_batch", "ratio": 1.01, "lowest": 0.97, "highest": 1.05},
            {"robot": "ur5", "solver": "frdm", "entry": "track", "ratio": 0.99, "lowest": 0.90, "highest": 1.10},
            {"robot": "ur5", "solver": "auto", "entry": "solve_all", "ratio": 0.80, "lowest": 0.70, "highest": 0.90}]
    table = router.markdown(rows).splitlines()
    verdicts = [line.rsplit("|", 2)[1].strip() for line in table if line.startswith("| ur5")]
    assert verdicts == ["met", "median met", "missed"]
