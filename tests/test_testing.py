"""rt70.testing: the one comparison helper of the suite fails where it must."""

import math

import numpy as np
import pytest

from rt70.testing import EPS, MIN_REL, assert_close, close, tolerance


def test_relative_bound_is_scaled_by_the_expected_max_norm():
    assert_close([1.0 + 1e-10, 2.0], [1.0, 2.0], rel=1e-10)
    with pytest.raises(AssertionError, match="exceeds"):
        assert_close([1.0 + 1e-9, 2.0], [1.0, 2.0], rel=1e-10)


def test_one_unit_in_the_last_place_passes_at_any_requested_rel():
    value = -246.14
    assert_close(np.nextafter(value, 0.0), value, rel=1e-30)
    assert_close(value + 4 * math.ulp(value), value, rel=0.0 + 1e-300)


def test_min_rel_is_a_few_units_in_the_last_place():
    assert 2 * EPS < MIN_REL < 20 * EPS
    assert tolerance(1e-20, 3.0) == pytest.approx(MIN_REL * 3.0, rel=1e-15)


def test_stated_scale_bounds_a_cancelling_quantity():
    assert_close(1e-9, 0.0, rel=1e-12, scale=1e4)
    with pytest.raises(AssertionError):
        assert_close(1e-7, 0.0, rel=1e-12, scale=1e4)


def test_zero_expected_without_scale_fails_unless_exactly_zero():
    assert_close(0.0, 0.0, rel=1e-12)
    with pytest.raises(AssertionError, match="natural scale"):
        assert_close(1e-300, 0.0, rel=1e-12)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_or_inf_on_either_side_fails(bad):
    with pytest.raises(AssertionError, match="NaN or infinity on the actual"):
        assert_close([1.0, bad], [1.0, 1.0], rel=1.0)
    with pytest.raises(AssertionError, match="NaN or infinity on the expected"):
        assert_close([1.0, 1.0], [1.0, bad], rel=1.0)
    assert not close([bad], [bad], rel=1.0)


def test_empty_or_mismatched_comparisons_fail():
    with pytest.raises(AssertionError, match="nothing compared"):
        assert_close([], [], rel=1e-3)
    with pytest.raises(AssertionError, match="shapes differ"):
        assert_close([1.0, 2.0], [1.0], rel=1e-3)


def test_per_entry_scales_broadcast():
    scale = np.array([1.0, 1e6])
    assert_close([1.0, 2.0 + 1e-5], [1.0, 2.0], rel=1e-10, scale=scale)
    with pytest.raises(AssertionError, match=r"index \(0,\)"):
        assert_close([1.0 + 1e-5, 2.0], [1.0, 2.0], rel=1e-10, scale=scale)


def test_bad_tolerances_are_refused():
    for rel in (0.0, -1.0, math.nan):
        with pytest.raises(ValueError, match="rel"):
            assert_close(1.0, 1.0, rel=rel)
    with pytest.raises(ValueError, match="scale"):
        assert_close(1.0, 1.0, rel=1e-3, scale=-1.0)


def test_what_names_the_quantity():
    with pytest.raises(AssertionError, match="^mass matrix: "):
        assert_close([2.0], [1.0], rel=1e-6, what="mass matrix")


def test_complex_values_compare_by_modulus_not_by_real_parts():
    assert_close([1.0 + 1e-13j], [1.0 + 0.0j], rel=1e-12)
    with pytest.raises(AssertionError):
        assert_close([1.0 + 1e-3j], [1.0 + 0.0j], rel=1e-6)
    with pytest.raises(AssertionError, match="NaN or infinity"):
        assert_close([complex(1.0, math.nan)], [1.0], rel=1.0)


def test_per_entry_scale_holds_small_entries_to_their_own_size():
    expected = np.array([1.0, 1e-6])
    actual = expected * (1.0 + np.array([0.0, 1e-3]))
    assert_close(actual, expected, rel=1e-6)
    with pytest.raises(AssertionError):
        assert_close(actual, expected, rel=1e-6, scale=np.abs(expected))
