"""Tests for fcplan.cli: commands, output, and one-line errors with exit status 2."""

from __future__ import annotations

import json
import subprocess
import sys

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


def _one_line_error(argv, capsys, *expected):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("fcplan")
    for text in expected:
        assert text in err, (text, err)


def test_bad_input_gives_one_line_and_exit_2(tmp_path, capsys):
    """Unknown scenario/scheduler, bad numbers and bad files print one line and exit 2."""
    _one_line_error(["run", "99"], capsys, "99", "practice")
    _one_line_error(["run", "1", "--scheduler", "nope"], capsys, "nope", "greedy")
    _one_line_error(["run", "1", "--seed", "-3"], capsys, "seed", "-3")
    _one_line_error(["run", "1", "--replan-period", "0"], capsys, "replan-period")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nworld_size = -5\n')
    _one_line_error(["scenario", "validate", str(bad)], capsys, "bad.toml")
    _one_line_error(["frobnicate"], capsys, "frobnicate")


def test_console_entry_point_runs_as_module():
    """`python -m fcplan run` works and errors exit 2 without a traceback."""
    ok = subprocess.run(
        [sys.executable, "-m", "fcplan", "run", "3", "-s", "idle", "--json"],
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0 and json.loads(ok.stdout)["scenario"] == "#3"
    bad = subprocess.run(
        [sys.executable, "-m", "fcplan", "run", "nope"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1


def _short_scenario(tmp_path, n=3, seconds=20):
    from fcplan.scenario import dump_scenario, load_scenario

    path = tmp_path / f"short{n}.toml"
    dump_scenario(load_scenario(n).replace(duration_s=seconds), path)
    return str(path)


def test_compare_prints_table_and_writes_files(tmp_path, capsys):
    """`fcplan compare` prints progress on stderr and the table on stdout, writes --json and
    --csv, and exits 0."""
    out_json, out_csv = tmp_path / "c.json", tmp_path / "c.csv"
    argv = ["compare", "--scenarios", _short_scenario(tmp_path), "--schedulers", "greedy,idle"]
    argv += ["--seeds", "0-1", "--jobs", "1", "--json", str(out_json), "--csv", str(out_csv)]
    assert main([*argv, "--by-difficulty"]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].startswith("4 episodes: 1 scenario(s) x 2 scheduler(s) x 2 seed(s)")
    assert lines[1].split()[:3] == ["scheduler", "n", "err"]
    assert lines[2].split()[:3] == ["greedy", "2", "0"] and lines[3].startswith("idle")
    assert "difficulty" in captured.out
    assert "compare: 4/4 episodes (100%)" in captured.err and "ETA" in captured.err
    doc = json.loads(out_json.read_text())
    assert [r["scheduler"] for r in doc["table"]] == ["greedy", "idle"]
    assert len(doc["episodes"]) == 4
    assert out_csv.read_text().splitlines()[0].startswith("scheduler,episodes,errors,")


def test_compare_bad_input_gives_one_line_and_exit_2(tmp_path, capsys):
    """Bad ranges, unknown names, bad numbers and unwritable outputs print one line, exit 2."""
    _one_line_error(
        ["compare", "--scenarios", "99", "--schedulers", "greedy"], capsys, "99", "practice"
    )
    _one_line_error(["compare", "--schedulers", "nope"], capsys, "nope", "greedy")
    _one_line_error(["compare", "--schedulers", "greedy", "--seeds", "a-b"], capsys, "seeds", "a-b")
    _one_line_error(["compare", "--schedulers", "greedy", "--scenarios", "5-3"], capsys, "5-3")
    _one_line_error(["compare", "--schedulers", "greedy", "--jobs", "0"], capsys, "jobs")
    _one_line_error(
        ["compare", "--schedulers", "greedy", "--time-limit", "x"], capsys, "time-limit"
    )
    _one_line_error(["compare", "--scenarios", "3"], capsys, "--schedulers")
    missing = str(tmp_path / "no" / "c.json")
    _one_line_error(["compare", "--schedulers", "greedy", "--json", missing], capsys, "--json")
