"""#60 item 1: where kinelab picks a start (teach, `kinelab ik`'s default), it is well conditioned and says where it
comes from. On aadeea0 the all-zero start was singular on 8 of the 21 registered arms (ur5 at rank 5 of 6,
crx10ia and kinova at rank 3); the threshold is the one `kinelab singular` calls near-singular."""

import numpy as np
import pytest
from helpers import lowest_part

import kinelab
from kinelab.analysis.singular import NEAR_SINGULAR, analyze
from kinelab.robot import catalog
from kinelab.view.scene import sigma_colour, sigma_words

ARMS = [e.name for e in catalog.ENTRIES.values() if not e.whole]


@pytest.mark.parametrize("name", ARMS)
def test_every_arm_starts_well_conditioned_and_says_why(name):
    robot = kinelab.load(name)
    q, how = robot.reference_q()
    a = analyze(robot, q)
    ratio = a.singular_values[a.full_rank - 1] / a.singular_values[0]
    assert a.rank == a.full_rank and ratio >= NEAR_SINGULAR, (how, ratio)
    assert robot.within_limits(q) and how


def test_the_ur5_middle_is_singular_and_the_start_says_it_chose_another():
    ur5 = kinelab.load("ur5")
    lower, upper = ur5.sample_bounds
    middle = analyze(ur5, 0.5 * (lower + upper))
    assert middle.rank < middle.full_rank  # stretched flat: what teach and ik started from
    q, how = ur5.reference_q()
    assert "well-conditioned" in how and not np.allclose(q, 0.5 * (lower + upper))


def test_the_sphere_s_colour_and_words_agree_with_kinelab_singular():
    """`view crx10ia --singular` drew σ_min/σ_max = 0.0122 bright green while `singular` calls < 0.01
    near-singular: now one threshold decides both, red to orange below it, green above."""
    def rgb(c):
        return c >> 16 & 0xFF, c >> 8 & 0xFF, c & 0xFF

    for ratio in (1e-9, 1e-4, 0.0099):
        r, g, _ = rgb(sigma_colour(ratio))
        assert r == 0xFF and g < 0xA0 and sigma_words(ratio) == "near-singular"
    for ratio in (0.0101, 0.0122, 0.3):
        r, g, _ = rgb(sigma_colour(ratio))
        assert g >= 0xC0 and r < g and sigma_words(ratio) == "away from a singular configuration"


FLOOR_STANDING = ["stanford", "era", "xarm6", "crx10ia", "ur10e_calibrated", "general6r", "panda", "ur3", "ur5",
                  "ur10", "kinova", "xarm7", "z1", "so101"]  # arms whose base plane is the floor (not the youBot:
# its base frame is at the wheels' axles, the floor 3.4 cm below)


@pytest.mark.parametrize("name", FLOOR_STANDING)
def test_every_floor_standing_arm_starts_and_shows_above_its_floor(name):
    """#72 item 3: the start (teach, ``kinelab ik``) and the display pose (``kinelab view``) put no frame and no link's
    mesh origin below the base plane by Pinocchio's placements (UR5's start had its wrist at z = −0.176 m)."""
    robot = kinelab.load(name)
    for q in (robot.reference_q()[0], robot.display_q()):
        assert lowest_part(robot, q) >= -1e-9
