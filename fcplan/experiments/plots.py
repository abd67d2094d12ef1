"""The sweep report's plots (matplotlib), each saved as PNG and PDF.

Each function draws one figure from the episodes and tables the report has already computed
(:mod:`fcplan.experiments.report`) and saves it at ``path`` (PNG, 150 dpi) and next to it as
vector PDF (:func:`save`), for a paper; schedulers keep one colour across figures
(:func:`scheduler_colors`). Only the report imports this module, and only when it draws plots,
so matplotlib stays optional (``fcplan[plot]``).

Readable for small samples:

* every episode is drawn as a point, next to the mean and its 95 % t-interval (dot and
  whisker, not bars: a bar's baseline at 0 means nothing for a score that may be negative);
* the y axis spans the episodes' values (and every interval that fits within three times that
  span); an interval reaching beyond is cut at the axis, drawn with an open arrowhead, and its
  half-width is written next to it (``±1320 (n=2)``): with two episodes the t quantile is 12.7,
  and such an interval would otherwise squash every other mark;
* the legend sits in one row under the axes, not beside them;
* :func:`plot_solve_time` skips a scheduler with no recorded task-graph size (its plans carry no
  ``SolveStats.size``) and says so in the legend.

Examples
--------
>>> clip_interval(10.0, 500.0, (0.0, 40.0))
(0.0, 40.0, True, True)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from fcplan.experiments.optional import require

__all__ = [
    "clip_interval",
    "plot_distribution",
    "plot_grouped",
    "plot_solve_time",
    "save",
    "scheduler_colors",
    "value_limits",
]


def scheduler_colors(names: list[str]) -> dict[str, Any]:
    """A tab10 colour per scheduler name, in order."""
    plt = require("matplotlib.pyplot", "plot")
    cmap = plt.get_cmap("tab10")
    return {n: cmap(i % 10) for i, n in enumerate(names)}


def save(fig: Any, path: Path) -> list[Path]:
    """Save ``fig`` at ``path`` (PNG) and as PDF beside it; close it; return both paths."""
    plt = require("matplotlib.pyplot", "plot")
    pdf = Path(path).with_suffix(".pdf")
    fig.savefig(path, dpi=150)
    fig.savefig(pdf, metadata={"CreationDate": None})  # no timestamp: reproducible files
    plt.close(fig)
    return [Path(path), pdf]


def value_limits(
    values: np.ndarray, means: np.ndarray, cis: np.ndarray, pad: float = 0.08
) -> tuple[float, float]:
    """The y range of a plot: the episodes' values and the means, widened by every interval that
    stays within three times that span, plus ``pad`` of the span on each side."""
    v = np.concatenate([np.ravel(values), np.ravel(means)]).astype(float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return (0.0, 1.0)
    lo, hi = float(v.min()), float(v.max())
    span = max(hi - lo, abs(hi) * 0.1, 1e-9)
    ok = np.isfinite(means) & np.isfinite(cis) & (cis <= 1.5 * span)
    if ok.any():
        lo = min(lo, float((means[ok] - cis[ok]).min()))
        hi = max(hi, float((means[ok] + cis[ok]).max()))
    span = max(hi - lo, 1e-9)
    return (lo - pad * span, hi + pad * span)


def clip_interval(
    mean: float, half: float, limits: tuple[float, float]
) -> tuple[float, float, bool, bool]:
    """The interval ``mean ± half`` cut to ``limits``: (low, high, cut low, cut high)."""
    lo, hi = mean - half, mean + half
    return (max(lo, limits[0]), min(hi, limits[1]), lo < limits[0], hi > limits[1])


def _legend_below(
    fig: Any, ax: Any, title: str | None = None, extra: list[Any] | None = None
) -> None:
    """One row of legend entries under the axes."""
    handles, labels = ax.get_legend_handles_labels()
    handles += extra or []
    labels += [h.get_label() for h in extra or []]
    if handles:
        fig.legend(
            handles,
            labels,
            loc="outside lower center",
            ncol=min(len(handles), 5),
            fontsize="small",
            title=title,
            frameon=False,
        )


def plot_distribution(
    ok: Any, names: list[str], metric: str, label: str, path: Path, colors: dict[str, Any]
) -> list[Path]:
    """Box plot and every completed episode's ``metric``, per scheduler (n under each name)."""
    plt = require("matplotlib.pyplot", "plot")
    fig, ax = plt.subplots(figsize=(max(5.0, 1.1 * len(names) + 2), 4.2), layout="constrained")
    data = [ok.loc[ok["scheduler"] == n, metric].to_numpy(float) for n in names]
    ax.boxplot(data, showfliers=False, widths=0.55, medianprops={"color": "black"})
    rng = np.random.default_rng(0)
    for i, (n, y) in enumerate(zip(names, data, strict=True)):
        x = i + 1 + rng.uniform(-0.18, 0.18, y.size)
        ax.scatter(x, y, s=16, alpha=0.7, color=colors[n], zorder=3, edgecolors="none")
    ticks = [f"{n}\n(n={len(y)})" for n, y in zip(names, data, strict=True)]
    ax.set_xticks(range(1, len(names) + 1), ticks, rotation=20 if len(names) > 4 else 0)
    ax.set_ylabel(label)
    ax.set_title(f"{label} per episode, by scheduler")
    ax.grid(axis="y", alpha=0.3)
    return save(fig, path)


def plot_grouped(
    ok: Any,
    table: Any,
    group_col: str,
    groups: list[Any],
    names: list[str],
    metric: str,
    label: str,
    path: Path,
    colors: dict[str, Any],
    title: str,
) -> list[Path]:
    """Every episode (points) and the mean with its 95 % interval (dot and whisker), one cluster
    per group and one column per scheduler; intervals beyond the episodes' range are cut and
    annotated (see the module docstring)."""
    plt = require("matplotlib.pyplot", "plot")
    from matplotlib.lines import Line2D

    k = max(len(names), 1)
    width = 0.8 / k
    fig, ax = plt.subplots(
        figsize=(min(max(5.5, 0.5 * len(groups) * k + 2.5), 16), 4.6), layout="constrained"
    )
    x = np.arange(len(groups))
    cells = []
    for n in names:
        sub = table[table["scheduler"] == n].set_index(group_col)
        mean = np.array([sub[metric].get(g, np.nan) for g in groups], float)
        ci = np.array([sub[f"{metric} ci"].get(g, np.nan) for g in groups], float)
        cells.append((mean, ci))
    limits = value_limits(
        ok[metric].to_numpy(float),
        np.concatenate([m for m, _ in cells]) if cells else np.zeros(0),
        np.concatenate([c for _, c in cells]) if cells else np.zeros(0),
    )
    rng = np.random.default_rng(0)
    cut_any = False
    for j, (n, (mean, ci)) in enumerate(zip(names, cells, strict=True)):
        xs = x - 0.4 + width * (j + 0.5)
        for gi, g in enumerate(groups):
            y = ok.loc[(ok["scheduler"] == n) & (ok[group_col] == g), metric].to_numpy(float)
            jit = rng.uniform(-0.25, 0.25, y.size) * width
            ax.scatter(xs[gi] + jit, y, s=12, alpha=0.45, color=colors[n], edgecolors="none")
            if not np.isfinite(mean[gi]):
                continue
            half = ci[gi] if np.isfinite(ci[gi]) else 0.0
            lo, hi, cut_lo, cut_hi = clip_interval(mean[gi], half, limits)
            ax.plot([xs[gi]] * 2, [lo, hi], color=colors[n], lw=1.6, solid_capstyle="butt")
            for cut, end, mk in ((cut_lo, lo, "v"), (cut_hi, hi, "^")):
                if cut:
                    cut_any = True
                    ax.plot(xs[gi], end, marker=mk, ms=6, mfc="white", color=colors[n])
            if cut_lo or cut_hi:
                ax.annotate(
                    f"±{half:,.0f}\n(n={y.size})" if half >= 100 else f"±{half:.3g}\n(n={y.size})",
                    (xs[gi], hi if cut_hi else lo),
                    xytext=(3, -14 if cut_hi else 4),
                    textcoords="offset points",
                    fontsize=6.5,
                    color="0.25",
                )
        ax.plot(xs, mean, "o", ms=6, color=colors[n], mec="black", mew=0.6, label=n, ls="none")
    ax.set_ylim(*limits)
    ax.set_xticks(x, [str(g) for g in groups], rotation=45 if len(groups) > 8 else 0)
    ax.set_xlim(-0.5, len(groups) - 0.5)
    ax.set_ylabel(f"{label}\n(points: episodes; dot: mean ± 95% CI)")
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    extra = []
    if cut_any:
        extra.append(
            Line2D([], [], marker="^", ls="none", mfc="white", color="0.3",
                   label="CI cut at the axis (half-width written)")
        )  # fmt: skip
    _legend_below(fig, ax, extra=extra)
    return save(fig, path)


def plot_solve_time(df: Any, names: list[str], path: Path, colors: dict[str, Any]) -> list[Path]:
    """Time per scheduler call against task-graph size (every replan), and the median per
    episode against team size. Schedulers whose replans carry no size are left out of the left
    panel and named in its legend."""
    plt = require("matplotlib.pyplot", "plot")
    from matplotlib.lines import Line2D
    from matplotlib.ticker import MaxNLocator

    ok = df[df["status"] == "ok"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.4), layout="constrained")
    unsized = []
    for n in names:
        sub = ok[ok["scheduler"] == n]
        if "replan_tasks" in sub and len(sub):
            tasks = np.concatenate([np.asarray(v, float) for v in sub["replan_tasks"]])
            ms = np.concatenate([np.asarray(v, float) for v in sub["replan_solve_ms"]])
            keep = (tasks >= 0) & (ms > 0)
            if keep.any():
                ax1.scatter(tasks[keep], ms[keep], s=6, alpha=0.3, color=colors[n], label=n)
            else:
                unsized.append(n)
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
    ax2.xaxis.set_major_locator(MaxNLocator(integer=True))
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3, which="both")
    extra = [Line2D([], [], ls="none", label=f"{', '.join(unsized)}: no size recorded, not drawn")]
    handles, labels = ax1.get_legend_handles_labels()
    if unsized:
        handles, labels = handles + extra, labels + [extra[0].get_label()]
    if handles:
        leg = ax1.legend(handles, labels, fontsize="small", markerscale=2)
        for h in leg.legend_handles:
            if h is not None:
                h.set_alpha(1)
    if ax2.get_legend_handles_labels()[0]:
        ax2.legend(fontsize="small")
    if not ax1.collections:
        ax1.text(0.5, 0.5, "no task-graph sizes recorded", ha="center", transform=ax1.transAxes)
    return save(fig, path)
