"""Reports: tables with confidence intervals, paired comparisons and plots from sweep results.

:func:`report` reads a results folder (:func:`~fcplan.experiments.load_results`), keeps the
episodes of its one study (a folder holding several studies is refused with a one-line error
naming them, unless one is chosen with ``study`` or they are pooled with ``allow_mixed``, which
the report then states: :mod:`fcplan.experiments.studies`) and writes, into ``out`` (default
``RESULTS/report``):

* ``report.md`` (also returned and printed by ``fcplan report``):

  - *per scheduler*: completed and failed episodes, and for each column of
    :data:`~fcplan.experiments.tables.REPORT_COLUMNS` (the metric table's scores, then solve
    times, fallbacks and wall time) the mean ± 95 % confidence half-width (Student t, :func:`~fcplan.experiments.stats.mean_ci`)
    over the scheduler's completed episodes;
  - the same *per difficulty group* (practice, easy, moderate, hard, custom);
  - *per setting* (scheduler x overrides x replan period x time limit) when the sweep varied
    any of those;
  - *paired differences* of every ``metric`` (headline first): for every pair of schedulers,
    the episodes both completed on the same instance (study, scenario, seed, overrides, replan
    period, time limit) are paired; the table gives the number of pairs, the mean difference
    ``a - b`` with its 95 % Student-t interval, Cohen's ``d_z``, wins/ties/losses, the
    two-sided Wilcoxon signed-rank p-value (:func:`~fcplan.experiments.stats.wilcoxon_p`) and its
    Holm adjustment over the pairs, and a verdict in words (``"unresolved at n=5 (...)"`` when
    the interval is too wide to tell: :mod:`fcplan.experiments.analysis`);
  - *fraction of the oracle*, when a clairvoyant ``oracle`` was swept: each scheduler's share
    of the reference's improvement over the ``idle`` team on the headline metric, as on the
    leaderboard (:func:`~fcplan.experiments.analysis.oracle_fractions`; the oracle is a
    reference: it is left out of the paired tables and rankings);
  - *ranking per metric* (final score, NRR, time to containment, contained, burned area,
    facility damage): the order by mean, the pairs that differ, the median ``|d_z|``, Friedman's
    test and Kendall's ``W``, and which metric separates the schedulers best;
  - the schedulers with episodes that fell back to greedy on more than half of their replans
    (:func:`~fcplan.experiments.tables.fallback_majority`, from the ``fallbacks`` and ``replans``
    columns): those episodes' scores are mostly greedy's;
  - the failed episodes with their errors.
* plots (matplotlib, Agg backend), each as PNG and as PDF beside it
  (:mod:`fcplan.experiments.plots`): ``score_distribution`` (box plot and every episode per
  scheduler), ``score_by_difficulty`` (every episode, and the mean with its CI per difficulty
  group), ``score_per_scenario`` (the same per scenario and scheduler; intervals far beyond the
  episodes' range are cut at the axis and their half-width written), ``solve_time_vs_size``
  (time per scheduler call against the task graph's size, every replan, and the median against
  team size per episode).
* ``report.html`` with ``html=True``: the same tables and the plots embedded.
* ``per_scheduler.csv``, ``per_difficulty.csv``, ``paired.csv``, ``rankings.csv`` (and
  ``oracle_fraction.csv``): the numbers of the tables.

Examples
--------
>>> import tempfile
>>> from fcplan.experiments import sweep
>>> out = tempfile.mkdtemp()
>>> _ = sweep({"scenarios": ["practice"], "schedulers": ["greedy", "idle"], "seeds": [0, 1],
...            "overrides": {"duration_s": 5}}, out, jobs=1, progress=False)
>>> rep = report(out, plots=False)
>>> rep.tables["per_scheduler"]["scheduler"].tolist()
['greedy', 'idle']
>>> rep.paired[["a", "b", "pairs"]].values.tolist()
[['greedy', 'idle', 2]]
"""

from __future__ import annotations

import base64
import html as _html
import json
import os
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.experiments.analysis import StudyStats, metric_label, results_pair_key, study_stats
from fcplan.experiments.optional import require
from fcplan.experiments.plots import (
    plot_distribution,
    plot_grouped,
    plot_solve_time,
    scheduler_colors,
)
from fcplan.experiments.results import load_results
from fcplan.experiments.statblocks import blocks
from fcplan.experiments.stats import mean_ci
from fcplan.experiments.studies import Selection, select_study
from fcplan.experiments.tables import REPORT_COLUMNS, difficulty_key, fallback_majority

__all__ = ["METRICS", "Report", "report"]

METRICS: dict[str, tuple[str, int]] = {c.name: (c.label, c.decimals) for c in REPORT_COLUMNS}
"""Column -> (label, decimals) of the metrics tabulated with a CI (from
:data:`fcplan.experiments.tables.REPORT_COLUMNS`)."""

Section = tuple[str, Any]
"""One block of the report: (``"h1"`` | ``"h2"`` | ``"p"`` | ``"table"`` | ``"img"``, content)."""


@dataclass
class Report:
    """A report's content.

    Attributes
    ----------
    markdown : str
    tables : dict of str -> DataFrame
        ``per_scheduler``, ``per_difficulty`` (and ``per_setting``): numeric columns
        ``<metric>`` (mean) and ``<metric> ci`` (half-width) for every metric in :data:`METRICS`.
    paired : DataFrame
        One row per pair of compared schedulers and metric: ``a``, ``b``, ``metric``, ``pairs``,
        ``mean_diff``, ``ci`` (half-width), ``low``, ``high``, ``effect_dz``, ``wins``, ``ties``,
        ``losses``, ``p_wilcoxon``, ``p_holm``, ``resolved``, ``pairs_needed_80``, ``verdict``
        (:meth:`fcplan.experiments.analysis.StudyStats.paired_records`).
    fractions : DataFrame
        Each scheduler's headline metric as a fraction of the oracle's (empty without an
        oracle).
    rankings : DataFrame
        One row per ranking metric: ``ranking``, ``pairs_differing``, ``median_abs_dz``,
        ``friedman_p``, ``kendall_w``.
    statistics : StudyStats or None
        The objects behind ``paired``, ``fractions`` and ``rankings``.
    files : list of Path
        Everything written.
    """

    markdown: str
    tables: dict[str, Any]
    paired: Any
    fractions: Any = None
    rankings: Any = None
    statistics: StudyStats | None = None
    files: list[Path] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# numbers


def _scenario_order(name: str) -> tuple[int, int, str]:
    m = re.fullmatch(r"#(\d+)", str(name))
    if name == "practice":
        return (0, 0, name)
    return (1, int(m.group(1)), name) if m else (2, 0, str(name))


def _group_table(df: Any, by: list[str], metrics: list[str]) -> Any:
    pd = require("pandas", "parquet")
    rows = []
    for key, g in df.groupby(by, sort=False, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        ok = g[g["status"] == "ok"]
        row: dict[str, Any] = dict(zip(by, key, strict=True))
        row["episodes"] = len(ok)
        row["failed"] = int((g["status"] != "ok").sum())
        for m in metrics:
            ci = mean_ci(ok[m].astype(float).to_numpy()) if m in ok else mean_ci([])
            row[m] = ci.mean
            row[f"{m} ci"] = ci.half_width
        rows.append(row)
    return pd.DataFrame(rows)


def _scheduler_order(results: Any, df: Any) -> list[str]:
    """Scheduler labels in the order of the sweep files (manifests), then any others sorted."""
    order: list[str] = []
    manifests = sorted(Path(results).glob("manifest-*.json"), key=lambda p: p.stat().st_mtime)
    for p in manifests:
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
            order += [str(v["label"]) for v in doc.get("schedulers", [])]
        except (OSError, ValueError, KeyError, TypeError):
            continue
    present = set(df["scheduler"])
    order = [n for n in dict.fromkeys(order) if n in present]
    return order + sorted(present - set(order))


# --------------------------------------------------------------------------------------------
# text


def _cell(v: Any, d: int = 1) -> str:
    if isinstance(v, float):
        return "nan" if v != v else f"{v:.{d}f}"
    return str(v)


def _ci_cells(
    table: Any, label_cols: list[str], metrics: list[str]
) -> tuple[list[str], list[list[str]]]:
    head = [*label_cols, "n", "failed"] + [METRICS[m][0] for m in metrics]
    body = []
    for _, r in table.iterrows():
        cells = [str(r[c]) for c in label_cols] + [str(r["episodes"]), str(r["failed"])]
        for m in metrics:
            d = METRICS[m][1]
            cells.append(f"{_cell(r[m], d)} ± {_cell(r[f'{m} ci'], d)}")
        body.append(cells)
    return head, body


def _md_table(head: list[str], body: list[list[str]]) -> str:
    esc = [[str(c).replace("|", "\\|") for c in row] for row in [head, *body]]
    lines = ["| " + " | ".join(esc[0]) + " |", "|" + "|".join("---" for _ in head) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in esc[1:]]
    return "\n".join(lines)


def _html_table(head: list[str], body: list[list[str]]) -> str:
    h = "".join(f"<th>{_html.escape(str(c))}</th>" for c in head)
    rows = "".join(
        "<tr>" + "".join(f"<td>{_html.escape(str(c))}</td>" for c in row) + "</tr>" for row in body
    )
    return f"<table><thead><tr>{h}</tr></thead><tbody>{rows}</tbody></table>"


# --------------------------------------------------------------------------------------------
# report


def report(
    results: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    *,
    html: bool = False,
    metric: str | Sequence[str] = "manual.final_score",
    plots: bool = True,
    allow_mixed: bool = False,
    study: str | None = None,
) -> Report:
    """Write the report of a sweep's results folder (see the module docstring).

    Parameters
    ----------
    results : path
        A folder written by :func:`~fcplan.experiments.sweep`.
    out : path, optional
        Output folder (default ``results/report``; created if needed).
    html : bool
        Also write ``report.html`` (plots embedded).
    metric : str or sequence of str
        The metric(s) of the paired comparisons (a column such as ``manual.final_score``,
        ``reference2020.final_score`` or ``outcome.burned_area_cells``); the first is the
        headline: the fractions of the oracle and the plots use it.
    plots : bool
        Write the PNG plots (needs matplotlib).
    allow_mixed : bool
        Pool the episodes of several studies written into the folder (the report says so);
        by default a folder holding several studies is refused (:mod:`fcplan.experiments.studies`).
    study : str, optional
        Report only this study of the folder (its hash or a unique prefix).

    Returns
    -------
    Report

    Raises
    ------
    FcplanError
        No episodes in the folder, an unknown metric, several studies (without ``study`` or
        ``allow_mixed``), or damaged/foreign files (ResultsError).
    """
    metric_list = [metric] if isinstance(metric, str) else list(dict.fromkeys(metric))
    df = _load(results, metric_list)
    selection = select_study(df, results, study=study, allow_mixed=allow_mixed)
    df = selection.rows
    names = _scheduler_order(results, df)
    df = df.assign(_o=df["scheduler"].map({n: i for i, n in enumerate(names)}))
    df = df.sort_values(["_o", "scenario", "seed"], kind="stable").drop(columns="_o")
    diffs = sorted(df["difficulty"].dropna().unique(), key=difficulty_key)
    scenarios = sorted(df["scenario"].unique(), key=_scenario_order)
    metrics = [m for m in METRICS if m in df.columns]
    tables, setting_cols = _tables(df, diffs, metrics)
    study_st = _statistics(df, names, metric_list)
    out_dir = Path(out) if out is not None else Path(results) / "report"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FcplanError(f"{out_dir}: cannot create the report folder: {exc}") from None
    images: list[tuple[str, Path]] = []
    if plots and (df["status"] == "ok").any():
        images = _draw_plots(out_dir, df, names, diffs, scenarios, metric_list[0])
    sections = _sections(df, selection, names, scenarios, tables, setting_cols, metrics, study_st)
    sections += [("img", image) for image in images]
    markdown = "\n\n".join(_markdown(kind, content) for kind, content in sections) + "\n"
    (out_dir / "report.md").write_text(markdown, encoding="utf-8")
    rep = Report(markdown=markdown, tables=tables, paired=_frame(study_st.paired_records()))
    rep.fractions = _frame(study_st.fraction_records())
    rep.rankings = _frame(study_st.ranking_records())
    rep.statistics = study_st
    rep.files = [out_dir / "report.md", *(p for _, p in images)]
    rep.files += [p.with_suffix(".pdf") for _, p in images]
    csvs = {
        "per_scheduler": tables["per_scheduler"],
        "per_difficulty": tables["per_difficulty"],
        "paired": rep.paired,
        "rankings": rep.rankings,
    }
    if study_st.fractions:
        csvs["oracle_fraction"] = rep.fractions
    for name, t in csvs.items():
        t.to_csv(out_dir / f"{name}.csv", index=False)
        rep.files.append(out_dir / f"{name}.csv")
    if html:
        rep.files.append(_write_html(out_dir / "report.html", sections))
    return rep


def _statistics(df: Any, names: list[str], metrics: list[str]) -> StudyStats:
    """The paired tables, fractions of the oracle and rankings of the completed episodes."""
    ok = df[df["status"] == "ok"]
    rows = ok.to_dict("records")
    kinds = dict(zip(df["scheduler"], df.get("scheduler_name", df["scheduler"]), strict=True))
    references = [n for n in names if str(kinds.get(n, n)) == "oracle"]
    return study_stats(rows, names, metrics, results_pair_key, references=references)


def _frame(records: list[dict[str, Any]]) -> Any:
    pd = require("pandas", "parquet")
    return pd.DataFrame.from_records(records)


def _load(results: str | os.PathLike[str], metrics: list[str]) -> Any:
    """The stored episodes, checked to hold ``metrics``, with groupable setting columns."""
    pd = require("pandas", "parquet")
    df = load_results(results)
    if df.empty:
        raise FcplanError(f"{results}: no episodes stored yet (run fcplan sweep first)")
    for metric in metrics:
        if metric not in df.columns or not pd.api.types.is_numeric_dtype(df[metric]):
            numeric = [
                c
                for c in df.columns
                if c.startswith(("manual.", "reference2020.", "outcome."))
                and pd.api.types.is_numeric_dtype(df[c])
            ]
            raise FcplanError(
                f"--metric {metric!r}: not a numeric result column; use one of "
                + ", ".join(numeric)
            )
    for c in ("overrides", "time_limit"):
        if c not in df:
            df[c] = "{}" if c == "overrides" else np.nan
    df["time_limit"] = df["time_limit"].fillna(-1.0)  # groupable; -1 = the scheduler's own
    return df


def _tables(df: Any, diffs: list[str], metrics: list[str]) -> tuple[dict[str, Any], list[str]]:
    """The per-scheduler, per-difficulty (and per-setting) tables, and the varied settings.

    ``df["difficulty"]`` is left as text (a missing difficulty reads ``"nan"``).
    """
    pd = require("pandas", "parquet")
    per_sched = _group_table(df, ["scheduler"], metrics)
    df["difficulty"] = pd.Categorical(df["difficulty"], categories=diffs, ordered=True)
    per_diff = _group_table(
        df.sort_values("difficulty", kind="stable"), ["difficulty", "scheduler"], metrics
    )
    per_diff["difficulty"] = per_diff["difficulty"].astype(str)
    df["difficulty"] = df["difficulty"].astype(str)
    tables = {"per_scheduler": per_sched, "per_difficulty": per_diff}
    setting_cols = [c for c in ("overrides", "replan_period", "time_limit") if df[c].nunique() > 1]
    if setting_cols:
        tables["per_setting"] = _group_table(df, ["scheduler", *setting_cols], metrics)
    return tables, setting_cols


def _draw_plots(
    out_dir: Path, df: Any, names: list[str], diffs: list[str], scenarios: list[str], metric: str
) -> list[tuple[str, Path]]:
    """Write the plots (PNG, and PDF beside each); return (title, PNG file) of each."""
    mpl = require("matplotlib", "plot")
    if "matplotlib.pyplot" not in sys.modules:
        mpl.use("Agg")  # files only; a notebook keeps its own backend
    colors = scheduler_colors(names)
    label = metric_label(metric)
    ok = df[df["status"] == "ok"]
    p = out_dir / "score_distribution.png"
    plot_distribution(ok, names, metric, label, p, colors)
    images = [(f"{label} per episode", p)]
    for col, groups, name, title, caption in (
        ("difficulty", diffs, "score_by_difficulty", "by difficulty group", "by difficulty"),
        ("scenario", scenarios, "score_per_scenario", "per scenario", "per scenario"),
    ):
        p = out_dir / f"{name}.png"
        table = _group_table(df, [col, "scheduler"], [metric])
        plot_grouped(ok, table, col, groups, names, metric, label, p, colors, f"{label} {title}")
        images.append((f"{label} {caption}", p))
    p = out_dir / "solve_time_vs_size.png"
    plot_solve_time(df, names, p, colors)
    images.append(("solve time vs problem size", p))
    return images


def _sections(
    df: Any,
    selection: Selection,
    names: list[str],
    scenarios: list[str],
    tables: dict[str, Any],
    setting_cols: list[str],
    metrics: list[str],
    study: StudyStats,
) -> list[Section]:
    """The report's content, shared by its Markdown and HTML forms (plots not included)."""
    n_ok = int((df["status"] == "ok").sum())
    found = selection.studies
    which = (
        f"study {found[0].describe()}"
        if len(found) == 1
        else f"{len(found)} studies: " + ", ".join(s.describe() for s in found)
    )
    intro = (
        f"{len(df)} episodes ({n_ok} completed, {len(df) - n_ok} failed) of {which}: "
        f"{len(names)} scheduler(s) x {len(scenarios)} scenario(s) x "
        f"{df['seed'].nunique()} seed(s). Cells are mean ± 95% CI half-width (Student t) over "
        "completed episodes; ± nan means fewer than two. Scores are the manual's unless marked "
        "ref2020."
    )
    sections: list[Section] = [("h1", "fcplan sweep report"), ("p", intro)]
    if selection.note:
        sections.append(("p", selection.note))
    sections += [
        ("h2", "Per scheduler"),
        ("table", _ci_cells(tables["per_scheduler"], ["scheduler"], metrics)),
        ("h2", "Per difficulty group"),
        ("table", _ci_cells(tables["per_difficulty"], ["difficulty", "scheduler"], metrics)),
    ]
    if "per_setting" in tables:
        sections += [
            ("h2", "Per setting"),
            ("table", _ci_cells(tables["per_setting"], ["scheduler", *setting_cols], metrics)),
        ]
    for block in blocks(study):
        sections += [("h2", block.title), ("p", block.note), ("table", block.cells)]
    sections += _fallback_sections(df[df["status"] == "ok"])
    failed = df[df["status"] != "ok"]
    if len(failed):
        rows = [
            [str(r.scheduler), str(r.scenario), str(r.seed), str(r.error)[:160]]
            for r in failed.head(20).itertuples()
        ]
        sections += [
            ("h2", f"Failed episodes ({len(failed)})"),
            ("table", (["scheduler", "scenario", "seed", "error"], rows)),
        ]
    return sections


def _fallback_sections(ok: Any) -> list[Section]:
    """A warning table of the schedulers whose episodes mostly fell back (none: nothing)."""
    if not {"fallbacks", "replans"} <= set(ok.columns) or ok.empty:
        return []
    flags = ok.apply(lambda r: fallback_majority(r.to_dict()), axis=1).astype(bool)
    counts = ok.assign(_f=flags).groupby("scheduler", sort=False)["_f"].agg(["sum", "size"])
    rows = [[str(k), str(int(r["sum"])), str(int(r["size"]))] for k, r in counts.iterrows()]
    rows = [r for r in rows if r[1] != "0"]
    if not rows:
        return []
    note = (
        "These episodes fell back to greedy on more than half of their replans: their scores "
        "are mostly greedy's, not the scheduler's."
    )
    head = ["scheduler", "episodes mostly fallen back", "completed episodes"]
    return [("h2", "Fallback warning"), ("p", note), ("table", (head, rows))]


def _markdown(kind: str, content: Any) -> str:
    """One section as Markdown."""
    if kind == "h1":
        return f"# {content}"
    if kind == "h2":
        return f"## {content}"
    if kind == "table":
        return _md_table(*content)
    if kind == "img":
        title, p = content
        return f"![{title}]({p.name})"
    return str(content)


def _html_section(kind: str, content: Any) -> str:
    """One section as HTML (plots embedded)."""
    if kind in ("h1", "h2"):
        return f"<{kind}>{_html.escape(content)}</{kind}>"
    if kind == "table":
        return _html_table(*content)
    if kind == "img":
        title, p = content
        data = base64.b64encode(p.read_bytes()).decode()
        return (
            f"<h3>{_html.escape(title)}</h3><img alt='{_html.escape(title)}' "
            f"src='data:image/png;base64,{data}'>"
        )
    return f"<p>{_html.escape(content)}</p>"


def _write_html(path: Path, sections: list[Section]) -> Path:
    """Write the report as one HTML page."""
    style = (
        "body{font-family:sans-serif;max-width:1200px;margin:2em auto}"
        "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;"
        "padding:3px 6px;text-align:right}img{max-width:100%}"
    )
    body = "".join(_html_section(kind, content) for kind, content in sections)
    doc = (
        f"<!doctype html><html><head><meta charset='utf-8'><title>fcplan report</title>"
        f"<style>{style}</style></head><body>{body}</body></html>\n"
    )
    path.write_text(doc, encoding="utf-8")
    return path
