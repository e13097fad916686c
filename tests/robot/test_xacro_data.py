"""A xacro file is data (#31.1): no code runs, nothing hangs, includes stay where the user pointed, and the idioms
of real description packages still expand (three packages written in their styles, in data/xacro)."""

import shutil
from pathlib import Path

import numpy as np
import pytest
from helpers import no_hang

import kinelab
import kinelab.cli
from kinelab import URDFError, load

xacro = pytest.importorskip("xacro")
DATA = Path(__file__).parent / "data" / "xacro"
HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
ARM = ('<link name="base"/><link name="tip"/><joint name="j" type="revolute"><parent link="base"/>'
       '<child link="tip"/><origin xyz="0 0 ${L}"/><axis xyz="0 0 1"/>'
       '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n')


def _write(path: Path, body: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEAD + body + "</robot>\n")
    return path


# --- the idioms of real description packages -------------------------------------------------------------------


def test_a_ur_style_package_expands_with_find_arguments_blocks_and_conditionals(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # includes resolve against the file, not the working folder
    path = DATA / "ur_like_description" / "urdf" / "ur_like.urdf.xacro"
    robot = load(path)
    assert robot.joint_names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"] and robot.tool == "tool0"
    # by hand: base 0.1 + d1 up, the shoulder offset along y, then a2 and a3 along the lift joint's pitched z (= x)
    np.testing.assert_allclose(robot.fk(np.zeros(3)).translation, [0.425 + 0.39225, 0.10915 + 0.0273,
                                                                    0.1 + 0.089159], atol=1e-12)
    np.testing.assert_allclose(robot.upper, [2 * np.pi, 2 * np.pi, np.pi], atol=1e-12)  # radians(360), min(.., 180)
    left = load(path, xacro_args={"prefix": "left_", "joint_limit_deg": "90"})
    assert left.joint_names[0] == "left_shoulder_pan_joint"
    np.testing.assert_allclose(left.upper, [np.pi / 2] * 3, atol=1e-12)


def test_a_franka_style_arm_expands_with_relative_includes_multi_blocks_and_elements(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    path = DATA / "franka_like" / "robots" / "arm.urdf.xacro"
    robot = load(path)
    assert robot.joint_names == ["fr_joint1", "fr_joint2", "fr_joint3"] and robot.tool == "fr_hand"
    np.testing.assert_allclose(robot.fk(np.zeros(3)).translation, [0, 0, 0.333 + 0.316 + 0.384 + 0.107], atol=1e-12)
    np.testing.assert_allclose(robot.upper, [2.8973, 1.7628, 2.8973], atol=1e-12)  # indexed list properties
    handless = load(path, xacro_args={"hand": "false", "arm_id": "x"})
    assert handless.tool == "x_link3" and handless.joint_names[0] == "x_joint1"
    # the ** block's origin and geometry landed inside the link's <visual>
    text = robot.urdf_path.read_text()
    assert '<visual><origin xyz="0 0 0.1665"/><geometry><cylinder length="0.333" radius="0.06"/>' in text
    assert '<mass value="1.0"/>' in text  # sqrt(4.0) / 2 from the nested include


def test_a_recursive_macro_a_namespaced_include_and_dirname_expand(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    path = DATA / "generic_arm" / "urdf" / "arm.urdf.xacro"
    for segments in (2, 4, 7):
        robot = load(path, xacro_args={"segments": str(segments)})
        assert robot.joint_names == [f"joint_{i}" for i in range(1, segments + 1)] and robot.tool == "tool"
        np.testing.assert_allclose(robot.fk(np.zeros(segments)).translation, [0, 0, 0.25 * segments + 0.05],
                                   atol=1e-12)
        axes = [robot.model.joints[j].shortname()[-1] for j in range(1, segments + 1)]
        assert axes == ["Z" if i % 2 else "Y" for i in range(1, segments + 1)]


# --- code, hangs and memory ------------------------------------------------------------------------------------


EXPLOITS = {  # what the fault run used: object access through xacro's python namespace, with no denied word
    "subclasses": "${[c for c in python.type.__subclasses__(python.object) if c.__name__ == 'catch_warnings']}",
    "warnings": "${python.vars(python.type)['mro']}",
    "no_underscore": "${python.getattr(python.type, 'mro')}",
    "module": "${xacro.arg.__globals__['os'].system('touch {marker}')}",
    "format": "${'x'.format(python)}",
    "vars": "${python.vars()}",
    "plain": "${type(1)}",
    "lambda": "${(lambda: 1)()}",
}


@pytest.mark.parametrize("name", list(EXPLOITS))
def test_object_access_from_an_expression_is_refused_and_nothing_runs(tmp_path, name):
    marker = tmp_path / "ran"
    path = _write(tmp_path / "evil.urdf.xacro", f'<link name="{EXPLOITS[name].replace("{marker}", str(marker))}"/>')
    with no_hang(20), pytest.raises(URDFError, match="would run code or read the machine"):
        load(path)
    assert not marker.exists()


def test_the_issue_s_os_system_chain_does_not_run_from_the_cli(tmp_path, capsys):
    marker = tmp_path / "ran"
    chain = ("${[c for c in python.type.__subclasses__(python.type.__base__) if c.__name__ == 'catch_warnings'][0]()"
             f"._module.sys.modules['os'].system('touch {marker}')}}")
    path = _write(tmp_path / "evil.urdf.xacro", f'<xacro:property name="x" value="{chain}"/><link name="${{x}}"/>')
    assert kinelab.cli.main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "attribute access" in err and not marker.exists()


@pytest.mark.parametrize("expression, words", [
    ("9**9**9", "a power of more than 4096 bits"),
    ("'a'*10**10", "a repetition of more than 1000000 items"),
    ("[[0]*1000]*100000", "a repetition of more than 1000000 items"),
    ("'%999999999d' % 1", "a '%' format wider than 999"),
    ("str([1]*999999) + str([1]*999999)", "more than 1000000 items"),
])
def test_an_expression_that_would_hang_or_take_gigabytes_is_refused_at_once(tmp_path, expression, words):
    path = _write(tmp_path / "bomb.urdf.xacro", f'<xacro:property name="L" value="${{{expression}}}"/>{ARM}')
    with no_hang(20), pytest.raises(URDFError, match=words):
        load(path)


def test_an_expansion_that_doubles_without_end_stops_at_its_element_limit(tmp_path):
    levels = "".join(f'<xacro:macro name="m{i}"><xacro:m{i - 1}/><xacro:m{i - 1}/></xacro:macro>\n'
                     for i in range(1, 40))
    path = _write(tmp_path / "laughs.urdf.xacro", '<xacro:macro name="m0"><link name="x"/></xacro:macro>\n'
                  + levels + "<xacro:m39/>\n")
    with no_hang(120), pytest.raises(URDFError, match="more than 50000 elements|took more than 20 s"):
        load(path)


def test_a_file_that_includes_itself_is_refused(tmp_path):
    path = _write(tmp_path / "loop.urdf.xacro", '<xacro:include filename="loop.urdf.xacro"/>')
    with no_hang(120), pytest.raises(URDFError, match="loop.urdf.xacro"):
        load(path)


# --- includes and packages -------------------------------------------------------------------------------------


def test_an_include_outside_the_file_s_folders_is_refused_unless_its_folder_is_given(tmp_path):
    (tmp_path / "secret").mkdir()
    _write(tmp_path / "secret" / "part.xacro", '<xacro:property name="L" value="0.4"/>')
    path = _write(tmp_path / "robot" / "r.urdf.xacro", f'<xacro:include filename="../secret/part.xacro"/>{ARM}')
    with pytest.raises(URDFError, match=r"includes .*secret/part.xacro, outside the folders a robot file may read"):
        load(path)
    absolute = _write(tmp_path / "robot" / "abs.urdf.xacro", '<xacro:include filename="/etc/hostname"/>')
    with pytest.raises(URDFError, match="includes /etc/hostname, outside"):
        load(absolute)
    robot = load(path, package_dirs=[str(tmp_path / "secret")])
    np.testing.assert_allclose(robot.fk(np.zeros(1)).translation, [0, 0, 0.4], atol=1e-12)


def test_find_looks_only_in_the_package_dirs_given(tmp_path, monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    package = tmp_path / "ws" / "src" / "my_parts"
    _write(package / "urdf" / "dims.xacro", '<xacro:property name="L" value="0.7"/>')
    (package / "package.xml").write_text("<package><name>my_parts</name></package>")
    path = _write(tmp_path / "robot" / "r.urdf.xacro",
                  f'<xacro:include filename="$(find my_parts)/urdf/dims.xacro"/>{ARM}')
    with pytest.raises(URDFError, match=r"\$\(find my_parts\): no package 'my_parts' in the folders"):
        load(path)
    robot = load(path, package_dirs=[str(tmp_path / "ws")])
    np.testing.assert_allclose(robot.fk(np.zeros(1)).translation, [0, 0, 0.7], atol=1e-12)


def test_a_failed_load_leaves_nothing_behind_for_the_next(tmp_path, monkeypatch):
    """After one failed load xacro's include stack kept that file's folder, so a hostile file loaded first
    redirected a later trusted robot's relative includes."""
    before = (xacro.filestack, xacro.macrostack, list(xacro.all_includes), dict(xacro.substitution_args_context))
    hostile = _write(tmp_path / "hostile" / "h.urdf.xacro",
                     '<xacro:include filename="part.xacro"/><link name="${python.type}"/>')
    _write(tmp_path / "hostile" / "part.xacro", '<xacro:property name="L" value="9"/>')
    good = _write(tmp_path / "good" / "g.urdf.xacro", f'<xacro:include filename="part.xacro"/>{ARM}')
    _write(tmp_path / "good" / "part.xacro", '<xacro:property name="L" value="0.3"/>')
    monkeypatch.chdir(tmp_path / "hostile")  # the working folder holds the hostile part.xacro too
    with pytest.raises(URDFError):
        load(hostile)
    assert (xacro.filestack, xacro.macrostack, list(xacro.all_includes),
            dict(xacro.substitution_args_context)) == before
    np.testing.assert_allclose(load(good).fk(np.zeros(1)).translation, [0, 0, 0.3], atol=1e-12)


def test_a_xacro_file_that_is_not_a_regular_file_or_too_large_is_refused_before_reading(tmp_path):
    with pytest.raises(URDFError, match="not a regular file"):
        load(_fifo(tmp_path))
    big = tmp_path / "big.urdf.xacro"
    with big.open("wb") as f:
        f.truncate(65 * 2**20)  # sparse: 65 MiB of zeros, no disk used
    with no_hang(20), pytest.raises(URDFError, match="kinelab reads files of at most"):
        load(big)


def _fifo(tmp_path: Path) -> Path:
    import os

    fifo = tmp_path / "pipe.urdf.xacro"
    os.mkfifo(fifo)
    return fifo


def test_the_bundled_styles_are_copied_nowhere(tmp_path):
    """The expansion of a package file is written to a private folder, not beside the file."""
    copy = tmp_path / "ur_like_description"
    shutil.copytree(DATA / "ur_like_description", copy)
    load(copy / "urdf" / "ur_like.urdf.xacro")
    assert sorted(p.name for p in (copy / "urdf").iterdir()) == ["ur_like.urdf.xacro", "ur_like_macro.xacro"]


def test_object_access_is_refused_even_in_a_branch_never_taken(tmp_path):
    """The refusal does not depend on values: a skipped branch that reaches xacro's python namespace is refused
    as one that runs."""
    for expression in ("L if True else python.type", "0 and xacro.arg('x')", "L if True else ''.__class__"):
        path = _write(tmp_path / "skip.urdf.xacro", f'<xacro:property name="L" value="0.3"/>'
                      f'<xacro:if value="${{({expression}) is not None}}"></xacro:if>{ARM}')
        with pytest.raises(URDFError, match="would run code or read the machine"):
            load(path)
