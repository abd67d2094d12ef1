"""The statistics of a study, shared by ``compare`` and ``report``: paired differences, the fraction
of the oracle, and a ranking per metric that says which metric separates the schedulers.

Every function here takes the completed episodes of a study as rows (mappings with a
``scheduler`` label and metric columns such as ``manual.final_score``) and a *pair key*: the
function of a row that names the (scenario, seed) instance it played, so that two schedulers are
compared on the instances both completed. :func:`fcplan.experiments.compare` pairs on (scenario,
seed); :func:`fcplan.experiments.report` on (study, scenario, seed, overrides, replan period, time
limit).

* :func:`paired_table`: every pair of schedulers on one metric: the mean paired difference
  ``a - b`` with its 95 % Student-t interval, Cohen's ``d_z``, wins/ties/losses, the two-sided
  Wilcoxon signed-rank p-value and its Holm adjustment over the family of pairs, and a verdict in
  words (:meth:`~fcplan.experiments.stats.PairedComparison.verdict`, e.g. ``"unresolved at
  n=5 (~40 pairs for 80% power at d_z=+0.45)"`` when the interval is too wide to tell).
* :func:`oracle_fractions`: each scheduler's metric as a fraction of the clairvoyant ``oracle``'s
  on the same instance (the number a paper quotes), the mean over instances of
  ``x_i / oracle_i`` with its interval, and the ratio of the means. A fraction is only defined
  where the oracle's value is positive; instances where it is not are counted, not used.
* :func:`metric_rankings`: per metric of :data:`~fcplan.experiments.tables.RANKING_COLUMNS` (the
  manual's final score and NRR, time to containment, contained, burned area, facility damage),
  the schedulers ordered by mean, the pairs that differ (interval excludes 0 and Holm-adjusted
  p < 0.05, Holm within each metric's family), the median ``|d_z|``, and Friedman's test with
  Kendall's ``W`` over the instances every scheduler completed. :func:`separation` says in one
  sentence which metric separates the schedulers best.

The ``oracle`` (any scheduler whose registered name is ``oracle``) sees the true fire: it is a
reference, not a policy, so it is left out of the pairs, the Holm families and the rankings, and
appears only as the denominator of the fractions.

Examples
--------
>>> rows = [{"scheduler": s, "seed": k, "score": v}
...         for s, vals in {"a": [10, 12, 11, 13, 12, 14], "b": [8, 9, 9, 10, 9, 11]}.items()
...         for k, v in enumerate(vals)]
>>> (c,) = paired_table(rows, ["a", "b"], "score", lambda r: r["seed"])
>>> c.diff.mean, c.wins, c.verdict()
(2.6666666666666665, 6, 'a better')
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan.experiments.stats import (
    Friedman,
    MeanCI,
    PairedComparison,
    friedman,
    mean_ci,
    paired_comparisons,
)
from fcplan.experiments.tables import RANKING_COLUMNS, REPORT_COLUMNS, higher_is_better

__all__ = [
    "MetricRanking",
    "OracleFraction",
    "PairKey",
    "RANKING_METRICS",
    "fixed_width",
    "fraction_cells",
    "metric_label",
    "metric_rankings",
    "oracle_fractions",
    "paired_cells",
    "paired_scores",
    "paired_table",
    "ranking_cells",
    "separation",
]

PairKey = Callable[[Mapping[str, Any]], Hashable]
"""The instance an episode row played (rows of two schedulers with equal keys are a pair)."""

Rows = Sequence[Mapping[str, Any]]


def metric_label(metric: str) -> str:
    """The table header of a result column (its own name when it is not tabulated).

    Examples
    --------
    >>> metric_label("manual.final_score"), metric_label("outcome.burned_area_cells")
    ('final score', 'burned')
    """
    for col in REPORT_COLUMNS:
        if col.name == metric:
            return col.label
    return metric


def _decimals(metric: str) -> int:
    for col in REPORT_COLUMNS:
        if col.name == metric:
            return col.decimals + 1
    return 2


def paired_scores(
    rows: Rows, schedulers: Sequence[str], metric: str, pair_key: PairKey
) -> dict[str, dict[Hashable, float]]:
    """Per scheduler, ``{pair key: metric value}`` of its rows (a later row with the same key
    replaces an earlier one; missing values are NaN)."""
    out: dict[str, dict[Hashable, float]] = {s: {} for s in schedulers}
    for r in rows:
        if r["scheduler"] in out:
            v = r.get(metric)
            out[r["scheduler"]][pair_key(r)] = math.nan if v is None else float(v)
    return out


def paired_table(
    rows: Rows,
    schedulers: Sequence[str],
    metric: str,
    pair_key: PairKey,
    *,
    confidence: float = 0.95,
    alpha: float = 0.05,
) -> list[PairedComparison]:
    """Every pair of ``schedulers`` on ``metric`` (see the module docstring); Holm over them."""
    scores = paired_scores(rows, schedulers, metric, pair_key)
    return paired_comparisons(
        scores, confidence, metric=metric, higher_is_better=higher_is_better(metric), alpha=alpha
    )


# --------------------------------------------------------------------------------------------
# fraction of the oracle


@dataclass(frozen=True)
class OracleFraction:
    """One scheduler's metric as a fraction of the oracle's on the same instances.

    Attributes
    ----------
    scheduler, oracle, metric : str
    fraction : MeanCI
        Mean and 95 % interval over instances of ``x_i / oracle_i`` (instances where the
        oracle's value is positive).
    ratio_of_means : float
        ``mean(x_i) / mean(oracle_i)`` over the same instances.
    excluded : int
        Instances left out because the oracle's value was 0 or negative (no fraction).
    above : int
        Instances where the scheduler's value was better than the oracle's (the oracle is a
        reference, not a bound).
    """

    scheduler: str
    oracle: str
    metric: str
    fraction: MeanCI
    ratio_of_means: float
    excluded: int
    above: int


def oracle_fractions(
    rows: Rows, schedulers: Sequence[str], oracle: str, metric: str, pair_key: PairKey
) -> list[OracleFraction]:
    """:class:`OracleFraction` of every scheduler but ``oracle`` (see the module docstring).

    Examples
    --------
    >>> rows = [{"scheduler": s, "seed": k, "x": v} for s, vals in
    ...         {"oracle": [100.0, 200.0, -5.0], "g": [90.0, 150.0, -20.0]}.items()
    ...         for k, v in enumerate(vals)]
    >>> (f,) = oracle_fractions(rows, ["oracle", "g"], "oracle", "x", lambda r: r["seed"])
    >>> round(f.fraction.mean, 3), round(f.ratio_of_means, 3), f.excluded, f.fraction.n
    (0.825, 0.8, 1, 2)
    """
    scores = paired_scores(rows, schedulers, metric, pair_key)
    ref = scores[oracle]
    higher = higher_is_better(metric)
    out = []
    for name in schedulers:
        if name == oracle:
            continue
        common = [k for k in scores[name] if k in ref]
        x = np.array([scores[name][k] for k in common], np.float64)
        o = np.array([ref[k] for k in common], np.float64)
        ok = o > 0
        ratio = float(x[ok].mean() / o[ok].mean()) if ok.any() else math.nan
        above = int((x > o).sum() if higher else (x < o).sum())
        out.append(
            OracleFraction(
                name, oracle, metric, mean_ci(x[ok] / o[ok]), ratio, int((~ok).sum()), above
            )
        )
    return out


# --------------------------------------------------------------------------------------------
# rankings


@dataclass(frozen=True)
class MetricRanking:
    """The schedulers on one metric: order by mean, the pairs that differ, Friedman's test.

    Attributes
    ----------
    metric, label : str
    order : tuple of str
        Schedulers, best mean first (in the metric's direction).
    means : dict of str -> float
    pairs : tuple of PairedComparison
        Every pair (Holm within this metric).
    friedman : Friedman
        Over the instances every scheduler completed (NaN p with fewer than 3 schedulers).
    """

    metric: str
    label: str
    order: tuple[str, ...]
    means: dict[str, float]
    pairs: tuple[PairedComparison, ...]
    friedman: Friedman

    @property
    def significant(self) -> int:
        """Pairs whose interval excludes 0 with Holm-adjusted p < alpha."""
        return sum(c.significant for c in self.pairs)

    @property
    def median_abs_effect(self) -> float:
        """Median ``|d_z|`` over the pairs (NaN pairs left out)."""
        eff = [abs(c.effect) for c in self.pairs if c.effect == c.effect]
        return float(np.median(eff)) if eff else math.nan

    def _pair(self, a: str, b: str) -> PairedComparison | None:
        for c in self.pairs:
            if {c.a, c.b} == {a, b}:
                return c
        return None

    def chain(self) -> str:
        """The order as ``"a > b ≈ c"``: ``>`` where the neighbours differ significantly.

        Examples
        --------
        >>> rows = [{"scheduler": s, "seed": k, "x": v + k % 2} for k in range(8)
        ...         for s, v in (("a", 9.0), ("b", 5.0), ("c", 5.0))]
        >>> metric_rankings(rows, ["c", "b", "a"], ["x"], lambda r: r["seed"])[0].chain()
        'a > c ≈ b'
        """
        out = self.order[0] if self.order else ""
        for a, b in zip(self.order, self.order[1:], strict=False):
            c = self._pair(a, b)
            out += f" {'>' if c is not None and c.significant else '≈'} {b}"
        return out


def metric_rankings(
    rows: Rows,
    schedulers: Sequence[str],
    metrics: Sequence[str],
    pair_key: PairKey,
    *,
    alpha: float = 0.05,
) -> list[MetricRanking]:
    """A :class:`MetricRanking` per metric present in ``rows`` (see the module docstring)."""
    out = []
    for metric in metrics:
        if not any(metric in r for r in rows):
            continue
        higher = higher_is_better(metric)
        scores = paired_scores(rows, schedulers, metric, pair_key)
        means = {s: mean_ci(list(v.values())).mean for s, v in scores.items()}
        sign = -1.0 if higher else 1.0
        order = tuple(
            sorted(schedulers, key=lambda s: (math.isnan(means[s]), sign * means[s]))
        )
        pairs = paired_comparisons(scores, metric=metric, higher_is_better=higher, alpha=alpha)
        blocks = [k for k in scores[schedulers[0]] if all(k in scores[s] for s in schedulers)]
        fr = friedman([[scores[s][k] for k in blocks] for s in schedulers], higher)
        out.append(
            MetricRanking(metric, metric_label(metric), order, means, tuple(pairs), fr)
        )
    return out


def separation(rankings: Sequence[MetricRanking]) -> str:
    """One sentence: which metric separates the schedulers best (most significant pairs, then
    the largest median ``|d_z|``), and how the headline (first) metric fares.

    Examples
    --------
    >>> rows = [{"scheduler": s, "seed": k, "x": v + (k * v) % 3, "y": float(k)}
    ...         for k in range(8) for s, v in (("a", 9.0), ("b", 5.0))]
    >>> separation(metric_rankings(rows, ["a", "b"], ["y", "x"], lambda r: r["seed"]))
    'x separates the schedulers best: 1 of 1 pair(s) differ (median |d_z| 3.24); the headline y separates 0 of 1.'
    """
    ranked = [r for r in rankings if r.pairs]
    if not ranked:
        return "Fewer than two schedulers: nothing to separate."
    best = max(ranked, key=lambda r: (r.significant, _finite(r.median_abs_effect)))
    m = len(best.pairs)
    n = max(c.n for c in best.pairs)
    if best.significant == 0:
        return (
            f"No metric separates any pair of schedulers at n={n} "
            "(every interval contains 0, or the Holm-adjusted test disagrees): more seeds needed."
        )
    text = (
        f"{best.label} separates the schedulers best: {best.significant} of {m} pair(s) differ "
        f"(median |d_z| {best.median_abs_effect:.2f})"
    )
    head = ranked[0]
    if head is not best:
        text += f"; the headline {head.label} separates {head.significant} of {len(head.pairs)}"
    return text + "."


def _finite(x: float) -> float:
    return -1.0 if x != x else x


# --------------------------------------------------------------------------------------------
# cells (shared by the text, Markdown and HTML tables)

Cells = tuple[list[str], list[list[str]]]


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
    head = ["scheduler", "n", "x / oracle [95% CI]", "mean x / mean oracle", "better than oracle"]
    body = []
    for f in fractions:
        cell = f"{f.fraction.mean:.3f} [{f.fraction.low:.3f}, {f.fraction.high:.3f}]"
        n = str(f.fraction.n) + (f" (+{f.excluded} oracle <= 0)" if f.excluded else "")
        body.append([f.scheduler, n, cell, _num(f.ratio_of_means, 3), str(f.above)])
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


RANKING_METRICS: tuple[str, ...] = tuple(c.name for c in RANKING_COLUMNS)
"""Column names of :data:`~fcplan.experiments.tables.RANKING_COLUMNS`."""
