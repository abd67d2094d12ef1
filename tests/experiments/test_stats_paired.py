"""Paired comparisons (:mod:`fcplan.experiments.stats`): Holm's adjustment, Wilcoxon p-values,
paired intervals and effect sizes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import stats

from fcplan.experiments.stats import holm, paired_comparisons, wilcoxon_p


@given(st.lists(st.floats(0, 1), min_size=1, max_size=12))
def test_holm_is_a_monotone_inflation_capped_at_one(p):
    """Holm: every adjusted p is >= its raw p and <= 1, and the order of the raw p-values is kept
    (a smaller raw p never gets a larger adjusted p)."""
    raw = np.array(p)
    adj = holm(raw)
    assert (adj >= raw - 1e-12).all() and (adj <= 1).all()
    order = np.argsort(raw, kind="stable")
    assert (np.diff(adj[order]) >= -1e-12).all()


def test_holm_known_values_and_nan():
    """Holm on a textbook example (m = 4), and NaN p-values left out of m."""
    assert holm([0.01, 0.04, 0.03, 0.005]).tolist() == pytest.approx([0.03, 0.06, 0.06, 0.02])
    adj = holm([0.01, math.nan, 0.02])
    assert math.isnan(adj[1]) and adj[[0, 2]].tolist() == pytest.approx([0.02, 0.02])


def test_wilcoxon_matches_scipy_without_zeros():
    """The p-value is scipy's two-sided signed-rank test on the non-zero differences."""
    d = np.array([1.5, -0.5, 2.0, 0.0, 3.0, 2.5, -1.0, 4.0])
    assert wilcoxon_p(d) == pytest.approx(stats.wilcoxon(d[d != 0]).pvalue)
    assert math.isnan(wilcoxon_p([0.0, 0.0])) and math.isnan(wilcoxon_p([1.0, math.nan]))


def test_paired_comparisons_every_pair_adjusted_together():
    """Three schedulers give three pairs; the interval is that of the differences, the effect
    is d_z, and the p-values are Holm-adjusted over the three."""
    rng = np.random.default_rng(0)
    base = rng.normal(100, 10, 30)
    scores = {"a": base + 5 + rng.normal(0, 1, 30), "b": base + rng.normal(0, 1, 30), "c": base}
    rows = paired_comparisons(scores)
    assert [(r.a, r.b) for r in rows] == [("a", "b"), ("a", "c"), ("b", "c")]
    d = scores["a"] - scores["b"]
    assert rows[0].diff.mean == pytest.approx(d.mean())
    assert rows[0].effect == pytest.approx(d.mean() / d.std(ddof=1))
    assert rows[0].resolved and rows[0].p_holm == pytest.approx(holm([r.p for r in rows])[0])
    with pytest.raises(ValueError, match="different numbers"):
        paired_comparisons({"a": [1, 2], "b": [1]})
