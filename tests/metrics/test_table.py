"""Tests of fcplan.metrics.table: the one metric table and the text table printed from it."""

from __future__ import annotations

import dataclasses

import pytest

from fcplan.errors import UnknownNameError
from fcplan.metrics import METRICS, Metrics, compute_all, format_metrics, metric_spec
from fcplan.trace import Trace


def test_table_has_one_row_per_metrics_field_in_field_order():
    """METRICS names are exactly the Metrics fields after ``definition``, in declaration order."""
    names = [f.name for f in dataclasses.fields(Metrics)]
    assert names[0] == "definition"
    assert [s.name for s in METRICS] == names[1:]


def test_labels_columns_and_titles_are_unique_and_filled():
    """Every spec has a label, a column header and a title, and no two specs share one."""
    for attr in ("label", "column", "title"):
        values = [getattr(s, attr) for s in METRICS]
        assert all(values), attr
        assert len(set(values)) == len(values), attr


def test_direction_of_penalties_and_scores():
    """Penalties and the negative reward ratio are lower-is-better; every score higher-is-better."""
    lower = {s.name for s in METRICS if not s.higher_is_better}
    assert lower == {"total_negative_reward", "expected_negative_reward", "negative_reward_ratio"}
    assert all(s.unit == "%" for s in METRICS if s.symbol in ("NRR", "OFS", "PS", "AS", "FPS"))


def test_metric_spec_lookup_and_unknown_name():
    """metric_spec finds a spec by field name; an unknown name is an UnknownNameError listing
    the metrics."""
    spec = metric_spec("facility_protection")
    assert spec.symbol == "FPS" and spec.key() == "manual.facility_protection"
    assert spec.heading == "Facility protection"
    with pytest.raises(UnknownNameError, match="known metrics: total_negative_reward"):
        metric_spec("score")


def test_format_metrics_prints_one_line_per_spec_with_its_label_and_unit():
    """format_metrics has a header and one line per METRICS row, starting with its label and
    unit."""
    tr = Trace.from_counts(
        ticks_per_second=1, active=[1], pruned=[1], sensed_active=[1], sensed_ever=[2]
    )
    lines = format_metrics(compute_all(tr)).splitlines()
    assert len(lines) == 1 + len(METRICS)
    for spec, line in zip(METRICS, lines[1:], strict=True):
        assert line[:31].rstrip() == spec.label
        assert line[31:38].rstrip() == spec.unit
