"""#57 item 1: one writer for every file kinelab writes. It creates a new file (mode by the umask) or replaces a
regular file (its mode kept), and refuses a device, FIFO, socket, folder or a link out of its folder by name, before
any work is done. On aadeea0 ``--html /dev/full`` turned the device into a regular file and said "wrote"."""

import os
import socket
import stat

import pytest

import kinelab
from kinelab import cli
from kinelab.files import output_target, write_output
from kinelab.view.scene import Scene

# every command that writes a file or a folder, with the arguments that make it do so
PAGES = [
    ["branches", "ur5", "--target-q", "0", "-1", "1", "0", "1", "0", "--html"],
    ["view", "ur5", "--html"],
    ["animate", "ur5", "--html"],
    ["map", "view", "STORE", "--html"],
]
FOLDERS = [
    ["validate", "--robots", "stanford", "--n", "2", "--out"],
    ["bench", "--robots", "ur5", "--n", "2", "--out"],
]


def _fifo(tmp_path):
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def _outside_link(tmp_path):
    other = tmp_path / "elsewhere"
    other.mkdir()
    (other / "precious.html").write_text("keep me")
    (tmp_path / "out").mkdir()
    link = tmp_path / "out" / "page.html"
    link.symlink_to(other / "precious.html")
    return link


def _socket(tmp_path):
    path = tmp_path / "s.sock"
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(path))
    return path, sock


def _device(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("making a device node needs root")
    path = tmp_path / "null"
    os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # a copy of /dev/null in the test's own folder
    return path


SPECIAL = {"fifo": _fifo, "outside link": _outside_link, "device": _device}


def _same(path, before):
    after = os.lstat(path)
    return (after.st_mode, after.st_ino, getattr(after, "st_rdev", 0)) == before


@pytest.mark.parametrize("kind", sorted(SPECIAL))
@pytest.mark.parametrize("argv", PAGES, ids=lambda a: a[0] + ("-" + a[1] if a[0] == "map" else ""))
def test_every_page_command_refuses_a_special_path_before_its_work(tmp_path, capsys, argv, kind):
    path = SPECIAL[kind](tmp_path)
    info = os.lstat(path)
    before = (info.st_mode, info.st_ino, getattr(info, "st_rdev", 0))
    argv = [str(tmp_path) if a == "STORE" else a for a in argv]
    code = cli.main([*argv, str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "cannot write the page" in err
    assert _same(path, before)  # the node is what it was
    if kind == "outside link":
        assert (tmp_path / "elsewhere" / "precious.html").read_text() == "keep me"


@pytest.mark.parametrize("kind", sorted(SPECIAL))
@pytest.mark.parametrize("argv", FOLDERS, ids=lambda a: a[0])
def test_every_folder_command_refuses_a_special_path(tmp_path, capsys, argv, kind):
    path = SPECIAL[kind](tmp_path)
    if kind == "outside link":
        path = tmp_path / "report"
        path.symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    info = os.lstat(path)
    before = (info.st_mode, info.st_ino, getattr(info, "st_rdev", 0))
    code = cli.main([*argv, str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "cannot write the report" in err
    assert _same(path, before)
    if kind == "outside link":
        assert (tmp_path / "elsewhere" / "precious.html").read_text() == "keep me"


@pytest.mark.parametrize("kind", sorted(SPECIAL))
def test_map_reach_refuses_a_special_out(tmp_path, capsys, kind):
    pytest.importorskip("zarr")
    path = SPECIAL[kind](tmp_path)
    if kind == "outside link":
        path = tmp_path / "map"
        path.symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    info = os.lstat(path)
    before = (info.st_mode, info.st_ino, getattr(info, "st_rdev", 0))
    code = cli.main(["map", "reach", "ur5", "--voxel", "0.4", "--orientations", "2", "--out", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "cannot write the map" in err
    assert _same(path, before)


def test_the_writer_refuses_a_socket_and_a_folder(tmp_path):
    path, sock = _socket(tmp_path)
    try:
        with pytest.raises(kinelab.KinelabError, match="it is a socket"):
            write_output(path, "x", "page")
    finally:
        sock.close()
    with pytest.raises(kinelab.KinelabError, match="it is a folder"):
        write_output(tmp_path, "x", "page")
    with pytest.raises(kinelab.KinelabError, match="does not exist"):
        write_output(tmp_path / "missing" / "p.html", "x", "page")


def test_a_replaced_page_keeps_its_mode_and_a_new_one_follows_the_umask(tmp_path):
    robot = kinelab.load("stanford")  # drawn from primitives: no meshes to load
    scene = Scene(robot, open=False)
    scene.show(robot.display_q())
    old = tmp_path / "old.html"
    old.write_text("old")
    old.chmod(0o644)
    scene.save_html(old)
    assert stat.S_IMODE(old.stat().st_mode) == 0o644 and "<!DOCTYPE html>" in old.read_text()
    mask = os.umask(0o027)
    try:
        new = scene.save_html(tmp_path / "new.html")
    finally:
        os.umask(mask)
    assert stat.S_IMODE(new.stat().st_mode) == 0o640
    scene.close()


def test_a_link_within_its_folder_writes_its_target(tmp_path):
    (tmp_path / "real.html").write_text("old")
    (tmp_path / "page.html").symlink_to("real.html")
    written = write_output(tmp_path / "page.html", "new", "page")
    assert written == tmp_path / "real.html" and (tmp_path / "real.html").read_text() == "new"
    assert (tmp_path / "page.html").is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["page.html", "real.html"]  # no temporary file left


def test_output_target_accepts_a_new_file(tmp_path):
    assert output_target(tmp_path / "new.html", "page") == tmp_path / "new.html"
    assert not (tmp_path / "new.html").exists()
