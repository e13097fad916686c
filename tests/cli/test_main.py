import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers import interruptible

import kinelab
from kinelab import cli
from kinelab.cli.common import plural as _plural
from kinelab.studies import paper001_stanford as seed001


def run(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_robots_lists_bundled_and_arms(capsys):
    code, out, _ = run(capsys, "robots", "--json")
    names = [r["name"] for r in json.loads(out)]
    assert code == 0 and names[:3] == ["stanford", "era", "youbot"] and "panda" in names


def test_info_youbot_lists_the_papers_joints_and_limits_in_degrees(capsys):
    code, out, _ = run(capsys, "info", "youbot")
    assert code == 0 and "8 DOF" in out
    rows = [line.split() for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert [r[1] for r in rows] == ["platform_x", "platform_y", "platform_yaw", "arm_joint_1",
                                    "arm_joint_2", "arm_joint_3", "arm_joint_4", "arm_joint_5"]
    limits = [(float(r[3]), float(r[5])) for r in rows[3:]]
    assert limits == [(-169, 169), (-65, 90), (-151, 146), (-102.5, 102.5), (-167.5, 167.5)]
    assert all(r[4] == "deg" for r in rows[3:])


def test_info_json_is_stable(capsys):
    code, out, _ = run(capsys, "info", "youbot", "--json")
    info = json.loads(out)
    assert code == 0 and info["dof"] == 8 and info["nq"] == 9
    j = info["joints"][5]
    assert j["name"] == "arm_joint_3" and j["lower_deg"] == pytest.approx(-151) and j["unit"] == "rad"
    assert info["collisions"] is None  # the collision model is built only when asked for (its meshes load)
    code, out, _ = run(capsys, "info", "youbot", "--json", "--collisions")
    assert json.loads(out)["collisions"].startswith("none (youbot has no collision geometry")
    code, out, _ = run(capsys, "info", "panda", "--json", "--collisions")
    assert json.loads(out)["collisions"].startswith("17 collision object(s) of panda, 0 obstacle(s); 75 pairs")


def test_info_names_the_closed_form_the_search_or_the_joint_a_7r_arm_holds(capsys):
    lines = {}
    for name in ("ur5", "kinova", "panda", "youbot", "xarm6", "baxter_left"):
        code, out, _ = run(capsys, "info", name, "--verbose")  # the class and its method: the solver's terms
        assert code == 0
        lines[name] = next(line for line in out.splitlines() if line.startswith("branches: "))
    assert lines["ur5"] == ("branches: 6R, axes 2, 3, 4 parallel, axes 5 and 6 meeting: every branch in closed form "
                            "(certified: each branch proved a root, the set every root unless a double root is met)")
    assert "spherical wrist" in lines["kinova"] and "every branch in closed form (certified" in lines["kinova"]
    assert lines["panda"].startswith("branches: with joint 7 (panda_joint7) held: ")
    assert "redundancy=K" in lines["panda"] and lines["youbot"].startswith("branches: none")
    assert lines["xarm6"] == ("branches: 6R, axes 2, 3 parallel, axes 4, 5 meeting: every branch by a 1-D search "
                              "over joint 6 (measured complete; certified by 16 proved branches, or where the general "
                              "elimination takes the chain by its certified set)")
    assert lines["baxter_left"].startswith("branches: with joint 1 (left_s0) held: ") and "1-D search" in \
        lines["baxter_left"]


def test_fk_stanford_matches_the_papers_rotation(capsys):
    code, out, _ = run(capsys, "fk", "stanford", "20", "40", "0.3", "-35", "60", "-45", "--deg", "--json")
    pose = json.loads(out)
    assert code == 0
    assert seed001.quat_distance_wxyz(pose["quat_wxyz"], seed001.N_REAL_WXYZ) < 1e-5
    assert pose["quat_wxyz"][0] >= 0
    assert pose["q"][2] == 0.3  # --deg leaves the prismatic joint in metres
    R = np.array(pose["rotation_matrix"])
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("argv, needle", [
    (["info", "nosuch"], "registered robots are: stanford"),
    (["fk", "stanford", "1", "2"], "must have 6 numbers"),
    (["fk", "stanford", "0", "0", "nan", "0", "0", "0"], "finite"),
    (["singular", "stanford", "0", "0", "2", "0", "0", "0"], "outside its limits"),  # fk computes and says so
    (["fk", "ur5", "0", "0", "0", "0", "0", "0", "--tool", "flange"], "unknown frame 'flange'"),
    (["fk", "stanford", "0", "x"], "'x' is not a number"),
    (["nosuchcommand"], "invalid choice"),
    (["animate", "era-knee"], "passages are: era-elbow, era-wrist, era-shoulder"),
])
def test_user_errors_print_one_line_and_exit_2(argv, needle):
    proc = subprocess.run([sys.executable, "-m", "kinelab.cli", *argv], capture_output=True, text=True,
                          env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinelab: error:") and needle in lines[0]
    assert proc.stdout == ""


def test_ik_reaches_the_papers_stanford_target_and_reports_pinocchios_errors(capsys):
    code, out, _ = run(capsys, "ik", "stanford", "--target-q", "20", "40", "0.3", "-35", "60", "-45",
                       "--start-q", "-30", "15", "0.1", "36", "-90", "45", "--deg", "--json")
    res = json.loads(out)
    assert code == 0 and res["success"] and res["status"] == "converged"
    assert res["position_error_m"] <= 1e-6 and res["rotation_error_rad"] <= 1e-6


def test_ik_says_what_its_time_measured_and_prints_frdm_s_monitor_for_frdm_alone(capsys):
    q = ["0.3", "-1.2", "1.0", "-0.5", "0.8", "0.2"]
    code, out, _ = run(capsys, "ik", "ur5", "--target-q", *q, "--solver", "analytic")
    assert code == 0 and "ms (one call, first-call costs included" in out and "monitor" not in out
    code, out, _ = run(capsys, "ik", "ur5", "--target-q", *q, "--seed", "0", "--start-q", "random", "--verbose",
                       "--solver", "frdm")
    assert code == 0 and "ms (one call, first-call costs included" in out and "monitor did not fire" in out
    assert "method frdm" in out


def test_ik_and_info_speak_plain_words_unless_verbose(capsys):
    """#60 item 3: "mode frdm+newton", "monitor did not fire", "no class holds to its tolerances" were routine
    output; they are the solver's terms, printed under --verbose (and kept in JSON)."""
    code, out, _ = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6")
    assert code == 0 and "mode" not in out and "method" not in out and "monitor" not in out
    code, out, _ = run(capsys, "info", "youbot")
    assert "no class holds" not in out and "no formula fits this arm's geometry" in out
    code, out, _ = run(capsys, "info", "youbot", "--verbose")
    assert "no class holds to its tolerances" in out
    code, out, _ = run(capsys, "branches", "crx10ia", "--target-q", "0.3", "0.5", "0.2", "0.4", "0.6", "0.1")
    assert "complete:" not in out and "not proved" in out and "one-dimensional search" in out
    code, out, _ = run(capsys, "branches", "panda", "--target-q", "0", "-0.5", "0", "-2", "0", "1.5", "0.7")
    assert "its configurations form a continuum" in out and "--redundancy K" in out  # samples, not "the" branches
    code, out, err = run(capsys, "fk", "ur5")
    assert code == 2 and "shape" not in err and "got none" in err
    code, out, err = run(capsys, "fk", "ur5", "1", "2", "3")
    assert code == 2 and "got 3 numbers" in err


def test_ik_beyond_reach_is_unreachable_with_exit_1(capsys):
    code, out, _ = run(capsys, "ik", "ur5", "--target-xyz", "3", "0", "0", "--json")
    res = json.loads(out)
    assert code == 1 and not res["success"] and res["status"] == "unreachable"


@pytest.mark.parametrize("argv, needle", [
    (["ik", "ur5"], "give the target"),
    (["ik", "ur5", "--target-xyz", "0.3", "0", "0.3", "--solver", "magic"], "unknown solver 'magic'"),
    (["ik", "stanford", "--target-q", "0", "0", "5", "0", "0", "0"], "outside its limits"),
    (["ik", "era", "--target-xyz", "4", "2", "6", "--kick", "joint9=-0.01"], "joints are: joint1"),
    (["ik", "era", "--target-xyz", "4", "2", "6", "--kick", "joint4"], "--kick wants JOINT=DELTA"),
    (["ik", "era", "--target-xyz", "4", "2", "6", "--interval", "joint5=80"], "wants JOINT=LOWER:UPPER"),
    (["ik", "era", "--target-xyz", "4", "2", "6", "--interval", "joint5=1:-1"], "is empty"),
    (["ik", "panda", "--target-xyz", "0.4", "0.2", "0.5", "--target-rpy", "180", "0", "0"], "looks like degrees"),
    (["ik", "panda", "--target-q", "0", "30", "0", "-90", "0", "90", "45"], "add --deg"),
    (["fk", "panda", "0", "30", "0", "-90", "0", "90", "45"], "30 for panda_joint2 looks like degrees"),
    (["ik", "era", "--target-xyz", "4", "2", "6", "--freeze", "joint1=x"], "is not a number"),
    (["ik", "era", "--solver", "dls", "--target-xyz", "4", "2", "6", "--freeze", "joint1"], "bypasses of --solver"),
])
def test_ik_user_errors(capsys, argv, needle):
    code, _, err = run(capsys, *argv)
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1


def test_ik_biquat_reproduces_seed_001_and_prints_model_time_and_M0(capsys):
    code, out, _ = run(capsys, "ik", "stanford", "--solver", "biquat", "--target-q", "20", "40", "0.3", "-35", "60",
                       "-45", "--start-q", "-30", "15", "0.1", "36", "-90", "45", "--deg", "--json")
    res = json.loads(out)
    assert code == 0 and res["success"]
    assert res["position_error_m"] <= 1e-6 and res["rotation_error_rad"] <= 1e-6
    assert res["info"]["model_time"] > 0 and res["info"]["M0"] == pytest.approx(-1.0, abs=1e-6)
    code, out, _ = run(capsys, "ik", "stanford", "--solver", "biquat", "--target-q", "20", "40", "0.3", "-35", "60",
                       "-45", "--start-q", "-30", "15", "0.1", "36", "-90", "45", "--deg")
    assert "model time" in out and "M0 = -1.000000" in out


def test_singular_at_a_configuration_reports_rank_and_lost_motion(capsys):
    code, out, _ = run(capsys, "singular", "youbot", "0", "0", "0", "30", "0", "0", "40", "10", "--deg", "--json")
    res = json.loads(out)
    assert code == 0 and res["rank"] == 5 and res["singular"] and len(res["lost_directions"]) == 1


def test_singular_sweep_lists_families(capsys):
    code, out, _ = run(capsys, "singular", "youbot", "--sweep", "3000", "--seed", "1", "--json")
    res = json.loads(out)
    assert code == 0 and res["families"]
    assert any(f["relations"] == ["arm_joint_2 = 0", "arm_joint_3 = 0"] for f in res["families"])


@pytest.mark.parametrize("argv, needle", [
    (["singular", "youbot"], "give a configuration"),
    (["singular", "youbot", "1", "2"], "8 numbers"),
    (["singular", "youbot", "--sweep", "0"], "at least one sample"),
])
def test_singular_user_errors(capsys, argv, needle):
    code, _, err = run(capsys, *argv)
    assert code == 2 and needle in err


def test_animate_the_shoulder_passage_writes_html_and_reports_the_jump(capsys, tmp_path):
    code, out, _ = run(capsys, "animate", "era-shoulder", "--without-bypass", "--html", str(tmp_path / "s.html"))
    assert code == 0 and (tmp_path / "s.html").stat().st_size > 10_000
    assert "216 of 217 samples reached (1 met by a jump)" in out  # the whole turn is a jump since #57
    assert float(out.split("largest joint step ")[1].split()[0]) > 6.0  # q1 swinging back a whole turn


def test_ik_bypass_flags_reach_the_solver_in_radians(capsys):
    era = kinelab.load("era")
    target_q = np.deg2rad([10, 20, 30, -60, 30, 10, 5])
    code, out, _ = run(capsys, "ik", "era", "--target-q", *map(str, np.rad2deg(target_q)), "--deg",
                       "--start-q", "0", "0", "0", "0", "0", "0", "0", "--kick", "joint4=-1", "--json")
    res = json.loads(out)
    assert code == 0 and res["success"]
    assert era.tool_error(np.array(res["q"]), era.fk(target_q))[0] <= 1e-6
    assert any(b["bypass"] == "kicks" for b in res["bypasses"])
    from kinelab.ik import solve

    same = solve(era, era.fk(target_q), q0=np.zeros(7), seed=0, kicks={"joint4": -np.deg2rad(1.0)})
    np.testing.assert_allclose(res["q"], same.q, atol=1e-12)  # −1 with --deg is −1° in radians


def test_singular_on_an_arm_with_fewer_than_six_joints(capsys):
    """Regression: a 5-joint arm used to end in an IndexError traceback."""
    code, out, _ = run(capsys, "singular", "so101", "0.1", "0.2", "0.3", "0.4", "0.5", "--json")
    res = json.loads(out)
    assert code == 0 and res["rank"] == 5 and res["full_rank"] == 5 and len(res["lost_directions"]) == 1


@pytest.mark.parametrize("argv, needle", [
    (["validate", "--out", "/proc/kinelab-report"], "not a writable folder"),
    (["validate", "--n", "0"], "n ≥ 1"),
    (["validate", "--n", "-1"], "n ≥ 1"),
    (["animate", "era-elbow", "--dt", "0"], "--dt 0.0 is not valid"),
    (["animate", "era-elbow", "--dt", "nan"], "--dt nan is not valid"),
    (["animate", "era-elbow", "--dt", "1e-300"], "is not valid"),
    (["singular", "ur5", "--sweep", "100000000"], "needs about"),
    (["singular", "ur5", "--sweep", "0"], "at least one sample"),
    (["ik", "ur5", "--target-xyz", "0.3", "0.2", "0.4", "--seed", "-1"], "seed"),
    (["bench", "--out", "/proc/kinelab-bench", "--n", "1"], "not a writable folder"),
    (["fk", "rd:finger_edu_descripton", "0", "0", "0"], "close names: rd:finger_edu_description"),
    # #39 item 10: an empty value read as "not given" (exit 0 with the default; view --html '' served for ever)
    (["fk", "ur5", "0", "0", "0", "0", "0", "0", "--tool", ""], "argument --tool: an empty value"),
    (["fk", "ur5", "0", "0", "0", "0", "0", "0", "--base", " "], "argument --base: an empty value"),
    (["fk", "ur5", "0", "0", "0", "0", "0", "0", "--package-dir", ""], "argument --package-dir: an empty value"),
    (["validate", "--out", ""], "argument --out: an empty value"),
    (["view", "ur5", "--html", ""], "argument --html: an empty value"),
    (["fk", "", "0"], "argument robot: an empty value"),
    (["map", "base", "youbot", "--grasp", "0.5", "0", "0.2", "0", "0", "0", "--top", "-1"], "count=-1 is not valid"),
])
def test_bad_values_end_in_one_line_and_exit_2_before_any_work(argv, needle):
    proc = subprocess.run([sys.executable, "-m", "kinelab.cli", *argv], capture_output=True, text=True,
                          env={**os.environ, "PYTHONWARNINGS": "ignore"}, timeout=300)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and needle in lines[0], proc.stderr
    assert proc.stdout == ""


@pytest.mark.parametrize("caller", [signal.SIG_DFL, signal.SIG_IGN], ids=["foreground", "background-job"])
def test_ctrl_c_stops_a_long_command_with_one_line_and_130(caller):
    """Whatever the suite's own SIGINT disposition (a background job or nohup ignores it), kinelab stops."""
    previous = signal.signal(signal.SIGINT, caller)
    try:
        proc = interruptible([sys.executable, "-m", "kinelab.cli", "singular", "ur5", "--sweep", "1000000", "--json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env={**os.environ, "PYTHONWARNINGS": "ignore"})
    finally:
        signal.signal(signal.SIGINT, previous)
    time.sleep(4.0)  # well inside the sweep's Jacobians
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130 and err.strip().splitlines() == ["kinelab: interrupted"] and out == ""


def test_a_failed_report_leaves_the_previous_one_whole(tmp_path, monkeypatch):
    from kinelab.report import render, validate

    out = tmp_path / "report"
    out.mkdir()
    (out / "report.json").write_text("previous")

    def half_written(report, folder):
        (folder / "report.json").write_text("partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(render, "_write_validate_files", half_written)
    with pytest.raises(KeyboardInterrupt):
        render.write_validate_report(validate.Report(robots=[], n=1, seed=0), out)
    assert (out / "report.json").read_text() == "previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # no temporary folder left behind


def test_a_first_ik_in_a_fresh_process_compiles_nothing_and_says_nothing_on_stderr():
    """First use = later use (#32): the kernels were compiled at install, so the first ``kinelab ik`` of a process
    loads no JIT compiler, prints no notice and gives the second call's answer."""
    script = ("import sys\n"
              "from kinelab.cli.main import main\n"
              "argv = ['ik', 'ur5', '--target-xyz', '0.4', '0.2', '0.5', '--seed', '3', '--json']\n"
              "assert main(argv) == 0\n"
              "print('--second--', flush=True)\n"
              "assert main(argv) == 0\n"
              "assert not any(m.split('.')[0] in ('numba', 'llvmlite') for m in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    first, second = done.stdout.split("--second--\n")
    assert json.loads(first)["q"] == json.loads(second)["q"]


PANDA_SRDF = str(kinelab.robot.catalog.erd_share_dir() / "example-robot-data" / "robots" / "panda_description"
                 / "srdf" / "panda.srdf")


def test_a_named_srdf_configuration_stands_for_q_and_a_base_reroots_the_chain(capsys):
    code, out, _ = run(capsys, "fk", "panda", "default", "--srdf", PANDA_SRDF, "--json")
    assert code == 0
    q = kinelab.load("panda", srdf=PANDA_SRDF).named_q("default")
    assert np.allclose(json.loads(out)["position_m"], kinelab.load("panda").fk(q).translation)
    code, out, _ = run(capsys, "ik", "panda", "--target-q", "default", "--srdf", PANDA_SRDF, "--group", "arm",
                       "--json")
    assert code == 0 and json.loads(out)["success"]
    code, out, _ = run(capsys, "fk", "panda", "-1", "0", "1", "0", "--base", "panda_link3", "--json")
    full = kinelab.load("panda")
    q_full = [0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0]
    expected = full.frame_placement(q_full, "panda_link3").inverse() * full.fk(q_full)
    assert code == 0 and np.allclose(json.loads(out)["position_m"], expected.translation)


@pytest.mark.parametrize(("argv", "said"), [
    (["fk", "panda", "home", "--srdf", PANDA_SRDF], "no configuration 'home'; configurations: default"),
    (["fk", "panda", "0", "x", "0", "0", "0", "0", "0"], "'x' is not a number"),
    (["fk", "panda", "default"], "without an SRDF"),
    (["info", "panda", "--group", "arm"], "needs srdf="),
    (["info", "panda", "--package-dir", "/nonexistent/dir"], "does not exist"),
    (["info", "panda", "--xacro-arg", "noequals"], "--xacro-arg takes NAME=VALUE"),
])
def test_bad_robot_sources_at_the_cli_give_one_line_and_exit_2(capsys, argv, said):
    code, out, err = run(capsys, *argv)
    assert code == 2 and said in err and len(err.strip().splitlines()) == 1


def test_version_hint_and_an_fk_outside_the_limits(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.strip() == f"kinelab {kinelab.__version__}"
    with pytest.raises(SystemExit) as done:
        cli.main(["ik", "ur5", "--task", "reach"])
    assert done.value.code == 2 and capsys.readouterr().err.rstrip().endswith("(see 'kinelab ik --help')")
    code, out, _ = run(capsys, "fk", "panda", *["0"] * 7, "--json")  # joint4's limits exclude 0: said, not refused
    result = json.loads(out)
    assert code == 0 and result["outside_limits"] == [
        "panda_joint4 = 0 rad is outside its limits [-3.072, -0.0698] rad"]
    assert np.allclose(result["position_m"], kinelab.load("panda").fk(np.zeros(7)).translation)
    assert (_plural(1, "restart"), _plural(0, "restart")) == ("1 restart", "0 restarts")


def test_printed_vectors_carry_no_negative_zero(capsys):
    code, out, _ = run(capsys, "singular", "ur5", "0", "0", "0", "0", "0", "0")
    assert code == 0 and "moves nothing" in out and "-0.0," not in out and "-0.0]" not in out


def test_freeze_and_interval_hold_from_the_start_and_the_text_says_so(capsys):
    code, out, _ = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--freeze", "joint1=0", "--seed", "0")
    q = np.array(json.loads(run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--freeze", "joint1=0",
                                "--seed", "0", "--json")[1])["q"])
    assert q[0] == 0.0  # held, not merely switched on by the monitor
    assert "bypasses: freeze from the start" in out
    code, out, _ = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--interval", "joint4=-90:0", "--deg",
                       "--seed", "0", "--json")
    res = json.loads(out)
    assert -np.pi / 2 - 1e-9 <= res["q"][3] <= 1e-9  # within the interval whatever the status
    assert any(b["bypass"] == "intervals" and b.get("sweep", 0) == 0 for b in res["info"]["answer_bypasses"])


def test_on_singular_keeps_the_papers_monitor_switched_policy_and_says_what_the_answer_used(capsys):
    code, out, _ = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--freeze", "joint1=0",
                       "--on-singular", "freeze", "--seed", "0", "--start-q", "random")
    assert code == 0 and "the answer's attempt: monitor" in out and "over all" in out
    code, _, err = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--on-singular", "freeze")
    assert code == 2 and "--on-singular" in err


def test_an_answer_outside_the_limits_is_never_presented_without_saying_so(capsys):
    code, out, _ = run(capsys, "ik", "so101", "--solver", "biquat", "--target-xyz", "0.2", "0", "0.1",
                       "--tol-rot", "1e-5", "--seed", "0", "--json")
    res = json.loads(out)
    assert not kinelab.load("so101").within_limits(np.array(res["q"]))  # the biquaternion law's answer, seed 0
    assert res["status"] == "outside_limits" and not res["success"] and code == 1
    assert res["position_error_m"] <= 1e-6 and res["rotation_error_rad"] <= 1e-5  # the pose itself is met
    assert "joint 'wrist_flex' at" in res["message"] and "outside its limits" in res["message"]


def test_view_draws_any_finite_q_with_a_note_for_joints_outside_their_limits(capsys, tmp_path):
    code, out, err = run(capsys, "view", "panda", "0", "0", "0", "0", "0", "0", "0", "--html",
                         str(tmp_path / "p.html"))
    assert code == 0 and "panda_joint4 = 0 rad is outside its limits" in err
    assert "panda at q = [0, 0, 0, 0, 0, 0, 0]" in out
    assert 'id="kinelab-caption"' in (tmp_path / "p.html").read_text()
    code, _, err = run(capsys, "view", "panda", "0", "nan", "0", "0", "0", "0", "0", "--html", str(tmp_path / "q.html"))
    assert code == 2 and ("NaN" in err or "finite" in err)


def test_every_option_of_every_command_has_help():
    import argparse

    from kinelab.cli.main import build_parser

    missing = []

    def walk(parser, path):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    walk(sub, [*path, name])
            elif action.dest != "help" and not action.help:
                missing.append((path, action.option_strings or action.dest))

    walk(build_parser(), [])
    assert missing == []


def test_a_sweep_prints_the_samples_it_ran_and_representatives_that_paste_back(capsys):
    code, out, _ = run(capsys, "singular", "ur5", "--sweep", "2000", "--grid")
    assert code == 0 and "729 samples (a grid of 2000 asked for)" in out
    line = next(x for x in out.splitlines() if "e.g. q = " in x)
    q = line.split("e.g. q = ")[1].split()
    code, out, _ = run(capsys, "singular", "ur5", *q)
    assert code == 0 and "(SINGULAR)" in out  # full precision: still singular when pasted back


def test_close_names_are_suggested_and_printed_numbers_have_no_minus_zero(capsys):
    for name, meant in (("pandaa", "panda"), ("UR5", "ur5"), ("franka", "panda")):
        code, _, err = run(capsys, "info", name)
        assert code == 2 and f"(did you mean {meant!r}?)" in err
    code, _, err = run(capsys, "ik", "ur5", "--target-xyz", "0.4", "0.2", "0.5", "--solver", "frdn")
    assert code == 2 and "(did you mean 'frdm'?)" in err
    code, _, err = run(capsys, "fk", "ur5", "0", "0", "0", "0", "0", "0", "--tool", "tool1")
    assert code == 2 and "(did you mean 'tool0'?)" in err
    code, out, _ = run(capsys, "fk", "stanford", "0", "0", "0", "0", "0", "0")
    assert code == 0 and "-0." not in out and "e-1" not in out  # no −0, no 1e-17 rounding noise
    code, out, _ = run(capsys, "ik", "era", "--target-xyz", "4", "2", "6", "--deg")
    assert code == 0 and len([line for line in out.splitlines() if line.startswith("  q")]) == 1
    assert out.splitlines()[1].count("]") == 2 and out.splitlines()[2].startswith("  position error")  # one line


def test_lock_holds_a_joint_from_the_command_line(capsys):
    code, out, _ = run(capsys, "info", "panda", "--lock", "panda_joint7=0.5", "--json")
    info = json.loads(out)
    assert code == 0 and info["dof"] == 6 and info["locked"]["panda_joint7"] == 0.5
    code, _, err = run(capsys, "info", "panda", "--lock", "panda_joint7=x")
    assert code == 2 and "--lock panda_joint7=x" in err
    code, _, err = run(capsys, "info", "panda", "--lock", "panda_joint77=0.1")
    assert code == 2 and "panda_joint77" in err


@pytest.mark.parametrize("solver", ["analytic", "dls", "biquat"])
def test_no_solver_prints_another_solver_s_diagnostics(capsys, solver):
    """#34.4: analytic answers printed FRDM's "monitor did not fire"."""
    code, out, _ = run(capsys, "ik", "ur5", "--target-xyz", "0.3", "0.2", "0.4", "--solver", solver)
    assert code == 0 and "monitor" not in out and "bypass" not in out


def test_the_closed_form_is_named_where_solvers_are_listed(capsys):
    """#34.5: solver='auto' was refused with a list that omitted analytic, and --help did not name it. Since #58 auto
    is a route for one answer too (the fastest with the same guarantees: the closed form on a UR5), and an unknown
    solver's list names analytic and auto."""
    ur5 = kinelab.load("ur5")
    res = kinelab.solve(ur5, kinelab.target_from_xyz_rpy([0.3, 0.1, 0.4]), solver="auto", seed=0)
    assert res.solver == "analytic"
    with pytest.raises(kinelab.SolverNotFoundError, match=r"solvers are: analytic, auto, biquat, dls, frdm"):
        kinelab.solve(ur5, kinelab.target_from_xyz_rpy([0.3, 0.1, 0.4]), solver="newton")
    with pytest.raises(SystemExit):
        cli.main(["ik", "--help"])
    out = capsys.readouterr().out
    assert "analytic" in out and "auto" in out


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova"])
def test_kinelab_ik_and_branches_print_the_api_s_answers(capsys, name):
    """#40: the CLI takes the one route: ``kinelab ik --seed`` prints what ``kinelab.solve`` returns for the same
    seed (q, status, counters and diagnostics, exactly: JSON keeps a float's every digit), and ``kinelab branches``
    prints ``kinelab.solve_all``'s branches."""
    robot = kinelab.load(name)
    rng = np.random.default_rng(23)
    for seed in range(3):
        q_target = robot.random_q(rng)
        words = [repr(v) for v in q_target.tolist()]
        code, out, _ = run(capsys, "ik", name, "--target-q", *words, "--seed", str(seed), "--json",
                           "--start-q", "random", "--solver", "frdm")
        printed = json.loads(out)
        res = kinelab.solve(robot, robot.fk(q_target), seed=seed, solver="frdm")
        assert code == (0 if res.success else 1)
        assert printed["q"] == res.q.tolist() and printed["status"] == res.status.value
        assert (printed["iterations"], printed["restarts"]) == (res.iterations, res.restarts)
        assert printed["info"]["sweeps"] == res.diagnostics.sweeps and printed["info"]["path"] == res.diagnostics.path
        code, out, _ = run(capsys, "branches", name, "--target-q", *words, "--seed", str(seed), "--json")
        found = kinelab.solve_all(robot, robot.fk(q_target), seed=seed)
        if found.method == "multistart":  # panda: rounds until the stopping rule; the sets agree, not the rows
            assert len(json.loads(out)["branches"]) > 0
            continue
        assert [b["q"] for b in json.loads(out)["branches"]] == found.q.tolist()


def test_ik_starts_from_the_middle_of_the_limits_and_answers_the_turn_nearest_it(capsys):
    """#43 item 7: a random default start gave the UR5 a shoulder lift of 4.91 rad (−1.37 rad is the same pose,
    inside the limits); the default start is now the reference configuration, every revolute answer the turn
    nearest it within the limits, and the output says which start was used."""
    ur5 = kinelab.load("ur5")
    words = ["0", "-1.57", "1.57", "0", "0", "0"]
    target = ur5.fk(np.array(words, dtype=float))
    start, how = ur5.reference_q()  # #60 item 1: the UR5's middle (all zeros) is singular, its display pose serves
    assert how.startswith("a well-conditioned configuration") and np.array_equal(start, ur5.display_q())
    for seed in range(5):
        code, out, _ = run(capsys, "ik", "ur5", "--target-q", *words, "--seed", str(seed), "--json")
        res = json.loads(out)
        q = np.array(res["q"])
        assert code == 0 and res["success"] and res["start"]["q"] == start.tolist()
        assert res["start"]["from"].startswith("a well-conditioned configuration")
        assert np.all(np.abs(q - start) <= np.pi + 1e-12) and ur5.within_limits(q, slack=0.0)
        assert max(ur5.tool_error(q, target)) <= 1e-6
        assert res["position_error_m"] == pytest.approx(ur5.tool_error(q, target)[0], abs=1e-12)
    code, out, _ = run(capsys, "ik", "ur5", "--target-q", *words)
    assert code == 0 and "start: a well-conditioned configuration" in out
    code, out, _ = run(capsys, "ik", "ur5", "--target-q", *words, "--start-q", "random", "--seed", "1")
    assert code == 0 and "start: drawn at random from the seed" in out


def test_a_robot_with_an_srdf_home_starts_from_it(tmp_path):
    ur5 = kinelab.load("ur5")
    home = [0.4, -1.0, 1.2, -0.3, 0.5, 0.1]
    joints = "".join(f'<joint name="{n}" value="{v}"/>' for n, v in zip(ur5.joint_names, home, strict=True))
    srdf = tmp_path / "ur5.srdf"
    srdf.write_text(f'<robot name="ur5"><group name="arm"><chain base_link="{ur5.base}" tip_link="{ur5.tool}"/>'
                    f'</group><group_state name="home" group="arm">{joints}</group_state></robot>')
    robot = kinelab.load(str(ur5.urdf_path), tool=ur5.tool, srdf=str(srdf))
    q, how = robot.reference_q()
    assert q.tolist() == home and how == "the SRDF's 'home' configuration"
    q, how = ur5.reference_q()  # without the SRDF: not its singular middle (#60 item 1)
    assert np.array_equal(q, ur5.display_q()) and how.startswith("a well-conditioned configuration")
    panda = kinelab.load("panda")
    q, how = panda.reference_q()  # a middle that is well conditioned stays the start
    assert np.allclose(q, 0.5 * (panda.lower + panda.upper)) and how == "the middle of the joint limits"


def _told_before(capsys, monkeypatch, argv, slow):
    """Run a command where someone watches (a terminal) and return, for each slow step in ``slow`` ((owner,
    attribute) pairs, wrapped), what the command had said on stderr just before that step began."""
    from kinelab import progress

    monkeypatch.setattr(progress, "interactive", lambda: True)
    said = []

    def announced(real, name):
        def wrapped(*args, **kwargs):
            said.append((name, capsys.readouterr().err))
            return real(*args, **kwargs)
        return wrapped

    for owner, name in slow:
        monkeypatch.setattr(owner, name, announced(getattr(owner, name), name))
    code = cli.main(argv)
    return code, said


def test_a_page_command_says_what_it_is_doing_before_each_slow_step(capsys, monkeypatch, tmp_path):
    """#43 item 6: `view --html`, `animate --html`, `branches --html` and `map view` were silent for seconds while
    meshes loaded, passages ran and pages were written. In a terminal each slow step is announced on stderr before
    it starts; to a pipe nothing is added (stderr stays empty)."""
    from kinelab.studies import paper000_era
    from kinelab.view import maps as map_view
    from kinelab.view import scene

    page = str(tmp_path / "p.html")
    cases = [(["view", "ur5", "--html", page], [(scene.Scene, "__init__"), (scene.Scene, "save_html")]),
             (["animate", "era-elbow", "--html", page], [(paper000_era, "run"), (scene.Scene, "__init__"),
                                                          (scene.Scene, "save_html")]),
             (["branches", "ur5", "--target-q", "0", "-1.57", "1.57", "0", "0.5", "0", "--html", page],
              [(scene, "side_by_side")])]
    for argv, slow in cases:
        code, said = _told_before(capsys, monkeypatch, argv, slow)
        assert code == 0 and [name for name, _ in said] == [name for _, name in slow], argv
        for name, err in said:
            assert err.strip().splitlines()[-1].startswith("kinelab: ") and err.rstrip().endswith("..."), (argv, name)
        monkeypatch.undo()
    stored = tmp_path / "map.zarr"
    kinelab.maps.reachability(kinelab.load("ur5"), kinelab.maps.MapSpec(voxel=0.4, orientations=2), out=str(stored))
    code, said = _told_before(capsys, monkeypatch, ["map", "view", str(stored), "--html", page],
                              [(map_view, "map_page")])
    assert code == 0 and said and "kinelab: drawing the map" in said[0][1]
    monkeypatch.undo()
    assert cli.main(["view", "ur5", "--html", page]) == 0 and capsys.readouterr().err == ""  # not a terminal


SWALLOWED = """
import os, signal, sys
import kinelab.cli.view as view
real = view.load_robot

def load_and_lose_a_ctrl_c(*args, **kwargs):
    try:  # what a library that guards its imports with `except BaseException` does to a Ctrl-C
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(10_000_000):
            pass
    except BaseException:
        pass
    return real(*args, **kwargs)

view.load_robot = load_and_lose_a_ctrl_c
from kinelab.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def test_a_ctrl_c_a_library_swallows_still_stops_the_command_and_keeps_the_old_page(tmp_path):
    """#67 item 5: an interrupt during start-up that a library caught let `view --html` finish, replace the old page
    and exit 0. The Ctrl-C is remembered: the old page stays whole, no temporary file is left, the exit is 130."""
    page = tmp_path / "view.html"
    page.write_text("the old page")
    proc = subprocess.run([sys.executable, "-c", SWALLOWED, "view", "ur5", "--html", str(page)], capture_output=True,
                          text=True, timeout=300, env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert proc.returncode == 130, proc.stderr[-1000:]
    assert proc.stderr.strip().splitlines()[-1].startswith("kinelab: interrupted")
    assert page.read_text() == "the old page"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["view.html"]


def test_the_cli_puts_the_callers_ctrl_c_handler_back(tmp_path):
    """main() holds interrupts only while it runs: in a program (or a test suite) that calls it, the handler before
    it is back after it, and a later write is not refused."""
    from kinelab.cli import main
    from kinelab.files import interrupted, write_output

    before = signal.getsignal(signal.SIGINT)
    assert main(["fk", "ur5", "0", "0", "0", "0", "0", "0"]) == 0
    assert signal.getsignal(signal.SIGINT) is before and not interrupted()
    assert write_output(tmp_path / "a.txt", "x").read_text() == "x"
