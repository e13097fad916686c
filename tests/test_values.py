"""kinelab.values: the one test of what kind of number a setting takes, for every layer."""

import math
from fractions import Fraction

import numpy as np
import pytest

from kinelab.values import is_real, is_whole


@pytest.mark.parametrize("value", [0, 1, -2.5, np.float64(0.1), np.float32(3.0), np.int64(7), Fraction(1, 3)])
def test_a_finite_real_of_any_kind_is_real(value):
    assert is_real(value)


@pytest.mark.parametrize("value", [True, False, np.bool_(True), math.nan, math.inf, -math.inf, np.float64("nan"),
                                   "1.0", None, [1.0], np.array([1.0]), 1 + 0j])
def test_bools_non_finite_numbers_and_non_numbers_are_not_real(value):
    assert not is_real(value)


def test_a_real_range_is_closed_unless_above_is_asked_for():
    assert is_real(0.0, 0) and not is_real(0.0, 0, above=True) and is_real(1e-300, 0, above=True)
    assert is_real(2.0, 0, 2) and not is_real(2.0 + 1e-12, 0, 2) and not is_real(-1e-12, 0)
    assert not is_real(math.inf, 0, math.inf)  # an unbounded range still asks for a finite number


@pytest.mark.parametrize("value", [0, -3, 4096, np.int64(5), np.int32(-1), np.uint8(2)])
def test_python_and_numpy_integers_are_whole(value):
    assert is_whole(value)


@pytest.mark.parametrize("value", [True, np.bool_(False), 1.0, np.float64(2.0), "3", None, Fraction(2, 1), math.nan])
def test_bools_floats_and_non_numbers_are_not_whole(value):
    assert not is_whole(value)


def test_a_whole_range_is_closed():
    assert is_whole(1, 1) and not is_whole(0, 1)
    assert is_whole(4096, 8, 4096) and not is_whole(4097, 8, 4096) and not is_whole(7, 8, 4096)
    assert is_whole(2**40) and not is_whole(2**31, hi=2**31 - 1)
