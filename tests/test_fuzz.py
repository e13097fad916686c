"""Fuzzing as a hostile user would: mutated URDFs, bad arguments to the public API, bad command lines.

Every case must end in an answer or in a KinelabError subclass (the CLI: exit 0, 1 or 2, one line on
stderr for 2, never a traceback). A success must survive Pinocchio's check. The CI runs a seeded subset;
``python tools/fuzz.py`` runs the long one (KINELAB_FUZZ_CASES sets the number of cases per test).
"""

import math
import os
import random
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinelab
from kinelab.robot import catalog

CASES = int(os.environ.get("KINELAB_FUZZ_CASES", "120"))
NUMBERS = ["nan", "inf", "-inf", "1e308", "1e-320", "0", "-1", "1e6", "abc", "", "1 2", "0 0 0", "1 nan 0"]


def _mutate(root: ET.Element, rng: random.Random) -> str:
    """One random change of a URDF tree; returns what was done."""
    elements = [e for e in root.iter() if e is not root]
    target = rng.choice(elements)
    kind = rng.choice(["attribute", "attribute", "attribute", "delete", "duplicate", "relink", "swap_limits"])
    if kind == "attribute" and target.attrib:
        key = rng.choice(sorted(target.attrib))
        target.set(key, rng.choice(NUMBERS + [target.get(key, "")[::-1]]))
    elif kind == "delete":
        parent = next(p for p in root.iter() if target in list(p))
        parent.remove(target)
    elif kind == "duplicate":
        parent = next(p for p in root.iter() if target in list(p))
        parent.append(ET.fromstring(ET.tostring(target)))
    elif kind == "relink":
        joints, links = root.findall("joint"), [link.get("name", "") for link in root.findall("link")]
        if joints and links:
            end = rng.choice(joints).find(rng.choice(["parent", "child"]))
            if end is not None:
                end.set("link", rng.choice(links + ["nosuch"]))
    elif kind == "swap_limits":
        for limit in root.iter("limit"):
            lo, hi = limit.get("lower"), limit.get("upper")
            if lo is not None and hi is not None:
                limit.set("lower", hi)
                limit.set("upper", lo)
                break
    return kind


def _check_robot(robot: kinelab.Robot) -> None:
    """A model that loaded must behave: finite FK, a proper rotation, finite limits with lower ≤ upper."""
    q = robot.neutral()
    oMtool = robot.fk(q)
    R = oMtool.rotation
    assert np.all(np.isfinite(oMtool.homogeneous))
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-9) and np.linalg.det(R) > 0.5
    assert np.all(robot.lower <= robot.upper)
    assert math.isfinite(robot.characteristic_length())


@pytest.mark.parametrize("name", ["stanford", "era", "youbot"])
def test_mutated_urdfs_load_or_are_refused_cleanly(tmp_path, name):
    path, _ = catalog.resolve(name)
    text = path.read_text()
    rng = random.Random(f"urdf-{name}")
    outcomes = {"loaded": 0, "refused": 0}
    for k in range(CASES):
        root = ET.fromstring(text)
        for _ in range(rng.randint(1, 3)):
            _mutate(root, rng)
        out = tmp_path / f"m{k}.urdf"
        out.write_bytes(ET.tostring(root))
        try:
            robot = kinelab.load(str(out), tool="tool")
        except kinelab.KinelabError:
            outcomes["refused"] += 1
            continue
        _check_robot(robot)
        outcomes["loaded"] += 1
    assert outcomes["loaded"] > 0 and outcomes["refused"] > 0  # the mutations reach both sides


BAD_VALUES = [None, -1, 0, 0.0, 1e-320, 1e308, float("nan"), float("inf"), -float("inf"), "x", [1, 2], (1.0,),
              {"a": 1}, True, 1 + 2j, np.float32(1.0), np.int64(3), 2.5, 100, 1e-6]
SOLVE_ARGUMENTS = ["tol_pos", "tol_rot", "time_budget", "max_restarts", "seed", "start_outside_limits"]
FRDM_OPTIONS = ["mode", "w_p", "w_p_factor", "w_axes", "order", "relax", "accel", "accel_memory", "max_sweeps",
                "eps_q", "stall_window", "stall_rel", "use_limits", "kicks", "intervals", "freeze", "policy",
                "active", "max_bypass_events", "polish", "trace"]
BIQUAT_OPTIONS = ["law", "k", "k0", "k_v", "integrator", "step", "max_time", "damping", "max_step", "max_steps",
                  "clamp", "record"]


@pytest.mark.parametrize("solver, options", [("frdm", FRDM_OPTIONS), ("biquat", BIQUAT_OPTIONS),
                                             ("dls", ["damping", "step", "max_iterations"])])
def test_bad_arguments_give_a_kinelab_error_or_an_honest_answer(solver, options):
    robot = kinelab.load("ur5")
    rng = random.Random(f"api-{solver}")
    counts = {"answered": 0, "refused": 0}
    for _ in range(CASES):
        kwargs = {}
        for name in rng.sample(SOLVE_ARGUMENTS + options, rng.randint(1, 2)):
            kwargs[name] = rng.choice(BAD_VALUES)
        target = robot.fk(robot.random_q(rng.randrange(1000)))
        kwargs.setdefault("time_budget", 0.05)
        try:
            res = kinelab.solve(robot, target, solver=solver, **kwargs)
        except kinelab.KinelabError:
            counts["refused"] += 1
            continue
        counts["answered"] += 1
        dp, dr = robot.tool_error(res.q, target)
        assert np.all(np.isfinite(res.q))
        if res.success:  # a success is Pinocchio's verdict at the tolerances that were asked for
            assert dp <= kwargs.get("tol_pos", 1e-6) and dr <= kwargs.get("tol_rot", 1e-6)
            assert robot.within_limits(res.q)
    assert counts["refused"] > 0 and counts["answered"] > 0


CLI_WORDS = ["ur5", "so101", "era", "nosuch", "0", "1e308", "nan", "-1", "x", "--deg", "--json", "--seed", "-1",
             "--tol-pos", "inf", "--time-budget", "0", "--target-xyz", "0.3", "0.2", "0.4", "--solver", "biquat",
             "--sweep", "5", "--n", "0", "--out", "/proc/x", "--kick", "joint4=abc", "--tool", "nosuch"]


def test_bad_command_lines_end_in_one_line_and_exit_2_or_run():
    rng = random.Random("cli")
    cases = max(6, CASES // 20)
    for _ in range(cases):
        command = rng.choice(["fk", "ik", "singular", "info", "validate", "animate"])
        argv = [command, *rng.sample(CLI_WORDS, rng.randint(1, 6))]
        proc = subprocess.run([sys.executable, "-m", "kinelab.cli", *argv], capture_output=True, text=True,
                              timeout=300, env={**os.environ, "PYTHONWARNINGS": "ignore"})
        assert "Traceback" not in proc.stderr, (argv, proc.stderr)
        assert proc.returncode in (0, 1, 2), (argv, proc.returncode)
        if proc.returncode == 2:
            lines = proc.stderr.strip().splitlines()
            assert len(lines) == 1 and re.match(r"(kinelab: error:|usage:)", lines[0]), (argv, proc.stderr)
