"""kinelab.geometry's angle wraps: into (−π, π] by whole turns, the array and the scalar form alike."""

import math

import numpy as np

from kinelab.geometry import wrap_angle, wrap_to_pi


def test_angles_come_back_inside_by_whole_turns_and_both_forms_agree_to_the_bit():
    rng = np.random.default_rng(4)
    angles = np.concatenate([rng.uniform(-50.0, 50.0, 2000), [math.pi, -math.pi, 3 * math.pi, -3 * math.pi, 0.0,
                                                                   2 * math.pi, 1e-300, -1e-300]])
    wrapped = wrap_to_pi(angles)
    assert np.all((wrapped > -math.pi) & (wrapped <= math.pi))
    turns = (angles - wrapped) / (2 * math.pi)
    assert np.allclose(turns, np.round(turns), atol=1e-12)
    assert [wrap_angle(float(a)) for a in angles] == wrapped.tolist()
    inside = rng.uniform(-math.pi, math.pi, 100)
    assert [wrap_angle(float(a)) for a in inside] == inside.tolist()  # exact for an angle already inside
    assert math.isnan(wrap_angle(math.nan)) and wrap_angle(math.inf) == math.inf
