"""`fcplan leaderboard RESULTS`: the page printed or written, its JSON, one-line errors."""

from __future__ import annotations

import json

import pytest

from fcplan.cli import main
from fcplan.experiments import sweep
from tests.cli.helpers import one_line_error


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Greedy, oracle and idle on hard-01, two seeds, shortened to 5 s."""
    out = tmp_path_factory.mktemp("results")
    sweep(
        {
            "scenarios": ["hard-01"],
            "schedulers": ["greedy", "oracle", "idle"],
            "seeds": "0-1",
            "overrides": {"duration_s": 5},
        },  # fmt: skip
        out,
        jobs=1,
        progress=False,
    )
    return out


def test_prints_the_page(results, capsys):
    """Without -o the page is printed; it records the command that made it."""
    assert main(["leaderboard", str(results)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# Leaderboard") and f"`fcplan leaderboard {results}`" in out
    assert "## Tier `fcplan-bench-v1/hard`: 1 scenario x 2 seeds" in out


def test_writes_the_page_and_the_numbers(results, tmp_path, capsys):
    """-o writes the page (the same as printed, with -o in the command), --json every number."""
    page, numbers = tmp_path / "leaderboard.md", tmp_path / "numbers.json"
    argv = ["leaderboard", str(results), "-o", str(page), "--json", str(numbers)]
    assert main(argv) == 0
    assert "1 tier(s) (fcplan-bench-v1/hard)" in capsys.readouterr().err
    text = page.read_text()
    assert f"-o {page}" in text and "| greedy |" in text
    doc = json.loads(numbers.read_text())
    assert doc["tiers"][0]["stats"]["greedy"]["fraction"] is not None


def test_another_metric_heads_the_page(results, capsys):
    """--metric ranks by another column (here the burned area, lower is better)."""
    assert main(["leaderboard", str(results), "--metric", "outcome.burned_area_cells"]) == 0
    out = capsys.readouterr().out
    assert "headline metric **burned**" in out and "lower is better" in out


def test_bad_inputs_fail_in_one_line(tmp_path, capsys):
    """A missing folder, a folder without episodes, an unknown metric and an output in a
    missing folder are one-line errors with exit status 2."""
    one_line_error(["leaderboard", str(tmp_path / "none")], capsys, "no such folder")
    one_line_error(["leaderboard", str(tmp_path)], capsys, "no episodes")
    one_line_error(
        ["leaderboard", str(tmp_path), "-o", str(tmp_path / "x" / "y.md")], capsys, "no such"
    )


def test_unknown_metric_fails_in_one_line(results, capsys):
    """A metric column the results lack is named."""
    one_line_error(["leaderboard", str(results), "--metric", "nope"], capsys, "'nope'")
