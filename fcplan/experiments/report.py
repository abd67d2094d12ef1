"""Reports: tables with confidence intervals, paired comparisons and plots from sweep results.

:func:`report` reads a results folder (:func:`~fcplan.experiments.load_results`) and writes, into
``out`` (default ``RESULTS/report``):

* ``report.md`` (also returned and printed by ``fcplan report``):

  - *per scheduler*: completed and failed episodes, and for each metric in :data:`METRICS` the
    mean ± 95 % confidence half-width (Student t, :func:`~fcplan.experiments.stats.mean_ci`)
    over the scheduler's completed episodes;
  - the same *per difficulty group* (practice, easy, moderate, hard, custom);
  - *per setting* (scheduler x overrides x replan period x time limit) when the sweep varied
    any of those;
  - *paired comparisons*: for every pair of schedulers, the episodes both completed on the same
    (scenario, seed, overrides, replan period, time limit) are paired; the table gives the number
    of pairs, the mean difference of the metric ± its 95 % CI, wins/ties/losses, and the p-value
    of the two-sided Wilcoxon signed-rank test (:func:`scipy.stats.wilcoxon`, zero differences
    dropped; ``p = 1`` when every pair ties, NaN without pairs);
  - the failed episodes with their errors.
* PNG plots (matplotlib, Agg backend): ``score_distribution.png`` (box plot and every episode per
  scheduler), ``score_by_difficulty.png`` (means with CI bars per difficulty group),
  ``score_per_scenario.png`` (mean and CI per scenario and scheduler), ``solve_time_vs_size.png``
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
from fcplan.experiments.results import load_results
from fcplan.experiments.stats import mean_ci

__all__ = ["METRICS", "Report", "report"]

#: Column -> (label, decimals) of the metrics tabulated with a CI.
METRICS: dict[str, tuple[str, int]] = {
    "manual.final_score": ("final score", 1),
    "manual.overall_firefighting": ("OFS %", 1),
    "manual.perception": ("PS %", 1),
    "manual.action": ("AS %", 1),
    "manual.facility_protection": ("FPS %", 1),
    "manual.negative_reward_ratio": ("NRR %", 1),
    "manual.total_negative_reward": ("neg. reward", 0),
    "reference2020.final_score": ("ref2020 final", 1),
    "solve_p50_ms": ("solve p50 ms", 2),
    "solve_p95_ms": ("solve p95 ms", 2),
    "fallbacks": ("fallbacks", 1),
    "wall_time_s": ("wall s", 2),
}
_DIFFICULTY = ("practice", "easy", "moderate", "hard", "custom")
_LOWER_IS_BETTER = ("negative_reward", "solve_", "wall_time", "fallbacks")
_PAIR_ON = ["scenario", "seed", "overrides", "replan_period", "time_limit"]


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


def _group_table(df, by: list[str], metrics: list[str]):
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


def _scheduler_order(results: Any, df) -> list[str]:
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


def _paired(df, metric: str):
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


def _cell(v: Any, d: int = 1) -> str:
    if isinstance(v, float):
        return "nan" if v != v else f"{v:.{d}f}"
    return str(v)


def _ci_cells(table, label_cols: list[str], metrics: list[str]) -> tuple[list[str], list[list]]:
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
# plots


def _colors(names: list[str]) -> dict[str, Any]:
    plt = require("matplotlib.pyplot", "plot")
    cmap = plt.get_cmap("tab10")
    return {n: cmap(i % 10) for i, n in enumerate(names)}


def _plot_distribution(ok, names, metric, path: Path, colors) -> None:
    plt = require("matplotlib.pyplot", "plot")
    fig, ax = plt.subplots(figsize=(max(5.0, 1.1 * len(names) + 2), 4.2), layout="constrained")
    data = [ok.loc[ok["scheduler"] == n, metric].to_numpy(float) for n in names]
    ax.boxplot(data, showfliers=False, widths=0.55, medianprops={"color": "black"})
    rng = np.random.default_rng(0)
    for i, (n, y) in enumerate(zip(names, data, strict=True)):
        x = i + 1 + rng.uniform(-0.18, 0.18, y.size)
        ax.scatter(x, y, s=14, alpha=0.6, color=colors[n], zorder=3)
    ax.set_xticks(range(1, len(names) + 1), names, rotation=20 if len(names) > 4 else 0)
    ax.set_ylabel(METRICS.get(metric, (metric,))[0])
    ax.set_title(f"{METRICS.get(metric, (metric,))[0]} per episode, by scheduler")
    ax.grid(axis="y", alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_grouped(table, group_col, groups, names, metric, path: Path, colors, title) -> None:
    """Means with CI bars: one cluster per group, one bar per scheduler."""
    plt = require("matplotlib.pyplot", "plot")
    width = 0.8 / max(len(names), 1)
    fig, ax = plt.subplots(
        figsize=(min(max(5.0, 0.55 * len(groups) * max(1, len(names)) / 2 + 3), 16), 4.4),
        layout="constrained",
    )
    x = np.arange(len(groups))
    for j, n in enumerate(names):
        sub = table[table["scheduler"] == n].set_index(group_col)
        mean = np.array([sub[metric].get(g, np.nan) for g in groups], float)
        ci = np.array([sub[f"{metric} ci"].get(g, np.nan) for g in groups], float)
        ax.bar(
            x - 0.4 + width * (j + 0.5),
            mean,
            width,
            yerr=np.nan_to_num(ci),
            capsize=2,
            color=colors[n],
            label=n,
        )
    ax.set_xticks(x, groups, rotation=45 if len(groups) > 8 else 0)
    ax.set_ylabel(f"{METRICS.get(metric, (metric,))[0]} (mean ± 95% CI)")
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0), title="scheduler")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_solve_time(df, names, path: Path, colors) -> None:
    plt = require("matplotlib.pyplot", "plot")
    ok = df[df["status"] == "ok"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    for n in names:
        sub = ok[ok["scheduler"] == n]
        if "replan_tasks" in sub and len(sub):
            tasks = np.concatenate([np.asarray(v, float) for v in sub["replan_tasks"]])
            ms = np.concatenate([np.asarray(v, float) for v in sub["replan_solve_ms"]])
            keep = (tasks >= 0) & (ms > 0)
            ax1.scatter(tasks[keep], ms[keep], s=5, alpha=0.25, color=colors[n], label=n)
        x = sub["n_agents"].to_numpy(float) if "n_agents" in sub else np.zeros(0)
        y = sub["solve_p50_ms"].to_numpy(float) if len(sub) else np.zeros(0)
        if x.size:
            xs = np.unique(x)
            med = [np.median(y[x == v]) for v in xs]
            jitter = np.random.default_rng(0).uniform(-0.12, 0.12, x.size)
            ax2.scatter(x + jitter, y, s=10, alpha=0.4, color=colors[n])
            ax2.plot(xs, med, "-o", color=colors[n], label=n, ms=4)
    ax1.set_xlabel("task-graph nodes at the replan")
    ax1.set_ylabel("scheduler call (ms)")
    ax1.set_yscale("log")
    ax1.set_title("time per replan vs problem size")
    ax2.set_xlabel("team size (agents)")
    ax2.set_ylabel("median scheduler call per episode (ms)")
    ax2.set_yscale("log")
    ax2.set_title("per episode vs team size (line: median)")
    from matplotlib.ticker import MaxNLocator

    ax2.xaxis.set_major_locator(MaxNLocator(integer=True))
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3, which="both")
        if ax.get_legend_handles_labels()[0]:
            leg = ax.legend(fontsize="small", markerscale=2)
            for h in leg.legend_handles:
                h.set_alpha(1)
    if not ax1.collections:
        ax1.text(0.5, 0.5, "no task-graph sizes recorded", ha="center", transform=ax1.transAxes)
    fig.savefig(path, dpi=110)
    plt.close(fig)


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
    pd = require("pandas", "parquet")
    df = load_results(results)
    if df.empty:
        raise FcplanError(f"{results}: no episodes stored yet (run fcplan sweep first)")
    metrics = [m for m in METRICS if m in df.columns]
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
    names = _scheduler_order(results, df)
    df = df.assign(_o=df["scheduler"].map({n: i for i, n in enumerate(names)}))
    df = df.sort_values(["_o", "scenario", "seed"], kind="stable").drop(columns="_o")
    diffs = sorted(
        df["difficulty"].dropna().unique(),
        key=lambda d: (_DIFFICULTY.index(d) if d in _DIFFICULTY else 9, d),
    )
    scenarios = sorted(df["scenario"].unique(), key=_scenario_order)
    ok = df[df["status"] == "ok"]

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
    paired = _paired(df, metric)

    out_dir = Path(out) if out is not None else Path(results) / "report"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FcplanError(f"{out_dir}: cannot create the report folder: {exc}") from None
    files: list[Path] = []
    images: list[tuple[str, Path]] = []
    if plots and len(ok):
        mpl = require("matplotlib", "plot")
        if "matplotlib.pyplot" not in sys.modules:
            mpl.use("Agg")  # files only; a notebook keeps its own backend
        colors = _colors(names)
        mlabel = METRICS.get(metric, (metric,))[0]
        p = out_dir / "score_distribution.png"
        _plot_distribution(ok, names, metric, p, colors)
        images.append((f"{mlabel} per episode", p))
        p = out_dir / "score_by_difficulty.png"
        diff_table = _group_table(df, ["difficulty", "scheduler"], [metric])
        _plot_grouped(
            diff_table,
            "difficulty",
            diffs,
            names,
            metric,
            p,
            colors,
            f"{mlabel} by difficulty group",
        )
        images.append((f"{mlabel} by difficulty", p))
        p = out_dir / "score_per_scenario.png"
        scen_table = _group_table(df, ["scenario", "scheduler"], [metric])
        _plot_grouped(
            scen_table, "scenario", scenarios, names, metric, p, colors, f"{mlabel} per scenario"
        )
        images.append((f"{mlabel} per scenario", p))
        p = out_dir / "solve_time_vs_size.png"
        _plot_solve_time(df, names, p, colors)
        images.append(("solve time vs problem size", p))
        files += [p for _, p in images]

    # ---- sections (Markdown and HTML from the same content) ----
    n_ok = len(ok)
    sweeps = sorted(df["config_hash"].dropna().unique()) if "config_hash" in df else []
    intro = (
        f"{len(df)} episodes ({n_ok} completed, {len(df) - n_ok} failed) from "
        f"{len(sweeps)} sweep(s): {len(names)} scheduler(s) x {len(scenarios)} scenario(s) x "
        f"{df['seed'].nunique()} seed(s). Cells are mean ± 95% CI half-width (Student t) over "
        "completed episodes; ± nan means fewer than two. Scores are the manual's unless marked "
        "ref2020."
    )
    sections: list[tuple[str, Any]] = [("h1", "fcplan sweep report"), ("p", intro)]
    sections += [("h2", "Per scheduler"), ("table", _ci_cells(per_sched, ["scheduler"], metrics))]
    sections += [
        ("h2", "Per difficulty group"),
        ("table", _ci_cells(per_diff, ["difficulty", "scheduler"], metrics)),
    ]
    if "per_setting" in tables:
        sections += [
            ("h2", "Per setting"),
            ("table", _ci_cells(tables["per_setting"], ["scheduler", *setting_cols], metrics)),
        ]
    mlabel = METRICS.get(metric, (metric,))[0]
    sections += [
        ("h2", f"Paired comparisons ({mlabel})"),
        (
            "p",
            "Episodes paired on (scenario, seed, overrides, replan period, time limit); "
            "difference = a - b; p: two-sided Wilcoxon signed-rank test.",
        ),
        (
            "table",
            (
                ["a", "b", "pairs", "a - b", "a wins/ties/losses", "p (Wilcoxon)", "verdict"],
                [
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
                ],
            ),
        ),
    ]
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
    for title, p in images:
        sections += [("img", (title, p))]

    md_parts = []
    html_parts = []
    for kind, content in sections:
        if kind == "h1":
            md_parts.append(f"# {content}")
            html_parts.append(f"<h1>{_html.escape(content)}</h1>")
        elif kind == "h2":
            md_parts.append(f"## {content}")
            html_parts.append(f"<h2>{_html.escape(content)}</h2>")
        elif kind == "p":
            md_parts.append(content)
            html_parts.append(f"<p>{_html.escape(content)}</p>")
        elif kind == "table":
            md_parts.append(_md_table(*content))
            html_parts.append(_html_table(*content))
        elif kind == "img":
            title, p = content
            md_parts.append(f"![{title}]({p.name})")
            data = base64.b64encode(p.read_bytes()).decode()
            html_parts.append(
                f"<h3>{_html.escape(title)}</h3><img alt='{_html.escape(title)}' "
                f"src='data:image/png;base64,{data}'>"
            )
    markdown = "\n\n".join(md_parts) + "\n"
    files.insert(0, out_dir / "report.md")
    (out_dir / "report.md").write_text(markdown, encoding="utf-8")
    for name, t in (("per_scheduler", per_sched), ("per_difficulty", per_diff), ("paired", paired)):
        t.to_csv(out_dir / f"{name}.csv", index=False)
        files.append(out_dir / f"{name}.csv")
    if html:
        style = (
            "body{font-family:sans-serif;max-width:1200px;margin:2em auto}"
            "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;"
            "padding:3px 6px;text-align:right}img{max-width:100%}"
        )
        doc = (
            f"<!doctype html><html><head><meta charset='utf-8'><title>fcplan report</title>"
            f"<style>{style}</style></head><body>{''.join(html_parts)}</body></html>\n"
        )
        (out_dir / "report.html").write_text(doc, encoding="utf-8")
        files.append(out_dir / "report.html")
    return Report(markdown=markdown, tables=tables, paired=paired, files=files)


def _verdict(r: Any) -> str:
    """Which scheduler is better at the 5 % level (lower is better for penalties and times)."""
    if r.pairs == 0 or r.p_wilcoxon != r.p_wilcoxon:
        return "-"
    if r.p_wilcoxon >= 0.05 or r.mean_diff == 0:
        return "no significant difference"
    lower_better = any(k in r.metric for k in _LOWER_IS_BETTER)
    return f"{r.a} better" if (r.mean_diff > 0) != lower_better else f"{r.b} better"
