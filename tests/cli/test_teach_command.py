"""``kinelab teach``: serves its page on 127.0.0.1 until Ctrl-C or SIGTERM, then frees the port; user errors are one
line and exit 2."""

import json
import os
import re
import signal
import socket
import subprocess
import sys
import urllib.request

import pytest
from helpers import interruptible

from kinelab import cli


def start(*argv):
    proc = interruptible([sys.executable, "-m", "kinelab.cli", "teach", *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONWARNINGS": "ignore"})
    line = proc.stdout.readline()
    found = re.search(r"on (http://127\.0\.0\.1:(\d+)/) \(Ctrl-C to stop\)", line)
    assert found, (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, found.group(1), int(found.group(2))


def port_is_free(port):
    """Whether a server could listen on the port again (as one restarting would: closed connections may linger)."""
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_teach_serves_the_page_and_stops_cleanly_freeing_its_port(stop):
    proc, url, port = start("ur5", "0.3", "-1.2", "1.4", "-0.8", "1.2", "0.2")
    try:
        with urllib.request.urlopen(url, timeout=30) as reply:
            assert "<title>ur5 · teach — kinelab</title>" in reply.read().decode("utf-8")
        with urllib.request.urlopen(url + "state?since=0", timeout=30) as reply:
            assert json.load(reply)["readout"]["q"] == [0.3, -1.2, 1.4, -0.8, 1.2, 0.2]
    finally:
        proc.send_signal(stop)
        out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0 and "Traceback" not in err
    assert port_is_free(port)


def test_user_errors_are_one_line_and_exit_2(capsys):
    for argv, words in ((["ur5", "--port", "70000"], "--port 70000 is not a port"),
                        (["ur5", "9", "9", "9", "9", "9", "9"], "looks like degrees"),
                        (["ur5", "--time-budget", "0"], "--time-budget 0 s"),
                        (["no-such-robot"], "no-such-robot")):
        code = cli.main(["teach", *argv])
        err = capsys.readouterr().err
        assert code == 2 and len(err.strip().splitlines()) == 1 and words in err, (argv, err)


def test_a_whole_robot_s_page_is_served_with_a_target_per_hand():
    proc, url, _ = start("baxter")
    try:
        with urllib.request.urlopen(url, timeout=60) as reply:
            page = reply.read().decode("utf-8")
        assert "<title>baxter · teach — kinelab</title>" in page and '"targets": ["target_0", "target_1"]' in page
        with urllib.request.urlopen(url + "state?since=0", timeout=30) as reply:
            hands = json.load(reply)["readout"]["hands"]
        assert [h["frame"] for h in hands] == ["left_gripper", "right_gripper"]
        assert all(h["position_error_m"] == 0.0 for h in hands)  # the targets start on the hands
    finally:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    assert proc.returncode == 0 and "Traceback" not in err


def test_a_whole_robot_s_page_refuses_a_chain_s_flags_by_name(capsys):
    for argv, words in ((["talos", "0.1"], "drop Q"),
                        (["talos", "--hands", "no_such_frame"], "no_such_frame"),
                        (["ur5", "--hands", "tool0", "--tool", "tool0"], "drop --tool")):
        code = cli.main(["teach", *argv])
        err = capsys.readouterr().err
        assert code == 2 and len(err.strip().splitlines()) == 1 and words in err, (argv, err)
