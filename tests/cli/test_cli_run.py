"""Tests of fcplan.cli.run: `fcplan run` prints both metric definitions, or JSON."""

from __future__ import annotations

import json

from fcplan.cli import main


def test_run_prints_both_metric_definitions(capsys):
    """`fcplan run practice` prints every manual metric, both definitions, ticks and wall time."""
    assert main(["run", "practice", "--scheduler", "greedy", "--seed", "0"]) == 0
    out = capsys.readouterr().out
    for text in (
        "total negative reward",
        "negative reward ratio",
        "overall firefighting",
        "perception",
        "action",
        "facility protection",
        "final score",
        "grade",
        "manual",
        "reference2020",
        "1800 ticks",
        "wall time",
    ):
        assert text in out, text


def test_run_json_is_machine_readable(capsys):
    """`--json` prints one JSON document with both metric definitions."""
    assert main(["run", "3", "-s", "idle", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["ticks"] == 1800 and set(doc["metrics"]) == {"manual", "reference2020"}


def test_progress_bar_counts_simulated_seconds_and_changes_no_result(capsys, monkeypatch):
    """``fcplan run`` moves a bar to the episode's length in simulated seconds; the results
    printed on stdout are those of a run without a bar."""
    import io

    import fcplan.cli.progress as progress

    real = progress.progress_bar
    monkeypatch.setattr(
        progress, "progress_bar", lambda total, **kw: real(total, **kw, disable=True)
    )
    assert main(["run", "1", "-s", "idle", "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    bars = []

    def shown_bar(total, **kwargs):
        bars.append(real(total, **{**kwargs, "file": io.StringIO()}))
        return bars[-1]

    monkeypatch.setattr(progress, "progress_bar", shown_bar)
    assert main(["run", "1", "-s", "idle", "--json"]) == 0
    with_bar = json.loads(capsys.readouterr().out)
    assert len(bars) == 1 and bars[0].n == bars[0].total == 180
    for doc in (plain, with_bar):
        doc.pop("wall_time_s")
    assert with_bar == plain
