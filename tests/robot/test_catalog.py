from pathlib import Path

import pytest

import kinelab
from kinelab.robot import catalog


def test_registered_names_cover_bundled_and_example_robot_data_arms():
    names = kinelab.robots()
    assert names[:3] == ["stanford", "era", "youbot"]
    assert {"panda", "ur5", "ur3", "ur10", "kinova", "xarm7"} <= set(names)


def test_example_robot_data_robots_directory_is_found_from_package_files():
    robots_dir = catalog.erd_robots_dir()
    assert robots_dir is not None and robots_dir.name == "robots"
    assert (robots_dir / "panda_description" / "urdf" / "panda.urdf").is_file()
    # package:// paths are relative to share/ ("package://example-robot-data/robots/...")
    assert any((Path(d) / "example-robot-data" / "robots").is_dir() for d in catalog.package_dirs())


def test_every_registered_urdf_exists():
    for name in kinelab.robots():
        path, entry = catalog.resolve(name)
        assert path.is_file(), name
        assert entry.name == name


def test_unknown_name_lists_the_valid_ones():
    with pytest.raises(kinelab.RobotNotFoundError) as err:
        catalog.resolve("pandaa")
    assert "pandaa" in str(err.value) and "panda" in str(err.value) and "stanford" in str(err.value)


@pytest.mark.parametrize("name", [n for n in catalog.names() if catalog.ENTRIES[n].source == "example-robot-data"
                                  and not catalog.ENTRIES[n].whole])  # the arms (whole robots: test_tree.py)
def test_every_registered_arm_agrees_with_yourdfpy_and_solves_its_own_poses(name):
    """The registered chain (base and tool from the entry or its SRDF group) against a second URDF reader,
    and FRDM on FK targets judged by Pinocchio."""
    import numpy as np

    from kinelab.analysis.oracles import fk_vs_yourdfpy

    robot = kinelab.load(name)
    agreement = fk_vs_yourdfpy(robot, count=20, seed=0)
    assert agreement.max_position <= 1e-9 and agreement.max_rotation <= 1e-9
    rng = np.random.default_rng(0)
    for k in range(10):
        target = robot.fk(robot.random_q(rng))
        res = kinelab.solve(robot, target, seed=k, time_budget=0.5)
        dp, dr = robot.tool_error(res.q, target)
        assert res.success and dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(res.q)


def test_kinelab_robots_says_where_each_chain_comes_from():
    entry = catalog.ENTRIES["pr2_left"]
    assert entry.chain == "SRDF group 'left_arm' of pr2_manipulation.srdf"
    robot = kinelab.load("pr2_left")
    assert (robot.base, robot.tool) == ("torso_lift_link", "l_wrist_roll_link")
    assert catalog.ENTRIES["tiago"].chain == "torso_lift_link → arm_tool_link"
