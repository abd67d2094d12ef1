"""Paired comparisons (:mod:`fcplan.experiments.stats`): Holm's adjustment, Wilcoxon p-values,
paired intervals and effect sizes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import stats

from fcplan.experiments.stats import (
    friedman,
    holm,
    paired_comparisons,
    paired_t_power,
    pairs_needed,
    smallest_wilcoxon_p,
    wilcoxon_p,
)


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
    assert math.isnan(wilcoxon_p([])) and math.isnan(wilcoxon_p([1.0, math.nan]))


def test_wilcoxon_of_all_ties_is_one():
    """Every difference zero is no evidence of a difference: p = 1 (it still counts in the Holm
    family), not NaN."""
    assert wilcoxon_p([0.0, 0.0, 0.0]) == 1.0
    (c,) = paired_comparisons({"a": [1.0, 2.0], "b": [1.0, 2.0]})
    assert c.p == 1.0 and c.ties == 2 and c.verdict() == "identical on all 2 pairs"


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


def test_paired_comparisons_on_keyed_scores_pair_common_instances_only():
    """With scores keyed by instance, each two schedulers are compared on the instances both
    have (a failed episode drops its instance from that scheduler's pairs only), in any order."""
    scores = {
        "a": {"s1": 10.0, "s2": 12.0, "s3": 11.0, "s4": 15.0},
        "b": {"s4": 14.0, "s2": 10.0, "s1": 9.0},
        "c": {"s1": 1.0, "s2": 2.0, "s3": 3.0, "s4": 4.0},
    }
    ab, ac, bc = paired_comparisons(scores)
    assert ab.n == 3 and ab.diff.mean == pytest.approx((1 + 2 + 1) / 3)
    assert ac.n == 4 and bc.n == 3
    assert (ab.wins, ab.ties, ab.losses) == (3, 0, 0) and ab.family == 3


def test_verdicts_in_words():
    """The verdict names the better scheduler (by the metric's direction) when the interval
    excludes 0 and the Holm p passes, says 'unresolved at n=N' with the pairs an 80%-power study
    needs when the interval contains 0, and says when the rank test cannot reach alpha at all."""
    rng = np.random.default_rng(3)
    base = rng.normal(0, 1, 40)
    (c,) = paired_comparisons({"x": base + 1.0, "y": base}, higher_is_better=False)
    assert c.resolved and c.significant and c.verdict() == "y better"
    (c,) = paired_comparisons({"x": base + rng.normal(0.05, 1, 40), "y": base})
    assert not c.resolved and c.verdict().startswith("unresolved at n=40 (~")
    assert "pairs for 80% power" in c.verdict()
    (c,) = paired_comparisons({"x": [5.0, 6.0, 7.0], "y": [1.0, 1.5, 2.0]})
    assert c.resolved and not c.significant
    assert (
        c.verdict()
        == "x ahead on the mean, not significant after Holm (Wilcoxon p >= 0.25 at 3 pairs)"
    )
    assert paired_comparisons({"x": [1.0], "y": [0.0]})[0].verdict() == "one pair: no interval"
    assert paired_comparisons({"x": {}, "y": {}})[0].verdict() == "no pairs"


def test_holm_floor_is_named_for_the_family():
    """Six pairs give a smallest Wilcoxon p of 1/32; over a family of 3 pairs Holm cannot go
    below 3/32 > 0.05, and the verdict says so instead of calling the clear difference nothing."""
    base = np.arange(6.0)
    scores = {"a": base + 100, "b": base + 50, "c": base}
    for c in paired_comparisons(scores):
        assert c.resolved and not c.significant
        assert "Wilcoxon p >= 0.094 after Holm at 6 pairs" in c.verdict()


@pytest.mark.parametrize("effect", [0.3, 0.8])
def test_pairs_needed_gives_the_promised_power(effect):
    """Simulated paired studies of pairs_needed(d) pairs with true effect d resolve (interval
    excludes 0) in 80% of the cases (within Monte Carlo error), and one pair fewer falls short
    of the exact power."""
    n = pairs_needed(effect)
    assert paired_t_power(effect, n) >= 0.8 > paired_t_power(effect, n - 1)
    rng = np.random.default_rng(12)
    trials = 3000
    d = rng.normal(effect, 1.0, (trials, n))
    half = stats.t.ppf(0.975, n - 1) * d.std(axis=1, ddof=1) / np.sqrt(n)
    resolved = np.abs(d.mean(axis=1)) > half
    assert resolved.mean() == pytest.approx(paired_t_power(effect, n), abs=3 * 0.4 / trials**0.5)


def test_pairs_needed_edge_cases():
    """A zero effect never resolves (inf), a NaN effect gives NaN, and the sign does not matter."""
    assert pairs_needed(0.0) == math.inf and math.isnan(pairs_needed(math.nan))
    assert pairs_needed(-0.5) == pairs_needed(0.5) == 34
    assert smallest_wilcoxon_p(0) == 1.0 and smallest_wilcoxon_p(10) == pytest.approx(2 / 1024)


def test_friedman_matches_scipy_and_kendall_w():
    """Friedman's p is scipy's; Kendall's W is chi2 / (n (k - 1)); mean ranks follow the
    metric's direction (rank 1 = best)."""
    rng = np.random.default_rng(5)
    x = rng.normal(0, 1, (3, 12)) + np.array([[1.0], [0.5], [0.0]])
    f = friedman(x)
    ref = stats.friedmanchisquare(*x)
    assert f.p == pytest.approx(ref.pvalue) and f.blocks == 12
    assert f.w == pytest.approx(ref.statistic / (12 * 2))
    low = friedman(x, higher_is_better=False)
    assert np.allclose(np.array(f.mean_ranks) + np.array(low.mean_ranks), 4.0)
    assert math.isnan(friedman(x[:2]).p)  # two schedulers: no Friedman test


@given(
    st.integers(3, 5).flatmap(
        lambda k: st.lists(
            st.lists(st.floats(-100, 100), min_size=k, max_size=k), min_size=2, max_size=15
        )
    )
)
def test_kendall_w_is_in_the_unit_interval(blocks):
    """Kendall's W is in [0, 1] (or NaN when undefined) for any data, ties included."""
    f = friedman(np.array(blocks).T)
    assert math.isnan(f.w) or 0.0 <= f.w <= 1.0 + 1e-12


def test_unresolved_mean_with_a_significant_rank_test_says_so():
    """When most pairs lean one way but a few large differences the other way keep the mean's
    interval around 0, the verdict is 'unresolved' and names the side the signed-rank test
    favours."""
    d = np.array([-1.0] * 90 + [1.0] * 20 + [10.0] * 6)  # median -1, mean ~ -0.08
    (c,) = paired_comparisons({"x": d, "y": np.zeros(d.size)})
    assert not c.resolved and c.p_holm < 0.05 and c.median == -1.0
    assert c.verdict().startswith("unresolved at n=116 (")
    assert "but Wilcoxon favours y, Holm p=" in c.verdict()
