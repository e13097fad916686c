"""Shared test helpers: the robots the cross-checks use, and small URDFs written by the tests."""

BUNDLED = ("stanford", "era", "youbot")
ERD_ARMS = ("panda", "ur5", "kinova", "xarm7")


def write_urdf(tmp_path, body: str, name: str = "r.urdf") -> str:
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="t">\n{body}\n</robot>\n')
    return str(path)


def revolute(name, parent, child, axis="0 0 1", xyz="0 0 0.5", extra=""):
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-2" upper="2" effort="1" velocity="1"/>'
            f"{extra}</joint>")
