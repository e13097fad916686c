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
