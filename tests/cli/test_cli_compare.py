"""Tests of fcplan.cli.compare: `fcplan compare` tables, files and one-line errors."""

from __future__ import annotations

import json

from fcplan.cli import main
from tests.cli.helpers import one_line_error


def _short_scenario(tmp_path, n=3, seconds=20):
    from fcplan.scenario import dump_scenario, load_scenario

    path = tmp_path / f"short{n}.toml"
    dump_scenario(load_scenario(n).replace(duration_s=seconds), path)
    return str(path)


def test_compare_prints_table_and_writes_files(tmp_path, capsys):
    """`fcplan compare` draws its progress bar (in episodes) on stderr and the table on stdout,
    writes --json and --csv, and exits 0."""
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
    assert (
        "compare: 100%" in captured.err and "4/4" in captured.err and "4/4 episodes" in captured.err
    )
    doc = json.loads(out_json.read_text())
    assert [r["scheduler"] for r in doc["table"]] == ["greedy", "idle"]
    assert len(doc["episodes"]) == 4
    assert out_csv.read_text().splitlines()[0].startswith("scheduler,episodes,errors,")


def test_compare_bad_input_gives_one_line_and_exit_2(tmp_path, capsys):
    """Bad ranges, unknown names, bad numbers and unwritable outputs print one line, exit 2."""
    one_line_error(
        ["compare", "--scenarios", "99", "--schedulers", "greedy"], capsys, "99", "practice"
    )
    one_line_error(["compare", "--schedulers", "nope"], capsys, "nope", "greedy")
    one_line_error(["compare", "--schedulers", "greedy", "--seeds", "a-b"], capsys, "seeds", "a-b")
    one_line_error(["compare", "--schedulers", "greedy", "--scenarios", "5-3"], capsys, "5-3")
    one_line_error(["compare", "--schedulers", "greedy", "--jobs", "0"], capsys, "jobs")
    one_line_error(["compare", "--schedulers", "greedy", "--time-limit", "x"], capsys, "time-limit")
    one_line_error(["compare", "--scenarios", "3"], capsys, "--schedulers")
    missing = str(tmp_path / "no" / "c.json")
    one_line_error(["compare", "--schedulers", "greedy", "--json", missing], capsys, "--json")


def test_compare_seeds_auto_says_why_it_stopped(tmp_path, capsys):
    """`--seeds auto` plays batches until resolved or the cap and prints why it stopped; the
    --json checkpoint can be resumed with --resume (same output, nothing replayed)."""
    out_json = tmp_path / "auto.json"
    argv = ["compare", "--scenarios", _short_scenario(tmp_path, 3, 4), "--schedulers"]
    argv += ["greedy,idle", "--seeds", "auto", "--seed-batch", "2", "--max-seeds", "4"]
    argv += ["--jobs", "1", "--quiet", "--json", str(out_json)]
    assert main(argv) == 0
    first = capsys.readouterr()
    assert first.err == ""  # --quiet: no progress bar
    assert "seeds auto: stopped at" in first.out and "Paired differences: final score" in first.out
    assert main([*argv, "--resume"]) == 0
    assert capsys.readouterr().out.split("\n", 1)[1] == first.out.split("\n", 1)[1]


def test_compare_statistics_options_are_checked(tmp_path, capsys):
    """--resume needs --json; --metric must be a numeric metric; --max-seeds a positive int."""
    base = ["compare", "--scenarios", "3", "--schedulers", "greedy"]
    one_line_error([*base, "--resume"], capsys, "--resume", "--json")
    one_line_error([*base, "--metric", "manual.grade"], capsys, "manual.grade")
    one_line_error([*base, "--seeds", "auto", "--max-seeds", "0"], capsys, "max-seeds")
    one_line_error([*base, "--seeds", "auto", "--seed-batch", "1"], capsys, "batch")
