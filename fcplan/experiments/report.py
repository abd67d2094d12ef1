"""Reports: tables with confidence intervals, paired comparisons and plots from sweep results.

:func:`report` reads a results folder (:func:`~fcplan.experiments.load_results`) and writes, into
``out`` (default ``RESULTS/report``):

* ``report.md`` (also returned and printed by ``fcplan report``):

  - *per scheduler*: completed and failed episodes, and for each column of
    :data:`~fcplan.experiments.tables.REPORT_COLUMNS` (the metric table's scores, then solve
    times, fallbacks and wall time) the mean ± 95 % confidence half-width (Student t, :func:`~fcplan.experiments.stats.mean_ci`)
    over the scheduler's completed episodes;
  - the same *per difficulty group* (practice, easy, moderate, hard, custom);
  - *per setting* (scheduler x overrides x replan period x time limit) when the sweep varied
    any of those;
  - *paired comparisons*: for every pair of schedulers, the episodes both completed on the same
    (scenario, seed, overrides, replan period, time limit) are paired; the table gives the number
    of pairs, the mean difference of the metric ± its 95 % CI, wins/ties/losses, and the p-value
    of the two-sided Wilcoxon signed-rank test (:func:`scipy.stats.wilcoxon`, zero differences
    dropped; ``p = 1`` when every pair ties, NaN without pairs);
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
* ``per_scheduler.csv``, ``per_difficulty.csv``, ``paired.csv``: the numbers of the tables.

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
import math
import os
import re
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.experiments.optional import require
from fcplan.experiments.plots import (
    plot_distribution,
    plot_grouped,
    plot_solve_time,
    scheduler_colors,
)
from fcplan.experiments.results import load_results
from fcplan.experiments.stats import mean_ci
from fcplan.experiments.tables import (
    REPORT_COLUMNS,
    difficulty_key,
    fallback_majority,
    higher_is_better,
)

__all__ = ["METRICS", "Report", "report"]

METRICS: dict[str, tuple[str, int]] = {c.name: (c.label, c.decimals) for c in REPORT_COLUMNS}
"""Column -> (label, decimals) of the metrics tabulated with a CI (from
:data:`fcplan.experiments.tables.REPORT_COLUMNS`)."""

_PAIR_ON = ["scenario", "seed", "overrides", "replan_period", "time_limit"]

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
        Columns ``a``, ``b``, ``metric``, ``pairs``, ``mean_diff``, ``ci``, ``wins``, ``ties``,
        ``losses``, ``p_wilcoxon``.
    files : list of Path
        Everything written.
    """

    markdown: str
    tables: dict[str, Any]
    paired: Any
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


def _wilcoxon(d: np.ndarray) -> float:
    if d.size == 0:
        return math.nan
    if np.all(d == 0):
        return 1.0
    stats = require("scipy.stats", "dev")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(stats.wilcoxon(d).pvalue)


def _paired(df: Any, metric: str) -> Any:
    pd = require("pandas", "parquet")
    ok = df[df["status"] == "ok"]
    names = list(dict.fromkeys(df["scheduler"]))
    rows = []
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            xa = ok[ok["scheduler"] == a].set_index(_PAIR_ON)[metric]
            xb = ok[ok["scheduler"] == b].set_index(_PAIR_ON)[metric]
            both = xa.to_frame("a").join(xb.to_frame("b"), how="inner")
            d = (both["a"] - both["b"]).to_numpy(np.float64)
            ci = mean_ci(d)
            rows.append(
                {
                    "a": a,
                    "b": b,
                    "metric": metric,
                    "pairs": int(d.size),
                    "mean_diff": ci.mean,
                    "ci": ci.half_width,
                    "wins": int((d > 0).sum()),
                    "ties": int((d == 0).sum()),
                    "losses": int((d < 0).sum()),
                    "p_wilcoxon": _wilcoxon(d),
                }
            )
    cols = ["a", "b", "metric", "pairs", "mean_diff", "ci", "wins", "ties", "losses"]
    return pd.DataFrame(rows, columns=[*cols, "p_wilcoxon"])


# --------------------------------------------------------------------------------------------
# text


def _label(metric: str) -> str:
    """The header of a result column (the column's own name if it is not tabulated)."""
    return METRICS.get(metric, (metric,))[0]


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


def _p(p: float) -> str:
    if p != p:
        return "nan"
    return f"{p:.2g}" if p >= 1e-4 else "<1e-4"


# --------------------------------------------------------------------------------------------
# report


def report(
    results: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    *,
    html: bool = False,
    metric: str = "manual.final_score",
    plots: bool = True,
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
    metric : str
        The metric of the paired comparisons and the plots (a column such as
        ``manual.final_score`` or ``reference2020.final_score``).
    plots : bool
        Write the PNG plots (needs matplotlib).

    Returns
    -------
    Report

    Raises
    ------
    FcplanError
        No episodes in the folder, an unknown metric, or damaged/foreign files (ResultsError).
    """
    df = _load(results, metric)
    names = _scheduler_order(results, df)
    df = df.assign(_o=df["scheduler"].map({n: i for i, n in enumerate(names)}))
    df = df.sort_values(["_o", "scenario", "seed"], kind="stable").drop(columns="_o")
    diffs = sorted(df["difficulty"].dropna().unique(), key=difficulty_key)
    scenarios = sorted(df["scenario"].unique(), key=_scenario_order)
    metrics = [m for m in METRICS if m in df.columns]
    tables, setting_cols = _tables(df, diffs, metrics)
    paired = _paired(df, metric)
    out_dir = Path(out) if out is not None else Path(results) / "report"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FcplanError(f"{out_dir}: cannot create the report folder: {exc}") from None
    images: list[tuple[str, Path]] = []
    if plots and (df["status"] == "ok").any():
        images = _draw_plots(out_dir, df, names, diffs, scenarios, metric)
    sections = _sections(df, names, scenarios, tables, setting_cols, metrics, paired, metric)
    sections += [("img", image) for image in images]
    markdown = "\n\n".join(_markdown(kind, content) for kind, content in sections) + "\n"
    files = [out_dir / "report.md", *(p for _, p in images)]
    files += [p.with_suffix(".pdf") for _, p in images]
    (out_dir / "report.md").write_text(markdown, encoding="utf-8")
    csvs = (
        ("per_scheduler", tables["per_scheduler"]),
        ("per_difficulty", tables["per_difficulty"]),
    )
    for name, t in (*csvs, ("paired", paired)):
        t.to_csv(out_dir / f"{name}.csv", index=False)
        files.append(out_dir / f"{name}.csv")
    if html:
        files.append(_write_html(out_dir / "report.html", sections))
    return Report(markdown=markdown, tables=tables, paired=paired, files=files)


def _load(results: str | os.PathLike[str], metric: str) -> Any:
    """The stored episodes, checked to hold ``metric``, with groupable setting columns."""
    pd = require("pandas", "parquet")
    df = load_results(results)
    if df.empty:
        raise FcplanError(f"{results}: no episodes stored yet (run fcplan sweep first)")
    if metric not in df.columns or not pd.api.types.is_numeric_dtype(df[metric]):
        numeric = [c for c in df.columns if c.startswith(("manual.", "reference2020."))]
        numeric = [c for c in numeric if pd.api.types.is_numeric_dtype(df[c])]
        raise FcplanError(
            f"--metric {metric!r}: not a numeric result column; use one of " + ", ".join(numeric)
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
    label = _label(metric)
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
    names: list[str],
    scenarios: list[str],
    tables: dict[str, Any],
    setting_cols: list[str],
    metrics: list[str],
    paired: Any,
    metric: str,
) -> list[Section]:
    """The report's content, shared by its Markdown and HTML forms (plots not included)."""
    n_ok = int((df["status"] == "ok").sum())
    sweeps = sorted(df["config_hash"].dropna().unique()) if "config_hash" in df else []
    intro = (
        f"{len(df)} episodes ({n_ok} completed, {len(df) - n_ok} failed) from "
        f"{len(sweeps)} sweep(s): {len(names)} scheduler(s) x {len(scenarios)} scenario(s) x "
        f"{df['seed'].nunique()} seed(s). Cells are mean ± 95% CI half-width (Student t) over "
        "completed episodes; ± nan means fewer than two. Scores are the manual's unless marked "
        "ref2020."
    )
    sections: list[Section] = [("h1", "fcplan sweep report"), ("p", intro)]
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
    sections += _paired_sections(paired, metric)
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


def _paired_sections(paired: Any, metric: str) -> list[Section]:
    """The paired-comparison heading, note and table."""
    head = ["a", "b", "pairs", "a - b", "a wins/ties/losses", "p (Wilcoxon)", "verdict"]
    body = [
        [
            r.a,
            r.b,
            str(r.pairs),
            f"{_cell(r.mean_diff, 2)} ± {_cell(r.ci, 2)}",
            f"{r.wins}/{r.ties}/{r.losses}",
            _p(r.p_wilcoxon),
            _verdict(r),
        ]
        for r in paired.itertuples()
    ]
    return [
        ("h2", f"Paired comparisons ({_label(metric)})"),
        (
            "p",
            "Episodes paired on (scenario, seed, overrides, replan period, time limit); "
            "difference = a - b; p: two-sided Wilcoxon signed-rank test.",
        ),
        ("table", (head, body)),
    ]


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


def _verdict(r: Any) -> str:
    """Which scheduler is better at the 5 % level (lower is better for penalties and times)."""
    if r.pairs == 0 or r.p_wilcoxon != r.p_wilcoxon:
        return "-"
    if r.p_wilcoxon >= 0.05 or r.mean_diff == 0:
        return "no significant difference"
    lower_better = not higher_is_better(r.metric)
    return f"{r.a} better" if (r.mean_diff > 0) != lower_better else f"{r.b} better"
