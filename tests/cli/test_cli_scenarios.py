"""Tests of fcplan.cli.scenarios and fcplan.cli.scenario: `fcplan scenarios` and
`fcplan scenario validate`."""

from __future__ import annotations

from fcplan.cli import main


def test_scenarios_lists_every_shipped_scenario(capsys):
    """`fcplan scenarios` lists practice and #1..#24 with difficulty and team."""
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "practice" in out and "#24" in out and "hard" in out and "2P/2A" in out


def test_validate_reports_manual_limits(tmp_path, capsys):
    """`fcplan scenario validate` accepts a shipped file and lists the manual limits a file
    exceeds."""
    from fcplan.scenario import load_scenario

    assert main(["scenario", "validate", "12"]) == 0
    assert "within the manual" in capsys.readouterr().out
    big = load_scenario(1).replace(world_size=2000)
    path = tmp_path / "big.toml"
    from fcplan.scenario import dump_scenario

    dump_scenario(big, path)
    assert main(["scenario", "validate", str(path)]) == 0
    assert "exceeds" in capsys.readouterr().out
