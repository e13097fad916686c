"""The URDFs kinelab writes from Denavit–Hartenberg tables (urdf/xarm6.urdf, urdf/crx10ia.urdf and
urdf/ur10e_calibrated.urdf from published ones, urdf/general6r.urdf from its own) are those tables: Pinocchio's FK
of each file equals the standard DH product at seeded random configurations."""

import numpy as np
import pytest

import kinelab

PI = np.pi
# (θ offset [rad], d [m], α [rad], a [m]) per joint, copied from each file's header (the published numbers)
TABLES = {
    "xarm6": [(0, 0.267, -PI / 2, 0), (-1.3849179, 0, 0, 0.28948866), (1.3849179, 0, -PI / 2, 0.0775),
              (0, 0.3425, PI / 2, 0), (0, 0, -PI / 2, 0.076), (0, 0.097, 0, 0)],
    "crx10ia": [(0, 0, PI / 2, 0), (PI / 2, 0, 0, 0.54), (0, 0, PI / 2, 0), (0, 0.54, -PI / 2, 0),
                (0, 0.15, PI / 2, 0), (0, 0.16, 0, 0)],
    # the UR10e's published table plus the calibration tools/make_calibrated_ur10e.py lists
    "ur10e_calibrated": [(0, 0.1807 + 0.18e-3, PI / 2 + 0.6e-3, 0.12e-3), (2.1e-3, 0, 3.4e-3, -0.6127 + 0.21e-3),
                         (-1.7e-3, 0, -2.2e-3, -0.57155 - 0.33e-3),
                         (0.9e-3, 0.17415 - 0.27e-3, PI / 2 + 1.1e-3, -0.09e-3),
                         (-1.2e-3, 0.11985 + 0.15e-3, -PI / 2 - 1.9e-3, 0.14e-3), (0, 0.11655 + 0.08e-3, 0, 0)],
    # kinelab's own general 6R arm (tools/make_general_6r.py)
    "general6r": [(0, 0.30, 1.10, 0.08), (0.35, 0.06, -0.55, 0.52), (-0.20, -0.04, 0.80, 0.42),
                  (0, 0.24, -1.25, 0.05), (0.10, 0.07, 0.95, 0.06), (0, 0.11, 0, 0.02)],
}


def dh(theta, d, alpha, a):
    """Rz(θ)·Tz(d)·Tx(a)·Rx(α), the standard DH link transform."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


@pytest.mark.parametrize("name", sorted(TABLES))
def test_the_file_is_its_dh_table(name):
    robot = kinelab.load(name)
    rng = np.random.default_rng(4)
    for _ in range(50):
        q = robot.random_q(rng)
        M = np.eye(4)
        for (offset, d, alpha, a), qi in zip(TABLES[name], q, strict=True):
            M = M @ dh(qi + offset, d, alpha, a)
        np.testing.assert_allclose(robot.fk(q).homogeneous, M, atol=1e-12)
