"""Tests for fcplan.experiments.stats: means and Student-t confidence intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.experiments.stats import MeanCI, mean_ci, paired_mean_ci, t_quantile

finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)


def test_ci_matches_hand_computation():
    """The half-width is t_{0.975, n-1} s / sqrt(n), with the t quantile from a printed table."""
    x = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]  # mean 5, sum of squares 32
    s = math.sqrt(32 / 7)
    t_table = 2.365  # Student t, 7 degrees of freedom, 97.5 % quantile (printed tables)
    ci = mean_ci(x)
    assert ci.mean == 5.0 and ci.n == 8
    assert ci.std == pytest.approx(s, rel=1e-12)
    assert ci.half_width == pytest.approx(t_table * s / math.sqrt(8), rel=1e-3)
    assert ci.low == pytest.approx(5.0 - ci.half_width) and ci.high > ci.mean
    assert t_quantile(0.95, 8) == pytest.approx(t_table, rel=1e-3)
    assert t_quantile(0.90, 2) == pytest.approx(6.314, rel=1e-3)  # 1 dof, 95 % quantile


def test_small_samples_documented_edge_cases():
    """n = 0 gives NaN mean and half-width; n = 1 gives the value and a NaN half-width."""
    empty = mean_ci([])
    assert empty.n == 0 and math.isnan(empty.mean) and math.isnan(empty.half_width)
    one = mean_ci([3.5])
    assert one.n == 1 and one.mean == 3.5 and math.isnan(one.half_width) and math.isnan(one.std)
    assert one.format() == "3.5 ± nan"


@given(c=finite, n=st.integers(2, 30))
def test_constant_sample_has_zero_half_width(c, n):
    """A constant sample has mean equal to the constant and a half-width of exactly 0."""
    ci = mean_ci([c] * n)
    assert ci.mean == pytest.approx(c) and ci.half_width == 0.0 and ci.std == 0.0


@given(x=st.lists(finite, min_size=2, max_size=20), shift=finite)
def test_interval_is_shift_equivariant(x, shift):
    """Shifting the sample shifts the mean and leaves the half-width unchanged."""
    a, b = mean_ci(x), mean_ci(np.asarray(x) + shift)
    assert b.mean == pytest.approx(a.mean + shift, abs=1e-6)
    assert b.half_width == pytest.approx(a.half_width, abs=1e-6)
    assert a.half_width >= 0.0


def test_nan_propagates():
    """A NaN value makes mean and half-width NaN (broken scores stay visible)."""
    ci = mean_ci([1.0, float("nan"), 3.0])
    assert math.isnan(ci.mean) and math.isnan(ci.half_width)


def test_paired_is_ci_of_differences():
    """paired_mean_ci(a, b) equals mean_ci(a - b); unequal lengths raise ValueError."""
    a, b = [10.0, 12.0, 9.0, 11.0], [9.0, 10.0, 9.5, 10.0]
    d = paired_mean_ci(a, b)
    ref = mean_ci(np.subtract(a, b))
    assert isinstance(d, MeanCI)
    assert (d.mean, d.half_width, d.n) == (ref.mean, ref.half_width, ref.n)
    with pytest.raises(ValueError, match="length"):
        paired_mean_ci([1.0, 2.0], [1.0])


def test_bad_confidence_is_rejected():
    """A confidence level outside (0, 1) raises ValueError, whatever the sample size."""
    for n in ([1.0], [1.0, 2.0]):
        with pytest.raises(ValueError, match="confidence"):
            mean_ci(n, confidence=1.0)
