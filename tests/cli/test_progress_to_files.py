"""#60 item 8: `kinelab validate 2> log` and `map reach` wrote tqdm's bar frames into the log file, against their
own rule (bars only where someone watches). Run as a user would, stderr to a file."""

import os
import subprocess
import sys


def run_logged(tmp_path, *argv):
    log = tmp_path / "log.txt"
    env = {k: v for k, v in os.environ.items() if k != "KINELAB_PROGRESS"}
    with open(log, "w") as err:
        done = subprocess.run([sys.executable, "-m", "kinelab.cli", *argv], stdout=subprocess.DEVNULL, stderr=err,
                              cwd=tmp_path, env=env, timeout=600)
    return done.returncode, log.read_text()


def test_validate_writes_no_bar_into_a_log_file(tmp_path):
    code, text = run_logged(tmp_path, "validate", "--robots", "ur5", "--n", "5", "--out", str(tmp_path / "r"))
    assert code == 0
    assert "\r" not in text and "|" not in text and "it/s" not in text, text[:300]


def test_map_reach_writes_no_bar_into_a_log_file(tmp_path):
    code, text = run_logged(tmp_path, "map", "reach", "so101", "--voxel", "0.1", "--orientations", "4",
                            "--out", str(tmp_path / "m"))
    assert code == 0, text[-500:]
    assert "\r" not in text and "it/s" not in text and "%|" not in text, text[:300]
