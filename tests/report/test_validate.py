import json
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from kinelab import cli
from kinelab.report import render, validate


def test_validate_passes_on_two_robots_and_writes_the_report(tmp_path, capsys):
    out = tmp_path / "report"
    code = cli.main(["validate", "--robots", "stanford", "ur5", "--n", "20", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    report = json.loads((out / "report.json").read_text())
    assert report["passed"] and {c["robot"] for c in report["checks"]} == {"stanford", "ur5"}
    assert any("seed 001" in c["name"] for c in report["checks"])
    assert any(c["name"].startswith("frdm:") for c in report["checks"])
    assert (out / "seed001_convergence.png").stat().st_size > 1000
    assert "data:image/png" in (out / "report.html").read_text()
    assert (out / "report.md").read_text().count("PASS") == len(report["checks"])
    assert "<table" in (out / "report.html").read_text()


def test_a_failing_check_makes_validate_exit_non_zero(monkeypatch, capsys, tmp_path):
    def with_a_failure(robot, n, seed):
        rows = validate.model_checks(robot, n, seed)
        return rows + [validate.Check(robot.name, "deliberately failing", 1.0, 0.5, "m")]

    monkeypatch.setattr(validate, "GENERAL_CHECKS", [with_a_failure])
    code = cli.main(["validate", "--robots", "ur5", "--n", "10", "--out", str(tmp_path)])
    assert code == 1
    assert "FAIL" in capsys.readouterr().out
    assert (tmp_path / "report.md").read_text().count("FAIL") == 1


def test_validate_refuses_an_unknown_robot_before_working(capsys):
    assert cli.main(["validate", "--robots", "nosuch"]) == 2
    assert "registered robots" in capsys.readouterr().err


def test_era_checks_cover_the_three_passages_and_print_tolerances_exactly():
    checks = validate.era_checks(validate.load("era"), 0, 0)
    names = " ".join(c.name for c in checks)
    for passage in ("elbow", "wrist", "shoulder"):
        assert f"seed 000 {passage}" in names
    assert all(c.passed for c in checks), [c for c in checks if not c.passed]
    table = render.validate_table(validate.Report(robots=["era"], checks=checks))
    step_row = next(line for line in table.splitlines() if "elbow, bypass: largest joint step" in line)
    assert "≤ 0.25" in step_row and " rad " in step_row  # a 0.25 rad bound printed as such, not "2e-01"
    drifts = [c.detail for c in checks if "the paper's drift shows" in c.name]
    degrees = [float(v) for d in drifts for v in re.findall(r"-?\d+\.\d", d)]
    assert len(drifts) == 2 and degrees and all(-180 < v <= 180 for v in degrees)  # #43 item 5: it read −278.6°


def test_json_alone_writes_no_report_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code = cli.main(["validate", "--robots", "ur5", "--n", "10", "--json"])
    assert code == 0 and json.loads(capsys.readouterr().out)["passed"]
    assert list(tmp_path.iterdir()) == []  # no ./kinelab-report


def test_a_whole_robot_takes_the_whole_body_checks(capsys):
    """#59: validate's whole-body section on TALOS: the compiled tree, every task's Jacobian, the limits over 2000
    steps and the converged solve, each against Pinocchio; all pass, each a number with its limit."""
    code = cli.main(["validate", "--robots", "talos", "--n", "5", "--json"])
    report = json.loads(capsys.readouterr().out)
    names = [c["name"] for c in report["checks"]]
    assert code == 0 and report["passed"] and all(n.startswith("whole body: ") for n in names)
    assert {"whole body: limit violations over the steps", "whole body: false successes (frdm)",
            "whole body: task Jacobians vs differences of Pinocchio's FK",
            "whole body: collision rows: rate against coal's central difference"} <= set(names)
    assert validate.DEFAULT_ROBOTS[-5:-3] == ("talos", "baxter")


def test_a_robot_with_loops_takes_the_loop_checks(capsys):
    """#69: validate's closed-chain section on the four-bar: every closure against Pinocchio's constraint models,
    the assemblies against the closed form, the loops after every step, the solve's targets; all pass."""
    code = cli.main(["validate", "--robots", "fourbar", "--n", "20", "--json"])
    report = json.loads(capsys.readouterr().out)
    names = [c["name"] for c in report["checks"]]
    assert code == 0 and report["passed"] and all(n.startswith("loops: ") for n in names)
    assert {"loops: closure errors vs Pinocchio's constraint models", "loops: assemblies against the closed form",
            "loops: closure error after every step", "loops: false successes (step)"} <= set(names)
    assert validate.DEFAULT_ROBOTS[-3:] == ("fourbar", "delta", "cassie")


def _report_with_one_failure():
    ok = validate.Check("era", "FK position: yourdfpy vs Pinocchio", 2e-16, 1e-9, "m", "200 random q")
    bad = validate.Check("era", "seed 000 wrist, q5, q6 < 80°: worst tool error", 2e-6, 1e-6, "m")
    shows = validate.Check("era", "seed 000 wrist, without bypass: the paper's drift shows", 1.0, 1.0, "yes/no",
                           at_least=True)
    return validate.Report(robots=["era"], checks=[ok, bad, shows], n=10)


def test_the_terminal_table_wraps_long_names_within_their_column_and_reads_positively():
    report = _report_with_one_failure()
    lines = render.validate_table(report, width=80).splitlines()
    assert all(len(line) <= 80 for line in lines)
    assert lines[-1] == "2 passed, 1 failed"
    drift = next(line for line in lines if "without bypass" in line)
    assert " yes " in drift and drift.endswith("PASS")  # yes/no shown, not a 0/1 "(0 = shown)"
    assert any(line.strip() == "worst tool error" for line in lines)  # the long name wrapped in its column


def test_the_html_report_puts_the_verdict_first_and_a_section_per_paper_with_captioned_figures(tmp_path):
    from kinelab.report.page import validate_html

    figure = tmp_path / "era_wrist.png"
    fig = render.Figure(figsize=(2, 1))
    fig.subplots().plot([0, 1], [0, 1])
    fig.savefig(figure)
    page = validate_html(_report_with_one_failure(), {"era_wrist.png": figure.read_bytes()})
    assert page.index("class='verdict fail'") < page.index("<h2>")  # verdict and summary first
    assert "Failed: era: seed 000 wrist, q5, q6 &lt; 80°: worst tool error" in page
    assert "<tr class='failed'>" in page and page.count("<tr class='failed'>") == 1
    section = page[page.index("Seed paper 000"):]
    assert "<figcaption>Figure: Seed 000, ERA wrist passage" in section and "data:image/png;base64," in section
    # #60 item 7: what the run ran on right under the verdict, before the first check (it was 6,700 px down)
    assert page.index("class='verdict fail'") < page.index("Machine and versions") < page.index("<table><tr><th>robot")
    assert "<script" not in page and "http" not in page  # self-contained


@pytest.mark.browser
def test_a_browser_shows_the_verdict_banner_at_the_top_of_the_report(tmp_path):
    """Headless Chromium renders the page: the red FAIL banner sits in the first rows, the failed row is
    tinted, the page's width is the browser's (no horizontal overflow of the tables)."""
    import os

    import browser
    import numpy as np
    from PIL import Image

    from kinelab.report.page import validate_html

    if browser.find_chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("CI must have chromium: .ci/run installs Debian's chromium")
        pytest.skip("Debian's chromium is not installed here")
    (tmp_path / "report.html").write_text(validate_html(_report_with_one_failure(), {}))
    png = browser.screenshot(tmp_path / "report.html", tmp_path / "report.png", size=(900, 1400))
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=int)
    red = (np.abs(rgb - (0xB3, 0x26, 0x1E)).max(axis=2) < 12)
    tint = (np.abs(rgb - (0xFD, 0xEC, 0xEA)).max(axis=2) < 6)
    assert red[:160].sum() > 5000  # the banner, first thing on the page
    assert tint.sum() > 2000  # the failed check's row (under the machine and versions)


def test_the_closed_form_checks_hold_on_ur5_and_fail_when_a_branch_is_missing(monkeypatch):
    """Every solver's answer from a random start is one of the closed form's branches; hide one branch of each
    pose and the check must fail for the answers that landed on it."""
    import kinelab
    import kinelab.ik as ik

    ur5 = kinelab.load("ur5")
    rows = validate.analytic_checks(ur5, 40, 0)
    assert [r.name for r in rows] == ["closed form: every branch met (Pinocchio-checked)",
                                      *(f"{s}: answers off the closed form's branches"
                                        for s in ("frdm", "biquat", "dls")),
                                      "completeness: the pose's own configuration among the branches, to 1e-06 rad"]
    assert all(r.passed for r in rows) and "on the branch nearest its start" in rows[1].detail
    assert "2000 poses, 0 missed" in rows[-1].detail
    # TIAGo Pro: no class, not even with an end joint held; the general elimination sweeps its joint 1
    swept = validate.analytic_checks(kinelab.load("tiago_pro"), 40, 0)
    assert swept[0].name == "elimination, joint 1 swept: every branch met (Pinocchio-checked)"
    assert swept[0].passed and swept[-1].passed and "0 missed" in swept[-1].detail  # (DLS's answers at a limit whose
    # root lies 1e-6 rad beyond it are not branches within the limits: 1 of 9 here, below the 95 % of 10 targets)
    real = ik.solve_all
    monkeypatch.setattr(ik, "solve_all", lambda *a, **kw: real(*a, **kw)[1:])
    assert not all(r.passed for r in validate.analytic_checks(ur5, 40, 0)[1:])


def test_the_completeness_check_fails_when_the_batch_loses_a_branch(monkeypatch):
    import dataclasses

    import kinelab
    from kinelab.report.bench import completeness

    xarm6 = kinelab.load("xarm6")
    assert validate.completeness_checks(xarm6, 0)[0].passed
    real = completeness.all_branches_batch

    def first_lost(robot, targets):
        batch = real(robot, targets)
        q = batch.q.copy()
        q[:, 0] = np.nan  # every pose's first branch gone
        return dataclasses.replace(batch, q=q)

    monkeypatch.setattr(completeness, "all_branches_batch", first_lost)
    row = validate.completeness_checks(xarm6, 0)[0]
    assert not row.passed and row.value < 0.9


def test_the_collision_checks_hold_on_panda_and_fail_when_the_check_sees_nothing(monkeypatch):
    import kinelab
    from kinelab.collision.model import CollisionModel

    panda = kinelab.load("panda")
    rows = validate.collision_checks(panda, 40, 0)
    assert [r.name for r in rows] == ["collisions: configurations where the check and Pinocchio's distances disagree",
                                      "collisions: successes that collide"]
    assert all(r.passed for r in rows)
    assert validate.collision_checks(kinelab.load("stanford"), 40, 0) == []  # no collision geometry: no check
    monkeypatch.setattr(CollisionModel, "colliding_pair", lambda self, q, first_test=True: None)
    assert not validate.collision_checks(panda, 40, 0)[0].passed


def test_the_swept_closed_form_checks_hold_on_the_era_and_fail_when_its_branches_are_wrong(monkeypatch):
    """The ERA has no closed form as a whole but one with joint 1 held: validate checks its branches and that
    FRDM's and DLS's answers are among them at their own joint-1 angle; branches moved off the answers fail it."""
    import kinelab
    from kinelab.ik.analytic import redundancy

    era = kinelab.load("era")
    rows = validate.analytic_checks(era, 40, 0)
    assert [r.name.split(":")[0] for r in rows] == ["closed form, joint 1 swept", "frdm", "dls", "completeness"]
    assert all(r.passed for r in rows)
    real = redundancy.at_value
    monkeypatch.setattr(redundancy, "at_value", lambda *a, **k: [(q + 0.01, *rest) for q, *rest in real(*a, **k)])
    rows = validate.analytic_checks(era, 40, 0)
    assert not any(r.passed for r in rows[:3])  # the moved branches miss the pose, and every answer misses them


def test_a_unit_wider_than_its_column_keeps_a_space_before_the_verdict():
    """#43 item 5: the console table printed "m or radPASS"."""
    check = validate.Check("ur5", "judge: compiled FK vs Pinocchio (certificate)", 1e-16, 1e-12, "m or rad")
    row = render.validate_table(validate.Report(robots=["ur5"], checks=[check])).splitlines()[1]
    assert "m or rad PASS" in row and row.endswith("PASS")


def test_the_report_says_when_with_what_code_libraries_processor_and_command_it_ran(tmp_path, monkeypatch):
    """#43 item 5: the report names its date, kinelab's version and commit, the libraries, the compiled core,
    the processor and the command; the commit is the checkout's HEAD (as git itself says) or None outside one."""
    import re
    import shutil
    import subprocess
    import sys
    from datetime import datetime

    import numpy as np
    import pinocchio as pin

    import kinelab
    from kinelab.report.provenance import commit_of

    monkeypatch.setattr(sys, "argv", ["kinelab", "validate", "--robots", "ur5"])
    report = validate.Report(robots=["ur5"], checks=[], n=10)
    p = report.to_dict()["provenance"]
    assert abs((datetime.fromisoformat(p["date"]) - datetime.now(datetime.fromisoformat(p["date"]).tzinfo))
               .total_seconds()) < 60
    assert p["command"] == "kinelab validate --robots ur5" and p["kinelab"] == kinelab.__version__
    assert (p["pinocchio"], p["numpy"]) == (pin.__version__, np.__version__)
    assert re.fullmatch(r"[0-9a-f]{12}", p["core"]) and p["processor"]
    here = Path(kinelab.__file__).resolve().parent
    git = shutil.which("git")
    if git is not None and commit_of(here) is not None:
        head = subprocess.run([git, "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, check=True)
        assert p["commit"] == head.stdout.strip()
    assert commit_of(tmp_path) is None
    line = render.provenance_line(p)
    assert p["date"] in line and "kinelab validate --robots ur5" in line and p["processor"] in line


def test_shares_carry_their_wilson_interval_and_pass_on_its_bound_in_every_form_of_the_report(tmp_path):
    """#43 item 5: success rates had no interval and the headline one sample size for every check. The Wilson
    interval of 50 successes in 100 is 40.4–59.6 % and of 50 in 50 is 92.9–100 % (n / (n + z²) for no failure).
    #60 item 7: a share is a fraction (unit "share", not "%" over a fraction) and passes on its 95 % lower bound:
    50 of 50 does not show 95 %, 100 of 100 (96.3 % at least) does."""
    assert validate.wilson(0.5, 100) == pytest.approx((0.40383, 0.59617), abs=1e-5)
    assert validate.wilson(1.0, 50) == pytest.approx((50 / (50 + 1.959963984540054**2), 1.0), abs=1e-12)
    short = validate.Check("ur5", "frdm: targets solved (Pinocchio-checked)", 1.0, 0.95, "share", "50 targets",
                           at_least=True, samples=50)
    enough = validate.Check("ur5", "biquat: targets solved (Pinocchio-checked)", 1.0, 0.95, "share", "100 targets",
                            at_least=True, samples=100)
    error = validate.Check("ur5", "FK position: yourdfpy vs Pinocchio", 2e-16, 1e-9, "m", "200 random q")
    assert not short.passed and enough.passed and error.passed
    report = validate.Report(robots=["ur5"], checks=[short, enough, error], n=200)
    checks = report.to_dict()["checks"]
    assert checks[0]["interval_95"] == pytest.approx(validate.wilson(1.0, 50)) and checks[0]["unit"] == "share"
    assert checks[0]["value"] == 1.0 and checks[2]["interval_95"] is None
    render._write_validate_files(report, tmp_path)
    md = (tmp_path / "report.md").read_text()
    assert "| 100.0 % (95 %: 92.9–100.0 %, n = 50) | ≥ 95 % | FAIL |" in md
    assert "| 100.0 % (95 %: 96.3–100.0 %, n = 100) | ≥ 95 % | PASS |" in md
    assert "each other check stating its own sample" in md and "pass on its bound" in md
    page = (tmp_path / "report.html").read_text()
    assert "(95 %: 92.9–100.0 %, n = 50)" in page and "configurations per check" not in page


def test_samples_for_a_bar_are_the_least_whose_bound_clears_it():
    from kinelab.report.check import samples_for

    for bar, misses in ((0.9, 0), (0.95, 2), (0.98, 1), (0.995, 0)):
        n = samples_for(bar, misses)
        assert validate.wilson((n - misses) / n, n)[0] >= bar > validate.wilson((n - 1 - misses) / (n - 1), n - 1)[0]
    assert samples_for(0.95) == 73  # n / (n + z²) ≥ 0.95 first at n = 73: z² · 19 = 72.99


def test_provenance_names_the_machine_and_what_defines_the_robots_and_the_reference():
    """#60 item 7: the processor's model and cores, and the versions of example-robot-data, yourdfpy, SciPy and
    coal, in the JSON (first), the Markdown and the page (at the top)."""
    from importlib import metadata

    from kinelab.report.provenance import provenance

    p = provenance()
    assert p["cores"] == os.cpu_count()
    for key, dist in (("example-robot-data", "example-robot-data"), ("yourdfpy", "yourdfpy"), ("scipy", "scipy"),
                      ("coal", "coal"), ("pinocchio", "pin")):
        assert p[key] == metadata.version(dist)
    report = validate.Report(robots=["ur5"], checks=[], n=10)
    assert next(iter(report.to_dict())) == "provenance"
    line = render.provenance_line(report.provenance)
    assert f"example-robot-data {p['example-robot-data']}" in line and f"{p['cores']} cores" in line


def test_every_joint_of_the_era_passage_figures_can_be_seen(tmp_path):
    """#43 item 5: along the elbow passage θ3 = θ5, and θ3's curve was drawn exactly under θ5's: not one of its
    pixels showed in the right panel. Each panel of the picture must show every joint's colour along the path."""
    from PIL import Image

    from kinelab import load
    from kinelab.studies import paper000_era as ep

    era = load("era")
    png = tmp_path / render._passage_figure(ep.run(ep.elbow_passage(era), era), "elbow", (2, 3, 4), tmp_path)
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    hues = {"θ3 (blue)": (b > r + 30) & (b > g + 10), "θ4 (orange)": (r > g + 40) & (g > b + 40),
            "θ5 (green)": (g > r + 40) & (g > b + 40)}
    half = rgb.shape[1] // 2
    for panel, columns in (("without bypass", slice(0, half)), ("with bypass", slice(half, None))):
        for joint, mask in hues.items():
            assert mask[:, columns].sum() >= 400, (panel, joint, int(mask[:, columns].sum()))  # a legend swatch: < 100


def test_a_log_gets_a_line_per_check_group_as_it_ends(capsys, tmp_path):
    """#72 item 1: with its output in a file or a pipe (as under pytest), validate says each group as it ends, on
    stderr (the table stays on stdout)."""
    assert cli.main(["validate", "--robots", "fourbar", "--n", "5", "--out", str(tmp_path / "r")]) == 0
    err = capsys.readouterr().err.splitlines()
    groups = [line for line in err if line.startswith("validate ") and "still running" not in line]
    assert len(groups) == 4 and groups[0].startswith("validate 1/4: fourbar, closure model check:")
    assert all(" failed (" in line for line in groups)


def test_a_slow_group_is_heard_from_while_it_runs(monkeypatch):
    """#72 item 1: a check group running longer than the heartbeat says so on stderr while it runs (the first
    command's log had 43 s of silence in TALOS's solve checks); no beating thread when nothing is asked (a
    terminal's bar). The group here runs until it has heard two beats, however long that takes; nothing is timed."""
    import io
    import threading

    from kinelab.report import validate as v

    class Listening(io.StringIO):
        """stderr that lets the group end once two heartbeats are written."""

        heard = threading.Event()

        def write(self, text):
            written = super().write(text)
            if self.getvalue().count("still running") >= 2:
                self.heard.set()
            return written

    monkeypatch.setattr(v, "HEARTBEAT", 0.01)
    err = Listening()
    monkeypatch.setattr(sys, "stderr", err)
    with v.heartbeat("validate 3/9: talos, solve checks"):
        err.heard.wait(600)  # a bound against a hang only
    assert err.getvalue().count("validate 3/9: talos, solve checks: still running (") >= 2
    quiet = Listening()
    monkeypatch.setattr(sys, "stderr", quiet)
    before = threading.active_count()
    with v.heartbeat(None):
        beating = threading.active_count()  # no thread started to beat
    assert beating == before and quiet.getvalue() == ""


def test_the_help_names_every_default_robot():
    """``kinelab validate --help`` lists the robots the default run checks (it had left out the loops')."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
        cli.main(["validate", "--help"])
    text = " ".join(out.getvalue().split())
    assert all(name in text for name in validate.DEFAULT_ROBOTS)
