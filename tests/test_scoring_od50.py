"""OD50 rules: interpolation, extrapolation at both ends, flat curves, double crossings."""

import math

import pytest

from benchmark.scoring import od50

D = [25, 50, 75, 100, 150, 200]


def test_interpolation_between_bracketing_distances():
    # AP falls from 0.7 at 75 m to 0.3 at 100 m: 0.5 is half way -> 87.5 m
    assert od50(D, [0.9, 0.8, 0.7, 0.3, 0.2, 0.1]) == pytest.approx(87.5)
    # a point exactly at 0.5 followed by a lower one is the crossing
    assert od50(D, [0.9, 0.5, 0.4, 0.3, 0.2, 0.1]) == pytest.approx(50.0)


def test_order_of_points_does_not_matter():
    assert od50(D[::-1], [0.1, 0.2, 0.3, 0.7, 0.8, 0.9]) == pytest.approx(87.5)


def test_extrapolation_beyond_the_far_end():
    # last two points 0.8 (150 m), 0.6 (200 m): slope -0.004 /m -> 0.5 at 225 m
    assert od50(D, [0.95, 0.9, 0.9, 0.85, 0.8, 0.6]) == pytest.approx(225.0)


def test_extrapolation_below_the_near_end():
    # first two points 0.45 (25 m), 0.35 (50 m): slope -0.004 /m -> 0.5 at 12.5 m
    assert od50(D, [0.45, 0.35, 0.3, 0.2, 0.1, 0.0]) == pytest.approx(12.5)
    # clipped at 0 m when the line reaches 0.5 only at negative distance
    assert od50(D, [0.2, 0.1, 0.1, 0.0, 0.0, 0.0]) == 0.0  # line gives -50 m


def test_flat_or_rising_curves():
    assert od50(D, [0.9] * 6) == math.inf  # never falls to 0.5
    assert od50(D, [0.9, 0.8, 0.8, 0.7, 0.6, 0.7]) == math.inf  # rising at the far end
    assert od50(D, [0.2] * 6) == 0.0  # never reaches 0.5
    assert od50(D, [0.1, 0.2, 0.3, 0.3, 0.2, 0.1]) == 0.0  # below 0.5 throughout, rising near


def test_double_crossing_counts_the_first_downward_one():
    # down at 25-50 m (0.7 -> 0.3), up again, down at 100-150 m: the first one counts
    assert od50(D, [0.7, 0.3, 0.6, 0.6, 0.4, 0.2]) == pytest.approx(37.5)
    # an upward crossing near (multiscale-like dip at 25 m) is skipped: 0.5 at 125 m
    assert od50(D, [0.4, 0.8, 0.9, 0.6, 0.4, 0.2]) == pytest.approx(125.0)
    # up-crossing only, ends above: extrapolate from the last two (0.6 -> 0.55): 250 m
    assert od50(D, [0.3, 0.4, 0.5, 0.6, 0.6, 0.55]) == pytest.approx(250.0)


def test_nan_points_are_dropped_and_bad_input_rejected():
    assert od50(D, [0.9, float("nan"), 0.7, 0.3, 0.2, 0.1]) == pytest.approx(87.5)
    with pytest.raises(ValueError, match="two or more"):
        od50([25, 50], [0.5, float("nan")])
    with pytest.raises(ValueError, match="same length"):
        od50([25, 50], [0.5])
    with pytest.raises(ValueError, match="distinct"):
        od50([25, 25], [0.6, 0.4])
