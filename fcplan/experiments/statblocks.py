"""The statistics of a study as titled tables of cells, shared by compare's text and the report.

:func:`blocks` turns a :class:`~fcplan.experiments.analysis.StudyStats` into :class:`Block` s (a
title, a note saying what the numbers are, and a header row plus rows of text cells);
:meth:`fcplan.experiments.ComparisonResult.format` prints them with :func:`fixed_width`, and
:func:`fcplan.experiments.report` writes them as Markdown and HTML tables. The cells of a paired
comparison read ``a - b [low, high]`` (the metric's decimals plus one), Cohen's ``d_z``, ``a``'s
wins/ties/losses, the Wilcoxon and Holm p-values (``<1e-4`` below 1e-4, ``-`` when undefined) and
the verdict in words.

Examples
--------
>>> from fcplan.experiments.analysis import study_stats
>>> rows = [{"scheduler": s, "seed": k, "manual.final_score": v + k % 3}
...         for k in range(6) for s, v in (("a", 250.0), ("b", 240.0))]
>>> st = study_stats(rows, ["a", "b"], ["manual.final_score"], lambda r: r["seed"])
>>> [b.title for b in blocks(st)]
['Paired differences: final score', 'Ranking per metric']
>>> print(fixed_width(*blocks(st)[0].cells))
a  b  n  a - b [95% CI]           d_z  W/T/L  p      Holm p  verdict
a  b  6  +10.00 [+10.00, +10.00]  nan  6/0/0  0.031  0.031   a better
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fcplan.experiments.analysis import (
    MetricRanking,
    OracleFraction,
    StudyStats,
    metric_label,
)
from fcplan.experiments.stats import PairedComparison
from fcplan.experiments.tables import REPORT_COLUMNS

__all__ = [
    "Block",
    "Cells",
    "blocks",
    "fixed_width",
    "fraction_cells",
    "paired_cells",
    "ranking_cells",
]

Cells = tuple[list[str], list[list[str]]]
"""A header row and body rows of text cells."""


@dataclass(frozen=True)
class Block:
    """One titled table of a study's statistics (rendered as text, Markdown or HTML)."""

    title: str
    note: str
    cells: Cells


def _decimals(metric: str) -> int:
    """Decimals of a difference of ``metric``: one more than its table cells."""
    for col in REPORT_COLUMNS:
        if col.name == metric:
            return col.decimals + 1
    return 2


def _p(p: float) -> str:
    if p != p:
        return "-"
    return f"{p:.2g}" if p >= 1e-4 else "<1e-4"


def _num(x: float, d: int, sign: bool = False) -> str:
    if x != x:
        return "nan"
    return f"{x:+.{d}f}" if sign else f"{x:.{d}f}"


def paired_cells(comparisons: Sequence[PairedComparison]) -> Cells:
    """Header and rows of a paired table: a, b, n, ``a - b [low, high]``, d_z, wins/ties/losses,
    p, Holm p, verdict."""
    head = ["a", "b", "n", "a - b [95% CI]", "d_z", "W/T/L", "p", "Holm p", "verdict"]
    body = []
    for c in comparisons:
        d = _decimals(c.metric)
        ci = (
            f"{_num(c.diff.mean, d, True)} [{_num(c.diff.low, d, True)}, "
            f"{_num(c.diff.high, d, True)}]"
        )
        body.append(
            [
                c.a,
                c.b,
                str(c.n),
                ci,
                _num(c.effect, 2, True),
                f"{c.wins}/{c.ties}/{c.losses}",
                _p(c.p),
                _p(c.p_holm),
                c.verdict(),
            ]
        )
    return head, body


def fraction_cells(fractions: Sequence[OracleFraction]) -> Cells:
    """Header and rows of the fraction-of-oracle table."""
    head = ["scheduler", "n", "fraction [95% CI]", "median pair", "better than reference"]
    body = [
        [
            f.scheduler,
            str(f.n),
            f"{_num(f.fraction, 3)} [{_num(f.low, 3)}, {_num(f.high, 3)}]",
            _num(f.median_pair, 3),
            str(f.above),
        ]
        for f in fractions
    ]
    return head, body


def ranking_cells(rankings: Sequence[MetricRanking]) -> Cells:
    """Header and rows of the ranking table: one row per metric."""
    head = ["metric", "ranking (best first)", "pairs differing", "median |d_z|", "Friedman p", "W"]
    body = [
        [
            r.label,
            r.chain(),
            f"{r.significant}/{len(r.pairs)}",
            _num(r.median_abs_effect, 2),
            _p(r.friedman.p),
            _num(r.friedman.w, 2),
        ]
        for r in rankings
    ]
    return head, body


def fixed_width(head: list[str], body: list[list[str]], indent: str = "") -> str:
    """A plain-text table: columns padded to their widest cell, the last one left ragged.

    Examples
    --------
    >>> print(fixed_width(["a", "bb"], [["xyz", "1"]]))
    a    bb
    xyz  1
    """
    widths = [max(len(row[k]) for row in [head, *body]) for k in range(len(head))]
    lines = [
        indent + "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip()
        for row in [head, *body]
    ]
    return "\n".join(lines)


def blocks(study: StudyStats) -> list[Block]:
    """The tables of ``study`` in display order: paired per metric, fraction of the oracle,
    rankings."""
    pct = f"{100 * study.confidence:g}%"
    out = []
    for metric, pairs in study.paired.items():
        if not pairs:
            continue
        note = (
            f"Pairs of episodes on the same instance; a - b with its {pct} Student-t "
            f"interval, Cohen's d_z, a's wins/ties/losses, the two-sided Wilcoxon "
            f"signed-rank p and its Holm adjustment over the {len(pairs)} pair(s)."
        )
        if study.oracle is not None:
            note += f" The {study.oracle} reference is not among the compared pairs."
        out.append(Block(f"Paired differences: {metric_label(metric)}", note, paired_cells(pairs)))
    if study.fractions:
        metric, base = study.fractions[0].metric, study.fractions[0].baseline
        share = (
            f"sum (x - {base}) / sum (reference - {base}): the share of the reference's "
            f"improvement over the {base} team"
            if base
            else "sum x / sum reference (no idle team in the study: meaningful only for "
            "positive scores; add idle for the leaderboard's fraction)"
        )
        note = (
            f"{metric_label(metric)}: {share}, over the instances all completed, with a {pct} "
            f"bootstrap interval (seeds resampled within each scenario) and the median of the "
            f"per-instance ratios. The reference ({study.oracle}) sees the true fire: not a "
            "policy, nor a bound."
        )
        out.append(Block(f"Fraction of {study.oracle}", note, fraction_cells(study.fractions)))
    if study.rankings and len(study.policies) > 1:
        note = (
            "Schedulers by mean, best first; '>' where neighbours differ (interval excludes "
            "0 and Holm p < 0.05 within the metric), '≈' where they do not; Friedman's test "
            "and Kendall's W over the instances every scheduler completed. " + study.separation()
        )
        out.append(Block("Ranking per metric", note, ranking_cells(study.rankings)))
    return out
