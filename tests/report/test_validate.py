import json

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
    assert " 0.25 rad" in step_row  # a 0.25 rad bound printed as such, not rounded to "2e-01"


def test_json_alone_writes_no_report_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code = cli.main(["validate", "--robots", "ur5", "--n", "10", "--json"])
    assert code == 0 and json.loads(capsys.readouterr().out)["passed"]
    assert list(tmp_path.iterdir()) == []  # no ./kinelab-report
