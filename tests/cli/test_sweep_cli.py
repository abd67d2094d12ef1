"""`fcplan sweep`: the --seeds auto options (the rest of the command is tested with the sweep)."""

from __future__ import annotations

from fcplan.cli import main
from tests.cli.helpers import one_line_error

STUDY = """
scenarios = ["practice"]
schedulers = ["greedy", "idle"]
seeds = [0]
[overrides]
duration_s = 4
"""


def test_sweep_seeds_auto_prints_why_it_stopped(tmp_path, capsys):
    """`fcplan sweep --seeds auto` replaces the file's seeds by batches, prints the stop reason
    and the report command; progress is off with --quiet."""
    config = tmp_path / "study.toml"
    config.write_text(STUDY)
    results = tmp_path / "r"
    argv = ["sweep", str(config), "--results", str(results), "--jobs", "1", "--quiet"]
    assert main([*argv, "--seeds", "auto", "--seed-batch", "3", "--max-seeds", "6"]) == 0
    out = capsys.readouterr()
    assert "seeds auto: stopped at" in out.out and out.err == ""
    assert f"report: fcplan report {results}" in out.out


def test_sweep_seeds_options_are_checked(tmp_path, capsys):
    """--seeds takes only 'auto'; --metric must be a numeric metric (one line, exit 2)."""
    config = tmp_path / "study.toml"
    config.write_text(STUDY)
    one_line_error(["sweep", str(config), "--seeds", "0-4"], capsys, "--seeds", "auto")
    one_line_error(
        [
            "sweep",
            str(config),
            "--results",
            str(tmp_path / "r"),
            "--seeds",
            "auto",
            "--metric",
            "x",
        ],
        capsys,
        "'x'",
    )
