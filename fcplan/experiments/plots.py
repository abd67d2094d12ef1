"""The sweep report's plots (matplotlib, drawn into PNG files).

Each function draws one figure from tables the report has already computed
(:mod:`fcplan.experiments.report`) and saves it at ``path``; schedulers keep one colour across
figures (:func:`scheduler_colors`). Only the report imports this module, and only when it draws plots, so
matplotlib stays optional (``fcplan[plot]``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from fcplan.experiments.optional import require

__all__ = ["scheduler_colors", "plot_distribution", "plot_grouped", "plot_solve_time"]


def scheduler_colors(names: list[str]) -> dict[str, Any]:
    """A tab10 colour per scheduler name, in order."""
    plt = require("matplotlib.pyplot", "plot")
    cmap = plt.get_cmap("tab10")
    return {n: cmap(i % 10) for i, n in enumerate(names)}


def plot_distribution(
    ok: Any, names: list[str], metric: str, label: str, path: Path, colors: dict[str, Any]
) -> None:
    """Box plot and every completed episode's ``metric``, per scheduler."""
    plt = require("matplotlib.pyplot", "plot")
    fig, ax = plt.subplots(figsize=(max(5.0, 1.1 * len(names) + 2), 4.2), layout="constrained")
    data = [ok.loc[ok["scheduler"] == n, metric].to_numpy(float) for n in names]
    ax.boxplot(data, showfliers=False, widths=0.55, medianprops={"color": "black"})
    rng = np.random.default_rng(0)
    for i, (n, y) in enumerate(zip(names, data, strict=True)):
        x = i + 1 + rng.uniform(-0.18, 0.18, y.size)
        ax.scatter(x, y, s=14, alpha=0.6, color=colors[n], zorder=3)
    ax.set_xticks(range(1, len(names) + 1), names, rotation=20 if len(names) > 4 else 0)
    ax.set_ylabel(label)
    ax.set_title(f"{label} per episode, by scheduler")
    ax.grid(axis="y", alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_grouped(
    table: Any,
    group_col: str,
    groups: list[Any],
    names: list[str],
    metric: str,
    label: str,
    path: Path,
    colors: dict[str, Any],
    title: str,
) -> None:
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
    ax.set_ylabel(f"{label} (mean ± 95% CI)")
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0), title="scheduler")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_solve_time(df: Any, names: list[str], path: Path, colors: dict[str, Any]) -> None:
    """Time per scheduler call against task-graph size (every replan), and the median per
    episode against team size."""
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
