"""Tests for fcplan.experiments.tables: experiment columns come from the one metric table."""

from __future__ import annotations

import pytest

from fcplan.experiments.tables import (
    OUTCOME_COLUMNS,
    REPORT_COLUMNS,
    RUN_COLUMNS,
    SCORE_COLUMNS,
    difficulty_key,
    higher_is_better,
)
from fcplan.metrics import METRICS, metric_spec


def test_score_columns_take_labels_decimals_and_direction_from_the_metric_table():
    """Every score column is ``<definition>.<metric>`` and carries its MetricSpec's column
    header (except the marked reference2020 column), decimals and direction."""
    names = {s.name for s in METRICS}
    for col in SCORE_COLUMNS:
        definition, _, metric = col.name.partition(".")
        assert metric in names and definition in ("manual", "reference2020")
        spec = metric_spec(metric)
        assert (col.decimals, col.higher_is_better) == (spec.decimals, spec.higher_is_better)
        assert col.label == (spec.column if definition == "manual" else "ref2020 final")
    assert [c.key for c in SCORE_COLUMNS] == [
        "final_score", "ofs", "ps", "as", "fps", "nrr", "neg_reward", "ref2020_final_score"
    ]  # fmt: skip


def test_old_module_tables_keep_their_contents():
    """compare.METRICS and report.METRICS, now built from the columns, hold what they always did
    (same keys, labels and decimals, in the same order)."""
    import importlib

    compare_mod = importlib.import_module("fcplan.experiments.compare")
    report_mod = importlib.import_module("fcplan.experiments.report")
    scores = [
        ("final_score", "manual.final_score", "final score", 1),
        ("ofs", "manual.overall_firefighting", "OFS %", 1),
        ("ps", "manual.perception", "PS %", 1),
        ("as", "manual.action", "AS %", 1),
        ("fps", "manual.facility_protection", "FPS %", 1),
        ("nrr", "manual.negative_reward_ratio", "NRR %", 1),
        ("neg_reward", "manual.total_negative_reward", "neg. reward", 0),
        ("ref2020_final_score", "reference2020.final_score", "ref2020 final", 1),
    ]
    outcomes = [
        ("outcome.time_to_containment_s", "contain s", 1),
        ("outcome.contained", "contained", 2),
        ("outcome.burned_area_cells", "burned", 0),
        ("outcome.facility_damage_cell_s", "damage cell s", 1),
    ]
    runs = [
        ("solve_p50_ms", "solve p50 ms", 2),
        ("solve_p95_ms", "solve p95 ms", 2),
        ("fallbacks", "fallbacks", 1),
        ("wall_time_s", "wall s", 2),
    ]
    assert list(compare_mod.METRICS.items()) == [(k, (n, lab)) for k, n, lab, _ in scores]
    want = [(n, (lab, d)) for _, n, lab, d in scores]
    want += [(n, (lab, d)) for n, lab, d in outcomes + runs]
    assert list(report_mod.METRICS.items()) == want
    assert REPORT_COLUMNS == SCORE_COLUMNS + OUTCOME_COLUMNS + RUN_COLUMNS


@pytest.mark.parametrize(
    ("column", "higher"),
    [
        ("manual.final_score", True),
        ("manual.total_negative_reward", False),
        ("reference2020.expected_negative_reward", False),
        ("manual.negative_reward_ratio", False),
        ("reference2020.perception", True),
        ("solve_p50_ms", False),
        ("solve_mean_ms", False),
        ("wall_time_s", False),
        ("fallbacks", False),
        ("tasks_mean", True),
        ("ticks", True),
    ],
)
def test_direction_of_result_columns(column, higher):
    """Penalties, NRR, solve and wall times and fallbacks are lower-is-better; scores and other
    columns higher-is-better."""
    assert higher_is_better(column) is higher


def test_difficulty_rows_in_the_scenarios_order_then_by_name():
    """Difficulty groups sort practice, easy, moderate, hard, custom, then unknown names."""
    groups = ["zeta", "custom", "hard", "alpha", "practice", "moderate", "easy"]
    assert sorted(groups, key=difficulty_key) == [
        "practice", "easy", "moderate", "hard", "custom", "alpha", "zeta"
    ]  # fmt: skip
