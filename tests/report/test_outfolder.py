"""--out never deletes a user's files: only an empty folder or a kinelab report of the same kind is replaced."""

import pytest

from kinelab import cli
from kinelab.errors import KinelabError
from kinelab.report.outfolder import MARKER, atomic_folder, check_output_folder


def _users_folder(tmp_path):
    folder = tmp_path / "thesis"
    (folder / "sub").mkdir(parents=True)
    (folder / "important.txt").write_text("keep me")
    (folder / "sub" / "thesis.tex").write_text("\\documentclass{article}")
    return folder


@pytest.mark.parametrize("argv", [["validate", "--robots", "ur5", "--n", "5"],
                                  ["bench", "--robots", "ur5", "--n", "2"]])
def test_a_folder_of_the_user_s_is_refused_and_left_alone(tmp_path, capsys, argv):
    folder = _users_folder(tmp_path)
    assert cli.main([*argv, "--out", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a kinelab" in err and "important.txt" in err
    assert (folder / "important.txt").read_text() == "keep me" and (folder / "sub" / "thesis.tex").is_file()


@pytest.mark.parametrize("out", [".", "..", "./", "../.."])
def test_the_working_folder_and_those_above_it_are_refused(tmp_path, monkeypatch, capsys, out):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "notes.txt").write_text("x")
    assert cli.main(["validate", "--robots", "ur5", "--n", "5", "--out", out]) == 2
    err = capsys.readouterr().err
    assert "not the working folder" in err and "Traceback" not in err
    assert (work / "notes.txt").is_file()


def test_a_report_of_the_same_kind_is_replaced_whole_and_one_of_another_kind_is_not(tmp_path):
    out = tmp_path / "r"
    with atomic_folder(out, "bench") as folder:
        (folder / "bench.json").write_text("{}")
    assert (out / MARKER).read_text().strip() == "bench"
    with atomic_folder(out, "bench") as folder:
        (folder / "bench.md").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "bench.md"]  # the old run's files are gone
    with pytest.raises(KinelabError, match="not a kinelab validate report"):
        check_output_folder(out, "validate")


def test_an_unmarked_folder_with_only_the_report_s_files_is_taken_as_an_earlier_report(tmp_path):
    out = tmp_path / "old"
    out.mkdir()
    for name in ("report.json", "report.md", "report.html", "era_elbow.png"):
        (out / name).write_text("")
    assert check_output_folder(out, "validate") == out
    (out / "mine.csv").write_text("")
    with pytest.raises(KinelabError, match="mine.csv"):
        check_output_folder(out, "validate")


def test_a_folder_of_the_user_s_figures_is_never_taken_for_a_report(tmp_path):
    """#31.5: validate --out DIR deleted a folder that held only the user's .png files."""
    out = tmp_path / "photos"
    out.mkdir()
    for name in ("holiday.png", "era_elbow.png"):
        (out / name).write_bytes(b"\x89PNG mine")
    with pytest.raises(KinelabError, match="holiday.png"):
        check_output_folder(out, "validate")
    (out / "holiday.png").unlink()  # a figure named as validate names one, and no report beside it: still the user's
    with pytest.raises(KinelabError, match="era_elbow.png"):
        check_output_folder(out, "validate")
    assert sorted(p.name for p in out.iterdir()) == ["era_elbow.png"]


def test_the_figures_an_old_report_may_hold_are_the_ones_validate_captions():
    from kinelab.report.outfolder import FIGURES
    from kinelab.report.page import CAPTIONS

    assert set(FIGURES) == set(CAPTIONS)
