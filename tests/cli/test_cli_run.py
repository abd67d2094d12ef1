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
