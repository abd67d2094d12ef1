"""The report's plots: readable for small samples, PNG and PDF, no silent omissions."""

from __future__ import annotations

import numpy as np
import pytest

pd = pytest.importorskip("pandas")
pytest.importorskip("matplotlib")

from fcplan.experiments.plots import (  # noqa: E402
    clip_interval,
    plot_grouped,
    plot_solve_time,
    scheduler_colors,
    value_limits,
)


def test_a_huge_interval_does_not_set_the_axis():
    """With n = 2 an interval of ±1000 around values within [-20, 300] is left out of the axis
    range; a modest interval is kept in it."""
    values = np.array([-20.0, 10.0, 250.0, 300.0])
    means = np.array([-5.0, 275.0])
    lo, hi = value_limits(values, means, np.array([1000.0, 40.0]))
    assert -60 < lo < -20 and 315 < hi < 370
    lo2, hi2 = value_limits(values, means, np.array([1000.0, 200.0]))
    assert hi2 >= 475  # 275 + 200 fits within three spans: shown whole


def test_clip_interval_reports_which_ends_are_cut():
    """An interval is cut to the limits, and each cut end is reported."""
    assert clip_interval(0.0, 10.0, (-5.0, 20.0)) == (-5.0, 10.0, True, False)
    assert clip_interval(0.0, 1.0, (-5.0, 20.0)) == (-1.0, 1.0, False, False)


def _episodes():
    rows = []
    for sched, base in (("greedy", 250.0), ("random", 0.0), ("idle", -200.0)):
        for scen in ("practice", "#1"):
            for seed, d in ((0, -60.0), (1, 60.0)):
                rows.append(
                    dict(scheduler=sched, scenario=scen, seed=seed, status="ok", n_agents=4,
                         score=base + (d * 10 if sched == "random" else d / 10),
                         replan_tasks=[10, 12] if sched == "greedy" else [-1, -1],
                         replan_solve_ms=[1.0, 2.0], solve_p50_ms=1.5)
                )  # fmt: skip
    return pd.DataFrame(rows)


def test_grouped_plot_is_written_as_png_and_pdf(tmp_path):
    """plot_grouped saves a PNG and a PDF, even with n = 2 and an interval of ±7600."""
    ok = _episodes()
    table = (
        ok.groupby(["scenario", "scheduler"], sort=False)["score"]
        .agg(["mean", "std", "count"])
        .reset_index()
    )
    table["score"] = table["mean"]
    table["score ci"] = 12.706 * table["std"] / np.sqrt(table["count"])
    names = ["greedy", "random", "idle"]
    files = plot_grouped(
        ok, table, "scenario", ["practice", "#1"], names, "score", "score",
        tmp_path / "g.png", scheduler_colors(names), "score per scenario",
    )  # fmt: skip
    assert [p.suffix for p in files] == [".png", ".pdf"]
    assert all(p.stat().st_size > 1000 for p in files)
    assert files[1].read_bytes().startswith(b"%PDF")


def test_solve_time_plot_names_the_schedulers_it_cannot_place(tmp_path, monkeypatch):
    """Schedulers with no recorded task-graph size are not drawn on the size axis, and the
    legend says so."""
    import matplotlib.figure

    labels: list[str] = []
    real = matplotlib.figure.Figure.savefig

    def spy(fig, *args, **kwargs):
        for ax in fig.axes:
            leg = ax.get_legend()
            if leg is not None:
                labels.extend(t.get_text() for t in leg.get_texts())
        return real(fig, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    names = ["greedy", "random", "idle"]
    plot_solve_time(_episodes(), names, tmp_path / "s.png", scheduler_colors(names))
    assert "random, idle: no size recorded, not drawn" in labels
    assert (tmp_path / "s.pdf").exists()
