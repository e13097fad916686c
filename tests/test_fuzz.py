"""Fuzzing as a hostile user would: mutated URDFs, bad arguments to the public API, bad command lines.

Every case must end in an answer or in a KinelabError subclass (the CLI: exit 0, 1 or 2, one line on
stderr for 2, never a traceback). A success must survive Pinocchio's check. The CI runs a seeded subset;
``python tools/fuzz.py`` runs the long one (KINELAB_FUZZ_CASES sets the number of cases per test).
"""

import contextlib
import functools
import json
import math
import numbers
import os
import random
import re
import signal
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinelab
from kinelab.robot import catalog

CASES = int(os.environ.get("KINELAB_FUZZ_CASES", "120"))
HANG = 60  # [s] a case still running after this is a hang


class Tally:
    """Outcomes per class: a clean KinelabError, an accepted call, a raw exception, a hang, and nonsense accepted
    (a call that returned although an argument was outside what it accepts). Written to KINELAB_FUZZ_REPORT
    (a JSON lines file) when set, so that ``tools/fuzz.py`` can print the table."""

    def __init__(self, name: str):
        self.name = name
        self.counts = {"cases": 0, "clean": 0, "accepted": 0, "raw": 0, "hangs": 0, "nonsense_accepted": 0}
        self.raw: list[str] = []

    def run(self, call, nonsense: bool = False):
        """Call ``call()`` and count its outcome; returns its result, or None."""
        self.counts["cases"] += 1
        signal.signal(signal.SIGALRM, _hang)
        signal.alarm(HANG)
        try:
            out = call()
        except kinelab.KinelabError:
            self.counts["clean"] += 1
            return None
        except _HangError:
            self.counts["hangs"] += 1
            return None
        except Exception as exc:  # noqa: BLE001 - counting raw exceptions is the point
            self.counts["raw"] += 1
            self.raw.append(f"{type(exc).__name__}: {exc}"[:200])
            return None
        finally:
            signal.alarm(0)
        self.counts["accepted"] += 1
        self.counts["nonsense_accepted"] += bool(nonsense)
        return out

    def close(self) -> dict[str, int]:
        """Write the counts (when asked) and return them."""
        report = os.environ.get("KINELAB_FUZZ_REPORT")
        if report:
            with open(report, "a") as f:
                f.write(json.dumps({"class": self.name, **self.counts}) + "\n")
        return self.counts


def _faults(tally: Tally) -> str:
    """What went wrong over the tally's cases: a raw exception, a hang, nonsense accepted, or cases that never
    reached one side (refused and answered); "" when none."""
    counts = tally.close()
    if counts["raw"]:
        return f"raw exceptions: {tally.raw[:5]}"
    if counts["hangs"] or counts["nonsense_accepted"]:
        return f"hangs or nonsense accepted: {counts}"
    if not (counts["clean"] > 0 and counts["accepted"] > 0):
        return f"the cases reached one side only: {counts}"
    return ""


class _HangError(Exception):
    pass


def _hang(*_):
    raise _HangError
NUMBERS = ["nan", "inf", "-inf", "1e308", "1e-320", "0", "-1", "1e6", "abc", "", "1 2", "0 0 0", "1 nan 0"]


def _mutate(root: ET.Element, rng: random.Random) -> str:
    """One random change of a URDF tree; returns what was done."""
    elements = [e for e in root.iter() if e is not root]
    if not elements:  # everything was deleted already
        return "none"
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
            with warnings.catch_warnings(record=True) as said:  # a mutated file's parser warnings, asked for
                warnings.simplefilter("always")
                robot = kinelab.load(str(out), tool="tool")
        except kinelab.KinelabError:
            outcomes["refused"] += 1
            continue
        assert all("\n" not in str(w.message) for w in said)  # each one line, as the CLI shows it
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
             "--sweep", "5", "--n", "0", "--out", "/proc/x", "--kick", "joint4=abc", "--tool", "nosuch",
             "--voxel", "1e-9", "--samples", "--html", "/proc/y.html", "--scheduler", "abc", "--trust-xacro",
             "--xacro-arg", "a=1", "--base", "--step", "--grasp"]
COMMANDS = ["fk", "ik", "singular", "info", "validate", "animate", "robots", "view", "map singular", "map reach",
            "map base", "bench"]


def test_bad_command_lines_end_in_one_line_and_exit_2_or_run():
    rng = random.Random("cli")
    cases = max(12, CASES // 10)
    for _ in range(cases):
        command = rng.choice(COMMANDS).split()
        argv = [*command, *rng.sample(CLI_WORDS, rng.randint(1, 6))]
        proc = subprocess.run([sys.executable, "-m", "kinelab.cli", *argv], capture_output=True, text=True,
                              timeout=300, env={**os.environ, "PYTHONWARNINGS": "ignore"})
        assert "Traceback" not in proc.stderr, (argv, proc.stderr)
        assert proc.returncode in (0, 1, 2), (argv, proc.returncode)
        if proc.returncode == 2:
            lines = proc.stderr.strip().splitlines()
            assert len(lines) == 1 and re.match(r"(kinelab: error:|usage:)", lines[0]), (argv, proc.stderr)


# -- every entry point: the same bad values, each outcome counted ---------------------------------------------

def _positive(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(float(v)) and float(v) > 0


def _count(v, least: int = 0) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool) and int(v) >= least


VALID = {  # what each keyword accepts; any other value accepted silently is counted as nonsense accepted
    "tol_pos": _positive, "tol_rot": _positive, "time_budget": lambda v: v is None or _positive(v),
    "max_restarts": _count, "seed": lambda v: v is None or _count(v),
    "task": lambda v: v in ("pose", "position", "axis", "orientation"), "axis": lambda v: v in ("x", "y", "z"),
    "start_outside_limits": lambda v: v in ("project", "refuse"),
    "max_solutions": lambda v: v is None or _count(v, 1), "jump_limit": lambda v: v is None or _positive(v),
    "hold": lambda v: _count(v, 1), "rest_weight": lambda v: v is None or (_positive(v) or v == 0),
}
WORDS = ["pose", "position", "axis", "orientation", "x", "y", "z", "project", "refuse", "POSE", ""]
ENTRY = {
    "solve_batch": ["tol_pos", "tol_rot", "time_budget", "max_restarts", "seed", "task", "axis"],
    "solve_all": ["tol_pos", "tol_rot", "time_budget", "seed", "task", "axis", "max_solutions"],
    "track": ["tol_pos", "tol_rot", "time_budget", "seed", "task", "axis", "jump_limit", "hold", "rest_weight"],
    "solve": ["tol_pos", "tol_rot", "time_budget", "max_restarts", "seed", "task", "axis", "start_outside_limits"],
}


@pytest.mark.parametrize("entry", list(ENTRY))
def test_every_entry_point_counts_no_raw_error_hang_or_nonsense_accepted(entry):
    robot = kinelab.load("ur5")
    rng = random.Random(f"entry-{entry}")
    tally = Tally(f"api.{entry}")
    for _ in range(max(10, CASES // 3)):
        kwargs = {name: rng.choice(BAD_VALUES + WORDS) for name in rng.sample(ENTRY[entry], rng.randint(1, 2))}
        kwargs.setdefault("time_budget", 0.02)
        nonsense = not all(VALID[name](value) for name, value in kwargs.items())
        if _positive(kwargs["time_budget"]):  # a valid but long budget is a long run, not a fuzz case
            kwargs["time_budget"] = min(float(kwargs["time_budget"]), 0.05)
        q = robot.random_q(rng.randrange(1000))
        target = robot.fk(q)
        out = tally.run(functools.partial(_call_entry, entry, robot, target, q, kwargs), nonsense)
        _check_successes(robot, out, target, kwargs)
    assert _faults(tally) == ""


def _call_entry(entry, robot, target, q, kwargs):
    if entry == "solve":
        return kinelab.solve(robot, target, **kwargs)
    if entry == "solve_batch":
        return kinelab.solve_batch(robot, [target] * 3, **kwargs)
    if entry == "solve_all":
        return kinelab.solve_all(robot, target, **kwargs)
    return kinelab.track(robot, [target, target], q0=q, **kwargs)


def _check_successes(robot, out, target, kwargs) -> None:
    """Whatever came back: every success is Pinocchio's verdict at the tolerances asked for, on a finite q."""
    if out is None:
        return
    rows = out if isinstance(out, list) else [out]
    for res in rows:
        q = np.atleast_2d(res.q)
        ok = np.atleast_1d(res.reached if hasattr(res, "reached") else res.success)
        for qb, good in zip(q, ok, strict=True):
            if good and kwargs.get("task", "pose") == "pose":
                dp, dr = robot.tool_error(qb, target)  # log3 rounds at ~1e-16: a tolerance below that is met exactly
                assert dp <= max(kwargs.get("tol_pos", 1e-6), 1e-15) and dr <= max(kwargs.get("tol_rot", 1e-6), 1e-15)
                assert robot.within_limits(qb)


LOAD_VALUES = [None, "", "nosuch", 5, 1.5, {"a": 1}, ["x"], {"shoulder_pan_joint": float("nan")},
               {"shoulder_pan_joint": 9.0}, {"nosuch": 0.0}, "tool0", "base_link", "/nonexistent", True]


def test_load_variants_count_no_raw_error_hang_or_nonsense_accepted(tmp_path):
    rng = random.Random("load")
    tally = Tally("load")
    for _ in range(max(10, CASES // 3)):
        kwargs = {name: rng.choice(LOAD_VALUES) for name in rng.sample(
            ["tool", "base", "locked", "package_dirs", "srdf", "group", "xacro_args"], rng.randint(1, 2))}
        nonsense = bool(kwargs.get("xacro_args"))  # a plain URDF reads no xacro argument: saying nothing would lie
        robot = tally.run(lambda kw=kwargs: kinelab.load("ur5", **kw), nonsense)
        if robot is not None:
            _check_robot(robot)
    assert _faults(tally) == ""


def test_map_functions_count_no_raw_error_hang_or_nonsense_accepted():
    from kinelab import maps

    ur5, youbot = kinelab.load("ur5"), kinelab.load("youbot")
    grasp = youbot.fk(youbot.display_q())
    rng = random.Random("maps")
    tally = Tally("maps")
    small = {"voxel": [0.5], "orientations": [1, 2], "samples": [5, 10], "step": [0.3], "restarts": [0, 2],
             "seed": [0, 3], "chunk_voxels": [8]}
    for _ in range(max(9, CASES // 4)):
        kind = rng.choice(["reachability", "singularity", "base_map"])
        names = {"reachability": ["voxel", "orientations", "restarts", "seed", "chunk_voxels"],
                 "singularity": ["samples", "seed"], "base_map": ["step", "restarts", "seed"]}[kind]
        kwargs = {name: rng.choice(small[name]) for name in names}
        bad = rng.choice(names)
        kwargs[bad] = rng.choice(BAD_VALUES)
        valid = _positive(kwargs[bad]) if bad in ("voxel", "step") else _count(kwargs[bad], 0 if bad in (
            "restarts", "seed") else 1)
        if valid and bad in ("voxel", "step"):
            kwargs[bad] = max(float(kwargs[bad]), 0.3)  # a valid but tiny grid is a long run, not a fuzz case
        calls = {"reachability": lambda kw=kwargs: maps.reachability(ur5, **kw),
                 "singularity": lambda kw=kwargs: maps.singularity(ur5, **{**kw, "samples": min(kw["samples"], 50)}
                                                                   if _count(kw["samples"]) else kw),
                 "base_map": lambda kw=kwargs: maps.base_map(youbot, grasp, **kw)}
        tally.run(calls[kind], nonsense=not valid)
    assert _faults(tally) == ""


MJCF = """<mujoco model="m"><compiler angle="radian"/><worldbody>
<body name="b0"><body name="b1" pos="0 0 0.3"><joint name="q1" type="hinge" axis="0 0 1" range="-2 2"/>
<body name="b2" pos="0 0.1 0.2" quat="1 0 0 0"><joint name="q2" type="hinge" axis="0 1 0" range="-1.5 1.5"/>
<body name="b3" pos="0 0 0.25"><joint name="q3" type="slide" axis="0 0 1" range="0 0.2"/>
<body name="tip" pos="0 0 0.1"/></body></body></body></body></worldbody></mujoco>"""
SRDF = """<robot name="ur5"><group name="arm"><chain base_link="base_link" tip_link="tool0"/></group>
<group name="all"><group name="arm"/><joint name="shoulder_pan_joint"/></group>
<group_state name="home" group="arm"><joint name="shoulder_pan_joint" value="0"/>
<joint name="shoulder_lift_joint" value="-1.5"/><joint name="elbow_joint" value="1"/>
<joint name="wrist_1_joint" value="0"/><joint name="wrist_2_joint" value="0"/><joint name="wrist_3_joint" value="0"/>
</group_state><end_effector name="hand" parent_link="tool0" group="arm"/></robot>"""


@pytest.mark.parametrize("kind", ["mjcf", "srdf"])
def test_mutated_mjcf_and_srdf_files_count_no_raw_error_or_hang(tmp_path, kind):
    rng = random.Random(f"file-{kind}")
    tally = Tally(f"files.{kind}")
    for k in range(max(10, CASES // 2)):
        root = ET.fromstring(MJCF if kind == "mjcf" else SRDF)
        for _ in range(rng.randint(1, 3)):
            _mutate(root, rng)
        path = tmp_path / f"m{k}.{'xml' if kind == 'mjcf' else 'srdf'}"
        path.write_bytes(ET.tostring(root))
        if kind == "mjcf":
            robot = tally.run(lambda p=path: kinelab.load(str(p)))
            if robot is not None:
                _check_robot(robot)
        else:
            robot = tally.run(lambda p=path: kinelab.load("ur5", srdf=str(p), group="arm"))
            if robot is not None:
                with contextlib.suppress(kinelab.KinelabError):
                    assert np.all(np.isfinite(robot.named_q("home")))
    assert _faults(tally) == ""


def test_the_fuzz_run_prints_no_warning_it_did_not_ask_for():
    """kinelab 0.2's test run ended with ~120 lines of the mutated files' parser warnings."""
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", __file__, "-k",
                           "mutated_urdfs"], capture_output=True, text=True, timeout=600,
                          env={**os.environ, "KINELAB_FUZZ_CASES": "30"})
    assert done.returncode == 0, done.stdout[-2000:]
    assert "warnings summary" not in done.stdout and " warning" not in done.stdout.splitlines()[-1]
