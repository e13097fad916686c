"""docs/extending.md holds: its example task, defined on the page (not in kinelab), is stepped and solved on TALOS
and judged here by Pinocchio; the page names every method of the task protocol."""

import re
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinelab.wholebody import Task

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"


def test_the_pages_toy_task_is_stepped_and_solved_by_its_own_methods(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    block = re.search(r"```python\n(.*?)```", PAGE.read_text(), re.S).group(1)
    namespace: dict = {}
    exec(compile(block, "extending.md", "exec"), namespace)  # noqa: S102 - the page's own example
    talos, q, solved = namespace["talos"], namespace["q"], namespace["solved"]
    assert not namespace["problem"].compiled  # a task with no compiled block: the readable step answered
    model, data = talos.model, talos.model.createData()
    j = model.joints[model.getJointId("arm_left_4_joint")]
    assert abs(q[j.idx_q] + 1.2) <= 1e-3
    assert solved.success and abs(solved.q[j.idx_q] + 1.2) <= 1e-6
    start = talos.neutral()
    for q_end in (q, solved.q):
        pin.framesForwardKinematics(model, data, q_end)
        for foot in ("left_sole_link", "right_sole_link"):
            before = talos.frame_placement(start, foot)
            after = data.oMf[model.getFrameId(foot)]
            assert np.linalg.norm(after.translation - before.translation) <= 1e-5
        assert talos.within_limits(q_end)


def test_the_page_names_every_method_of_the_protocol():
    page = PAGE.read_text()
    methods = [name for name in vars(Task) if not name.startswith("_") and name not in ("uses_com", "preference",
                                                                                       "second")]
    missing = [m for m in methods if f"`{m}" not in page]
    assert not missing, missing
