"""Reports: every scheduler and a CI per metric, paired Wilcoxon comparisons, files written."""

from __future__ import annotations

import pytest

from fcplan.cli import main
from fcplan.experiments import sweep
from fcplan.experiments.report import METRICS, report

pytest.importorskip("pandas")
pytest.importorskip("matplotlib")

CONFIG = {
    "scenarios": ["practice", 1],
    "schedulers": ["greedy", "random", "idle"],
    "seeds": [0, 1],
    "replan_period": 2.0,
    "overrides": {"duration_s": 30},
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    d = tmp_path_factory.mktemp("results")
    sweep(CONFIG, d, jobs=2, progress=False)
    return d


def test_report_has_every_scheduler_and_a_ci_per_metric(results, tmp_path):
    """Per-scheduler and per-difficulty tables list every scheduler with `mean ± ci` for every
    metric; the paired table covers every pair with a Wilcoxon p-value; files are written."""
    rep = report(results, tmp_path, html=True)
    table = rep.tables["per_scheduler"]
    assert table["scheduler"].tolist() == ["greedy", "random", "idle"]
    for m in METRICS:
        assert table[f"{m} ci"].notna().all(), m
    md = rep.markdown
    for name in CONFIG["schedulers"]:
        line = next(ln for ln in md.splitlines() if ln.startswith(f"| {name} |"))
        assert line.count("±") == len(METRICS)
    assert {"easy", "practice"} <= set(rep.tables["per_difficulty"]["difficulty"])
    pairs = {(r.a, r.b) for r in rep.paired.itertuples()}
    assert pairs == {("greedy", "random"), ("greedy", "idle"), ("random", "idle")}
    assert rep.paired["p_wilcoxon"].between(0, 1).all()
    assert (rep.paired["pairs"] == 4).all()
    names = {p.name for p in rep.files}
    assert {"report.md", "report.html", "score_distribution.png", "solve_time_vs_size.png"} <= names
    assert {"score_per_scenario.png", "score_by_difficulty.png", "paired.csv"} <= names
    assert all(p.stat().st_size > 0 for p in rep.files)


def test_report_cli_prints_markdown(results, tmp_path, capsys):
    """`fcplan report RESULTS --out DIR` prints the Markdown tables and exits 0."""
    assert main(["report", str(results), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "## Per scheduler" in out and "## Paired differences: final score" in out
    assert (tmp_path / "report.md").read_text(encoding="utf-8") == out


def test_unknown_metric_and_empty_folder_are_clear_errors(results, tmp_path, capsys):
    """A metric that is not a numeric column, or a folder without episodes, exits 2 in one line."""
    assert main(["report", str(results), "--metric", "manual.grade"]) == 2
    assert "not a numeric result column" in capsys.readouterr().err
    assert main(["report", str(tmp_path)]) == 2
    assert "no episodes stored" in capsys.readouterr().err


def test_report_warns_about_episodes_that_mostly_fell_back(tmp_path, monkeypatch):
    """A scheduler that fell back on more than half of its replans gets a 'Fallback warning'
    section naming it with its count; a report without such episodes has none."""
    from fcplan import scheduling
    from fcplan.experiments import report, sweep

    class Broken:
        name = "broken-report-test"

        def plan(self, graph, *, time_limit=None, rng=None):
            raise RuntimeError("always")

    monkeypatch.setitem(scheduling._RUNTIME, "broken-report-test", Broken)
    config = {
        "scenarios": ["practice"],
        "schedulers": ["greedy", "broken-report-test"],
        "seeds": [0],
        "overrides": {"duration_s": 4},
    }
    sweep(config, tmp_path, jobs=1, progress=False)
    md = report(tmp_path, plots=False).markdown
    assert "## Fallback warning" in md
    assert "| broken-report-test | 1 | 1 |" in md and "| greedy | 1" not in md.split("Fallback")[1]
