"""fcplan.experiments.leaderboard and leaderboard_page: tiers from scenario names, the fraction of
the oracle, paired comparisons, the tier check, and a page built from real results."""

from __future__ import annotations

import datetime
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.errors import FcplanError
from fcplan.experiments import compare, sweep
from fcplan.experiments.leaderboard import (
    fraction_of_oracle,
    is_policy,
    leaderboard,
    read_episodes,
    tier_of,
)
from fcplan.experiments.leaderboard_page import markdown
from fcplan.scenario import load_scenario

HARD = "fcplan-bench-v1/hard-{:02d}"


def _rows(scores: dict[str, list[float]], scenarios: int = 2, ofs: float = 50.0) -> list[dict]:
    """Episode rows: scheduler -> one score per (scenario, seed) pair, scenarios outermost."""
    rows = []
    for name, values in scores.items():
        per = len(values) // scenarios
        for i, v in enumerate(values):
            rows.append(
                {
                    "scenario": HARD.format(i // per + 1),
                    "scheduler": name,
                    "seed": i % per,
                    "status": "ok",
                    "manual.final_score": float(v),
                    "manual.overall_firefighting": ofs,
                    "fallbacks": 1,
                    "replans": 10,
                    "replan_solve_ms": [1.0, 2.0, 3.0, 100.0],
                }  # fmt: skip
            )
    return rows


def test_fraction_is_one_for_the_oracle_and_zero_for_idle():
    """A scheduler scoring the oracle's scores has fraction 1, one scoring idle's has 0."""
    oracle, idle = [10.0, 20.0, 5.0, 8.0], [-100.0, -90.0, -120.0, -80.0]
    assert fraction_of_oracle(oracle, oracle, idle)[0] == pytest.approx(1.0)
    assert fraction_of_oracle(idle, oracle, idle)[0] == pytest.approx(0.0)


def test_fraction_is_a_ratio_of_means_not_a_mean_of_ratios():
    """F = sum(s - idle) / sum(oracle - idle); a pair where little was at stake does not
    dominate (its per-pair ratio is 10, the fraction stays near the other pair's)."""
    f, _, median = fraction_of_oracle([10.0, 50.0], [1.0, 100.0], [0.0, 0.0])
    assert f == pytest.approx(60.0 / 101.0)
    assert median == pytest.approx((10.0 + 0.5) / 2)


@settings(max_examples=40, deadline=None)
@given(
    data=st.lists(
        st.tuples(st.floats(-300, 300), st.floats(1, 300), st.floats(-300, -1)),
        min_size=2,
        max_size=12,
    ),
    scale=st.floats(0.1, 10),
    shift=st.floats(-500, 500),
)
def test_fraction_is_invariant_under_affine_changes_of_the_score(data, scale, shift):
    """Rescaling and shifting every score (a * s + b, a > 0) leaves the fraction and its
    interval unchanged: it does not depend on the score's units or zero."""
    s = np.array([d[0] for d in data])
    idle = np.array([d[2] for d in data])
    oracle = idle + np.array([d[1] for d in data])
    f, ci, _ = fraction_of_oracle(s, oracle, idle)
    g, cj, _ = fraction_of_oracle(scale * s + shift, scale * oracle + shift, scale * idle + shift)
    assert g == pytest.approx(f, rel=1e-9, abs=1e-9)
    assert np.allclose(ci, cj, rtol=1e-6, atol=1e-9, equal_nan=True)


def test_fraction_interval_contains_the_estimate_and_is_reproducible():
    """The bootstrap interval (within scenarios) holds the estimate and is the same every call."""
    rng = np.random.default_rng(3)
    idle = rng.normal(-200, 10, 40)
    oracle = idle + rng.uniform(100, 300, 40)
    s = idle + 0.7 * (oracle - idle) + rng.normal(0, 20, 40)
    strata = np.repeat(np.arange(4), 10)
    a = fraction_of_oracle(s, oracle, idle, strata)
    assert a == fraction_of_oracle(s, oracle, idle, strata)
    f, (lo, hi), _ = a
    assert lo < f < hi and hi - lo < 0.3


def test_tiers_come_from_scenario_names():
    """Suite scenarios group by (suite, tier); anything else is the tier 'other'."""
    assert tier_of("fcplan-bench-v1/hard-07") == ("fcplan-bench-v1", "hard")
    assert tier_of("gen-3-abcdef12") == ("", "other")
    assert is_policy("routing") and not is_policy("oracle") and not is_policy("random")


def test_policies_ranked_references_apart_and_stats_computed():
    """Policies are ranked by mean; the oracle and idle follow unranked; solve percentiles pool
    every replan; fallbacks and replans are summed; fractions use the same pairs."""
    n = 8
    rows = _rows(
        {"greedy": [10.0] * n, "cbba": [20.0] * n, "oracle": [30.0] * n, "idle": [-70.0] * n}
    )
    t = leaderboard(rows).tiers[0]
    assert t.order == ["cbba", "greedy", "oracle", "idle"]
    assert t.stats["cbba"].fraction == pytest.approx(0.9)
    assert t.stats["greedy"].fraction == pytest.approx(0.8)
    assert t.stats["greedy"].solve_p50_ms == pytest.approx(2.5)
    assert (t.stats["greedy"].fallbacks, t.stats["greedy"].replans) == (n, 10 * n)
    assert t.scenarios == [HARD.format(1), HARD.format(2)] and t.seeds == [0, 1, 2, 3]


def test_proven_gaps_pool_every_bounded_replan_and_show_a_dash_without_one():
    """The gap column pools the replans where a scheduler proved a bound (NaN: none) and says
    on how many; a scheduler that proves no bound gets '-'."""
    n = 8
    rows = _rows({"milp": [10.0] * n, "greedy": [5.0] * n, "oracle": [30.0] * n,
                  "idle": [-70.0] * n})  # fmt: skip
    for r in rows:
        r["replan_gap"] = (
            [0.0, 0.0, 0.1, float("nan")] if r["scheduler"] == "milp" else [float("nan")] * 4
        )
    t = leaderboard(rows).tiers[0]
    milp, greedy = t.stats["milp"], t.stats["greedy"]
    assert milp.bounded_replans == 3 * n and milp.gap_p50 == 0.0
    assert milp.gap_p95 == pytest.approx(np.percentile([0.0, 0.0, 0.1] * n, 95))
    assert greedy.bounded_replans == 0 and math.isnan(greedy.gap_p50)
    page = markdown(t_board := leaderboard(rows))
    assert t_board.tiers[0].stats["milp"].bounded_replans == 3 * n
    line = next(x for x in page.splitlines() if x.startswith("| 1 | milp"))
    assert f"0.00 / {100 * milp.gap_p95:.2f} ({3 * n}/{10 * n})" in line
    assert "| - |" in next(x for x in page.splitlines() if "| greedy" in x)


def test_rows_of_an_older_fcplan_without_gaps_are_read():
    """Results written before the gap columns existed (missing, or NaN after a table read)
    mixed with newer rows: the gaps pool over the rows that have them."""
    n = 8
    rows = _rows({"milp": [10.0] * n, "greedy": [5.0] * n, "oracle": [30.0] * n,
                  "idle": [-70.0] * n})  # fmt: skip
    for i, r in enumerate(rows):
        if r["scheduler"] == "milp" and i % 2:
            r.update(replan_gap=[0.0, 0.2], bounded_replans=2, gap_p50=0.1)
        else:
            r.update(replan_gap=float("nan"), bounded_replans=float("nan"), gap_p50=float("nan"))
    t = leaderboard(rows).tiers[0]
    assert t.stats["milp"].bounded_replans == n and t.stats["milp"].gap_p50 == pytest.approx(0.1)
    assert t.stats["greedy"].bounded_replans == 0
    assert "| - |" in next(x for x in markdown(leaderboard(rows)).splitlines() if "| greedy" in x)


def test_oracle_on_top_compares_the_pairs_both_have():
    """While a study runs the oracle may have fewer (scenario, seed) pairs than a policy: the
    tier check compares their means on the pairs both have, not over different pairs."""
    rows = _rows({"greedy": [10.0, 10.0, 100.0, 100.0] * 2})
    rows += _rows({"oracle": [30.0] * 4, "idle": [-70.0] * 4})  # seeds 0-1 of each scenario
    assert leaderboard(rows).tiers[0].check.oracle_top is True


def test_the_reference_is_the_best_oracle_variant_on_each_pair():
    """With two oracle variants the fraction's reference and the tier check's oracle mean are
    the better variant per (scenario, seed); with one, that variant."""
    n = 8
    rows = _rows({"greedy": [20.0] * n, "oracle": [30.0, 0.0] * 4,
                  "oracle[routing]": [0.0, 30.0] * 4, "idle": [-70.0] * n})  # fmt: skip
    t = leaderboard(rows).tiers[0]
    assert t.stats["greedy"].fraction == pytest.approx(0.9)  # (20 + 70) / (30 + 70)
    assert t.stats["oracle"].fraction == pytest.approx(680 / 800)
    assert t.check.oracle_top is True  # the reference scores 30 on every pair
    assert t.order[-3:] == ["oracle", "oracle[routing]", "idle"]
    alone = leaderboard([r for r in rows if r["scheduler"] != "oracle[routing]"]).tiers[0]
    assert alone.stats["greedy"].fraction == pytest.approx(720 / 680)
    assert alone.check.oracle_top is False  # the oracle's mean 15 is below greedy's 20


def test_a_variant_still_being_played_is_left_out_of_the_reference():
    """An oracle variant that has played only some of the pairs does not shrink the reference
    to those pairs: the reference stays the complete variant's on every pair (the policies'
    fractions are over all of them, with an interval of width > 0), the partial variant's row
    is ranked '-' on the page, not 'ref', and it joins the reference once complete."""
    n = 8
    rng = np.random.default_rng(1)
    greedy = 20.0 + rng.normal(0, 5, n)
    rows = _rows({"greedy": greedy, "oracle": [30.0] * n, "idle": [-70.0] * n})
    partial = [r for r in _rows({"oracle[milp]": [40.0] * n}) if r["seed"] == 0]
    t = leaderboard(rows + partial).tiers[0]
    assert t.reference == ("oracle",)
    f = t.stats["greedy"]
    assert f.fraction == pytest.approx((greedy.sum() + 70 * n) / (100 * n))
    assert f.fraction_ci[0] < f.fraction < f.fraction_ci[1]
    page = markdown(leaderboard(rows + partial)).splitlines()
    assert next(x for x in page if "| oracle[milp]" in x).startswith("| - |")
    assert next(x for x in page if "| oracle (" in x).startswith("| ref |")
    full = leaderboard(rows + _rows({"oracle[milp]": [40.0] * n})).tiers[0]
    assert full.reference == ("oracle", "oracle[milp]")
    assert full.stats["greedy"].fraction == pytest.approx((greedy.sum() + 70 * n) / (110 * n))


def test_fraction_interval_pools_scenarios_of_one_pair():
    """Scenarios with a single pair each would resample to themselves (an interval of zero
    width); they are resampled together, so the interval has width, and strata of several
    pairs keep being resampled within themselves."""
    rng = np.random.default_rng(4)
    idle = np.zeros(6)
    oracle = rng.uniform(50, 150, 6)
    s = oracle * rng.uniform(0.5, 1.0, 6)
    f, (lo, hi), _ = fraction_of_oracle(s, oracle, idle, strata=["a", "b", "c", "d", "e", "f"])
    assert lo < f < hi
    same = fraction_of_oracle(s, oracle, idle, strata=None)
    assert (lo, hi) == same[1]  # every stratum a singleton: the plain bootstrap


def test_tier_check_counts_resolved_pairs_and_cleared_scenarios():
    """Clearly different policies are separated with every pair resolved at Holm p < 0.01 and
    the tier accepted; identical ones are not separated; OFS 100 everywhere is reported."""
    rng = np.random.default_rng(0)
    base = rng.normal(0, 30, 40)
    rows = _rows(
        {
            "a": base + 50,
            "b": base + 25 + rng.normal(0, 1, 40),
            "c": base + rng.normal(0, 1, 40),
            "oracle": base + 80,
            "idle": base - 200,
        }  # fmt: skip
    )
    check = leaderboard(rows).tiers[0].check
    assert check.separated and check.resolved == check.pairs == 3
    assert check.oracle_top and check.accepted and check.cleared_all == ()
    same = _rows({"a": base, "b": base + rng.normal(0, 1, 40)}, ofs=100.0)
    check = leaderboard(same).tiers[0].check
    assert not check.separated and not check.keep and not check.accepted
    assert check.cleared_all == ("a", "b") and check.oracle_top is None


def test_per_scenario_means_spread_and_clearing_on_the_page():
    """Each scenario gets every scheduler's mean score and OFS over its seeds, the policies'
    spread (best minus worst mean) and whether every policy cleared it; the page shows them in
    one table row per scenario and the JSON has the same numbers."""
    rows = _rows({"greedy": [10.0, 20.0, 0.0, 0.0], "cbba": [30.0, 30.0, 5.0, 5.0]})
    for r in rows:  # scenario 1: everyone at OFS 100; scenario 2: cbba short of it on seed 0
        cleared = r["scenario"] == HARD.format(1) or not (
            r["scheduler"] == "cbba" and r["seed"] == 0
        )
        r["manual.overall_firefighting"] = 100.0 if cleared else 80.0
    t = leaderboard(rows).tiers[0]
    assert t.per_scenario[HARD.format(1)] == {"cbba": (30.0, 100.0, 2), "greedy": (15.0, 100.0, 2)}
    assert t.per_scenario[HARD.format(2)]["cbba"] == (5.0, 90.0, 2)
    page = markdown(leaderboard(rows))
    assert "| hard-01 | 30.0 (100) | 15.0 (100) | 15.0 | yes |" in page
    assert "| hard-02 | 5.0 (90) | 0.0 (100) | 5.0 | no |" in page
    doc = leaderboard(rows).to_dict()["tiers"][0]["per_scenario"]
    assert doc[HARD.format(2)]["greedy"] == {"mean": 0.0, "ofs": 100.0, "n": 2}


def test_failed_episodes_are_counted_not_averaged():
    """A failed episode counts in `failed` and is left out of the means and pairs."""
    rows = _rows({"greedy": [1.0, 2.0, 3.0, 4.0], "cbba": [2.0, 3.0, 4.0, 5.0]})
    rows[0].update(status="failed", **{"manual.final_score": math.nan})
    t = leaderboard(rows).tiers[0]
    assert (t.stats["greedy"].episodes, t.stats["greedy"].failed) == (3, 1)
    assert t.pairs[0].diff.n == 3


def test_no_episodes_or_unknown_metric_fail_in_one_line(tmp_path):
    """Empty results and a metric column the results lack are one-line FcplanErrors."""
    with pytest.raises(FcplanError, match="no episodes"):
        leaderboard(str(tmp_path))
    with pytest.raises(FcplanError, match="no column 'manual.nope'"):
        leaderboard(_rows({"greedy": [1.0, 2.0]}), metric="manual.nope")
    with pytest.raises(FcplanError, match="expected a results folder"):
        read_episodes(tmp_path / "x.csv")


@pytest.fixture(scope="module")
def real_results(tmp_path_factory):
    """A small real sweep on two suite scenarios, shortened to 8 s."""
    out = tmp_path_factory.mktemp("results")
    sweep(
        {
            "scenarios": ["hard-01", "hard-02"],
            "schedulers": ["greedy", "cbba", "oracle", "idle"],
            "seeds": "0-1",
            "overrides": {"duration_s": 8},
        },  # fmt: skip
        out,
        jobs=1,
        progress=False,
    )
    return out


def test_page_from_a_real_sweep_names_suite_versions_and_wall_time(real_results):
    """The page of a real results folder names the suite, the libraries, the command, the
    wall time of producing the results and every scheduler of the tier."""
    board = leaderboard(real_results)
    assert [(t.suite, t.tier) for t in board.tiers] == [("fcplan-bench-v1", "hard")]
    page = markdown(board, "fcplan leaderboard results")
    assert "Suite **fcplan-bench-v1**" in page and "numpy" in page
    assert "`fcplan leaderboard results`" in page and "wall-clock time" in page
    for name in ("greedy", "cbba", "oracle (reference", "idle (baseline"):
        assert f"| {name}" in page
    assert board.meta["wall_time_s"] > 0 and board.meta["hosts"]
    doc = board.to_dict()
    json.dumps(doc, allow_nan=False)  # plain JSON, NaN written as null
    assert doc["tiers"][0]["stats"]["greedy"]["episodes"] == 4


def test_page_names_the_code_each_episode_came_from(real_results):
    """The page counts the episodes per code version (the commit of the rows' ``code``) and
    points at `fcplan verify`; rows without the column are counted as not recorded."""
    from fcplan.provenance import code_identity

    ident = code_identity()
    name = (
        ident["commit"][:10] + ("+dirty" if ident["dirty"] else "")
        if ident["commit"]
        else f"source {ident['source']}"
    )
    rows = read_episodes(real_results)
    assert leaderboard(rows).meta["code"] == {name: 16}
    for r in rows[:3]:
        del r["code"]
    board = leaderboard(rows)
    assert board.meta["code"] == {name: 13, "not recorded": 3}
    page = markdown(board)
    assert f"{name} (13 episodes), not recorded (3 episodes)" in page
    assert "`fcplan verify RESULTS`" in page


def test_compare_json_gives_the_same_tier(tmp_path):
    """A `fcplan compare --json` file is read like a results folder (its wall time is the
    comparison's)."""
    short = load_scenario("hard-03").replace(duration_s=5)
    result = compare([short], ["greedy", "idle"], [0, 1], jobs=1)
    path = tmp_path / "c.json"
    result.to_json(path)
    board = leaderboard(path)
    t = board.tiers[0]
    assert (t.suite, t.tier, t.order) == ("fcplan-bench-v1", "hard", ["greedy", "idle"])
    assert board.meta["wall_time_s"] == pytest.approx(result.wall_time_s)


def test_lower_is_better_metrics_rank_and_normalise_the_other_way():
    """On a lower-is-better metric (burned area) the smallest mean ranks first, the fraction of
    the oracle is still 1 for the oracle's values and 0 for idle's, and the oracle on top means
    lowest."""
    rows = _rows({"a": [300.0] * 4, "b": [200.0] * 4, "oracle": [100.0] * 4, "idle": [500.0] * 4})
    for r in rows:
        r["outcome.burned_area_cells"] = r["manual.final_score"]
    t = leaderboard(rows, metric="outcome.burned_area_cells").tiers[0]
    assert t.order[:2] == ["b", "a"]
    assert t.stats["b"].fraction == pytest.approx(0.75)
    assert t.stats["oracle"].fraction == pytest.approx(1.0)
    assert t.check.oracle_top is True


def test_a_partial_policy_is_ranked_apart_and_makes_the_check_provisional():
    """A policy that has played only some (scenario, seed) pairs of the tier is ranked after the
    complete ones whatever its mean, the tier check names it and cannot accept the tier, and the
    page gives it rank `-`, says how many pairs it has and calls the verdict provisional."""
    rng = np.random.default_rng(0)
    base = rng.normal(0, 30, 40)
    full = {"a": base + 50, "b": base + 25, "c": base, "oracle": base + 80, "idle": base - 200}
    rows = _rows(full)
    assert leaderboard(rows).tiers[0].check.accepted  # every pair played: accepted
    # "late" is the best policy on the few pairs it has played (scenario 1, seeds 0-4)
    rows += [dict(r, scheduler="late", **{"manual.final_score": 500.0})
             for r in rows if r["scheduler"] == "a" and r["seed"] < 5
             and r["scenario"] == HARD.format(1)]  # fmt: skip
    t = leaderboard(rows).tiers[0]
    assert t.instances == 40 and t.stats["late"].instances == 5 and t.stats["a"].instances == 40
    assert t.order[:4] == ["a", "b", "c", "late"]
    assert t.check.incomplete == ("late",) and not t.check.accepted
    page = markdown(leaderboard(rows), "fcplan leaderboard results")
    assert "| - | late (partial: 5 of 40 pairs) | 500.0" in page
    assert "| 1 | a |" in page and "| 3 | c |" in page
    assert "**Provisional: not every policy has played every pair yet (late 5 of 40)." in page


def test_page_names_the_tiers_of_a_suite_that_have_no_episodes():
    """Results on two scenarios of fcplan-bench-v1's hard tier alone: the page says that the
    suite's scale tier (six scenarios) has no episodes and that the hard tier has two of its
    twelve, instead of silently leaving them out."""
    page = markdown(leaderboard(_rows({"a": [1.0, 2.0, 3.0, 4.0]})), "cmd")
    assert "no episodes in the results: `fcplan-bench-v1/scale` (6 scenarios)." in page
    assert "Only 2 of the tier's 12 scenarios have episodes so far." in page


def test_wall_time_is_the_union_of_the_episodes_run_intervals():
    """Two overlapping episodes (10-40 s and 20-50 s) and one after a pause (1000-1030 s) took
    70 s of wall-clock time: overlaps count once and the pause between runs is left out."""
    rows = _rows({"a": [1.0, 2.0, 3.0]}, scenarios=1)
    for r, (end, took) in zip(rows, [(40.0, 30.0), (50.0, 30.0), (1030.0, 30.0)], strict=True):
        r["finished_at"] = datetime.datetime.fromtimestamp(end, datetime.UTC).isoformat()
        r["episode_wall_s"] = took
    meta = leaderboard(rows).meta
    assert meta["wall_time_s"] == pytest.approx(70.0) and meta["episode_time_s"] == 90.0
