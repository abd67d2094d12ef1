"""A study's statistics (:mod:`fcplan.experiments.analysis`, :mod:`fcplan.experiments.statblocks`):
pairs by instance, fractions of the oracle, rankings per metric, and their tables."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fcplan.experiments.analysis import (
    RANKING_METRICS,
    metric_rankings,
    oracle_fractions,
    paired_table,
    results_pair_key,
    separation,
    study_stats,
)
from fcplan.experiments.oracle_reference import fraction_of_oracle
from fcplan.experiments.statblocks import blocks, fixed_width


def _rows(values: dict[str, list[float]], metric: str = "manual.final_score") -> list[dict]:
    return [
        {"scheduler": s, "scenario": "#1", "seed": k, metric: v}
        for s, vals in values.items()
        for k, v in enumerate(vals)
    ]


def _seed(row):
    return row["seed"]


def test_paired_table_uses_the_metric_direction():
    """For a lower-is-better metric (burned area) the scheduler with the smaller values is the
    better one; Holm runs over the pairs of that metric."""
    rng = np.random.default_rng(1)
    base = rng.normal(500, 50, 20)
    metric = "outcome.burned_area_cells"
    rows = _rows({"a": base - 40 + rng.normal(0, 5, 20), "b": base, "c": base + 1}, metric)
    ab, ac, bc = paired_table(rows, ["a", "b", "c"], metric, _seed)
    assert ab.verdict() == "a better" and ac.verdict() == "a better"
    assert not ab.higher_is_better and ab.family == 3
    assert bc.verdict() == "b better"  # b is 1 cell smaller on every pair


def test_oracle_fraction_is_normalised_by_idle_as_on_the_leaderboard():
    """With the idle team in the study the fraction is sum(x - idle) / sum(oracle - idle), the
    leaderboard's number (fraction_of_oracle), also where scores are negative; idle itself gets
    no row; 'above' counts instances beating the reference."""
    rows = _rows(
        {
            "oracle": [200.0, 100.0, -50.0, 50.0],
            "g": [100.0, 120.0, -80.0, 40.0],
            "idle": [-100.0, -100.0, -200.0, -100.0],
        }
    )
    (f,) = oracle_fractions(rows, ["g", "idle"], "oracle", "manual.final_score", _seed)
    assert f.baseline == "idle" and f.n == 4 and f.above == 1
    assert f.fraction == pytest.approx((200 + 220 + 120 + 140) / (300 + 200 + 150 + 150))
    assert f.fraction == pytest.approx(fraction_of_oracle([100, 120, -80, 40], [200, 100, -50, 50],
                                                          [-100, -100, -200, -100])[0])  # fmt: skip
    assert f.low <= f.fraction <= f.high


def test_oracle_fraction_without_idle_is_the_ratio_of_sums_and_nan_when_lower_is_better():
    """Without an idle team: sum x / sum oracle (baseline None); for a lower-is-better metric
    that ratio has no meaning and is NaN rather than a misleading number."""
    rows = _rows({"oracle": [200.0, 100.0], "g": [100.0, 110.0]})
    (f,) = oracle_fractions(rows, ["g"], "oracle", "manual.final_score", _seed)
    assert f.baseline is None and f.fraction == pytest.approx(210 / 300)
    burned = _rows({"oracle": [200.0, 100.0], "g": [100.0, 110.0]}, "outcome.burned_area_cells")
    (f,) = oracle_fractions(burned, ["g"], "oracle", "outcome.burned_area_cells", _seed)
    assert math.isnan(f.fraction)


def test_the_reference_is_the_best_oracle_variant_on_each_instance():
    """With two oracle variants the reference on each instance is the better of the two (as on
    the leaderboard), named 'best of ...'; a lower-is-better metric takes the smaller."""
    rows = _rows(
        {
            "oracle": [10.0, 40.0],
            "oracle[routing]": [30.0, 20.0],
            "g": [20.0, 20.0],
            "idle": [0.0, 0.0],
        }
    )
    refs = ["oracle", "oracle[routing]"]
    (f,) = oracle_fractions(rows, ["g", "idle"], refs, "manual.final_score", _seed)
    assert f.oracle == "best of oracle, oracle[routing]"
    assert f.fraction == pytest.approx(40 / 70)
    st = study_stats(rows, [*refs, "g", "idle"], ["manual.final_score"], _seed, references=refs)
    assert st.oracle == f.oracle and st.fractions == [f]


def test_rankings_order_by_direction_and_name_the_separating_metric():
    """Schedulers are ordered best first in each metric's direction; the sentence names the
    metric with most differing pairs, and the headline's count when another metric wins."""
    rng = np.random.default_rng(9)
    n = 30
    noise = rng.normal(0, 30, (3, n))
    rows = []
    for i, s in enumerate(["a", "b", "c"]):
        for k in range(n):
            rows.append(
                {
                    "scheduler": s,
                    "seed": k,
                    "manual.final_score": 250 + noise[i, k],  # no real difference
                    "outcome.burned_area_cells": 300 + 100 * i + rng.normal(0, 5),
                }
            )
    ranked = metric_rankings(rows, ["c", "a", "b"], RANKING_METRICS, _seed)
    assert [r.metric for r in ranked] == ["manual.final_score", "outcome.burned_area_cells"]
    burned = ranked[1]
    assert burned.order == ("a", "b", "c") and burned.chain() == "a > b > c"
    assert burned.significant == 3 and burned.friedman.p < 1e-6
    assert burned.friedman.w == pytest.approx(1.0)
    text = separation(ranked)
    assert text.startswith("burned separates the schedulers best: 3 of 3 pair(s) differ")
    assert "the headline final score separates" in text


def test_study_stats_leaves_the_oracle_out_of_pairs_and_rankings():
    """The reference scheduler is not compared or ranked; it is the denominator of the
    fractions; the blocks are the paired table, the fractions and the ranking."""
    rows = _rows(
        {
            "oracle": [280.0, 270.0, 275.0, 290.0, 285.0, 278.0],
            "a": [250.0, 240.0, 260.0, 255.0, 245.0, 252.0],
            "b": [200.0, 190.0, 210.0, 205.0, 199.0, 201.0],
        }
    )
    st = study_stats(
        rows, ["oracle", "a", "b"], ["manual.final_score"], _seed, references=["oracle"]
    )
    assert st.policies == ("a", "b") and st.oracle == "oracle"
    assert [(c.a, c.b) for c in st.paired["manual.final_score"]] == [("a", "b")]
    assert [f.scheduler for f in st.fractions] == ["a", "b"]
    assert all("oracle" not in r.order for r in st.rankings)
    titles = [b.title for b in blocks(st)]
    assert titles == ["Paired differences: final score", "Fraction of oracle", "Ranking per metric"]
    text = fixed_width(*blocks(st)[1].cells)
    assert text.splitlines()[1].startswith("a ")
    records = st.paired_records()
    assert records[0]["verdict"] == "a better" and records[0]["pairs"] == 6


def test_results_pair_key_reads_missing_and_nan_as_none():
    """Rows before study hashes and rows without a time limit pair with each other."""
    a = {"scenario": "#1", "seed": 0, "overrides": "{}", "replan_period": 1.0}
    b = {**a, "study_hash": float("nan"), "time_limit": math.nan}
    assert results_pair_key(a) == results_pair_key(b)
