"""kinelab.lazy.module, the one way a module names another it imports only on first use (#58 item 5)."""

import subprocess
import sys

PROBE = """
import sys
from kinelab import lazy
namespace = {}
namespace["m"] = lazy.module("json.tool", namespace)
print("json.tool" in sys.modules)
value = namespace["m"].main   # the first read imports it
print("json.tool" in sys.modules, namespace["m"] is sys.modules["json.tool"], value is sys.modules["json.tool"].main)
print(lazy.module("json.tool", {}) is sys.modules["json.tool"])   # imported already: the module itself
"""


def test_a_lazy_module_is_imported_on_first_use_and_then_stands_where_its_name_is():
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "True", "True", "True", "True"]


def test_a_patched_attribute_of_a_lazily_named_module_is_what_its_user_sees(monkeypatch):
    """A test that patches a function of a module is seen by the module that names it lazily (the attribute is
    read from the module at each call, as after a plain import of the module)."""
    import kinelab.geometry
    from kinelab.cli import common

    monkeypatch.setattr(kinelab.geometry, "quat_wxyz_from_matrix", lambda R: np.array([1.0, 0.0, 0.0, 0.0]))
    import numpy as np
    import pinocchio as pin

    pose = common.pose_dict(pin.SE3(pin.exp3(np.array([0.3, 0.0, 0.0])), np.zeros(3)))
    assert pose["quat_wxyz"] == [1.0, 0.0, 0.0, 0.0]
