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
* :func:`oracle_fractions`: each scheduler's share of the clairvoyant reference's improvement
  over the idle team on the same instances, ``sum (x_i - idle_i) / sum (oracle_i - idle_i)``
  with a bootstrap interval (the number a paper quotes, and the leaderboard's:
  :mod:`fcplan.experiments.oracle_reference`); the reference on an instance is the best of the
  oracle variants run on it. Without the idle team in the study it is ``sum x_i / sum
  oracle_i``, meaningful only for positive scores.
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

from fcplan.experiments.oracle_reference import (
    complete_variants,
    fraction_on_pairs,
    reference_scores,
)
from fcplan.experiments.stats import (
    Friedman,
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
    "RESULTS_PAIR_ON",
    "RANKING_METRICS",
    "metric_label",
    "metric_rankings",
    "oracle_fractions",
    "paired_scores",
    "paired_table",
    "reference_label",
    "results_pair_key",
    "separation",
    "StudyStats",
    "study_stats",
]

PairKey = Callable[[Mapping[str, Any]], Hashable]
"""The instance an episode row played (rows of two schedulers with equal keys are a pair)."""

Rows = Sequence[Mapping[str, Any]]

IDLE = "idle"
"""The baseline that normalises the fraction of the oracle (the team that does nothing)."""

RANKING_METRICS: tuple[str, ...] = tuple(c.name for c in RANKING_COLUMNS)
"""Column names of :data:`~fcplan.experiments.tables.RANKING_COLUMNS`."""


RESULTS_PAIR_ON: tuple[str, ...] = (
    "study_hash",
    "scenario",
    "seed",
    "overrides",
    "replan_period",
    "time_limit",
)
"""The columns that name the instance of a sweep result row (:func:`results_pair_key`)."""


def results_pair_key(row: Mapping[str, Any]) -> tuple[Any, ...]:
    """The instance a sweep result row played: its :data:`RESULTS_PAIR_ON` values, with a
    missing or NaN value (a row written before study hashes, no time limit) read as None.

    Examples
    --------
    >>> results_pair_key({"scenario": "#3", "seed": 1, "overrides": "{}", "replan_period": 1.0,
    ...                   "time_limit": float("nan")})
    (None, '#3', 1, '{}', 1.0, None)
    """
    out = []
    for c in RESULTS_PAIR_ON:
        v = row.get(c)
        out.append(None if v is None or (isinstance(v, float) and v != v) else v)
    return tuple(out)


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
    """One scheduler's fraction of the clairvoyant reference on the same instances.

    Attributes
    ----------
    scheduler, metric : str
    oracle : str
        The reference: an oracle label, or ``"best of a, b"`` when several oracle variants ran
        (the best of them on each instance, :func:`~fcplan.experiments.oracle_reference.reference_scores`).
    baseline : str or None
        ``"idle"`` when the study ran the idle team: the fraction is then ``sum (x_i - idle_i) /
        sum (oracle_i - idle_i)``, the share of the reference's improvement over doing nothing
        (:func:`~fcplan.experiments.oracle_reference.fraction_of_oracle`, the leaderboard's
        number). None: ``sum x_i / sum oracle_i``, which means something only when every score
        is positive (NaN for a lower-is-better metric).
    fraction, low, high : float
        The fraction and its 95 % bootstrap interval (seeds resampled within each scenario).
    median_pair : float
        The median of the per-instance ratios.
    n : int
        Instances where the scheduler, the reference and the baseline all completed.
    above : int
        Instances where the scheduler did better than the reference (a reference, not a bound).
    """

    scheduler: str
    oracle: str
    metric: str
    baseline: str | None
    fraction: float
    low: float
    high: float
    median_pair: float
    n: int
    above: int


def reference_label(references: Sequence[str]) -> str:
    """How the reference of several oracle variants is named (one: its own label)."""
    return references[0] if len(references) == 1 else "best of " + ", ".join(references)


def oracle_fractions(
    rows: Rows,
    schedulers: Sequence[str],
    references: str | Sequence[str],
    metric: str,
    pair_key: PairKey,
    *,
    baseline: str = IDLE,
) -> list[OracleFraction]:
    """:class:`OracleFraction` of every scheduler but the references and the ``baseline``
    (normalised by it when it is among ``schedulers``; see :class:`OracleFraction`).

    Examples
    --------
    >>> rows = [{"scheduler": s, "seed": k, "x": v} for s, vals in
    ...         {"oracle": [100.0, 200.0], "g": [90.0, 150.0], "idle": [-50.0, 0.0]}.items()
    ...         for k, v in enumerate(vals)]
    >>> (f,) = oracle_fractions(rows, ["oracle", "g", "idle"], "oracle", "x", lambda r: r["seed"])
    >>> f.baseline, round(f.fraction, 3), f.n  # (140 + 150) / (150 + 200)
    ('idle', 0.829, 2)
    """
    refs = [references] if isinstance(references, str) else list(references)
    names = list(dict.fromkeys([*refs, *schedulers]))
    scores = {
        k: {i: v for i, v in d.items() if math.isfinite(v)}
        for k, d in paired_scores(rows, names, metric, pair_key).items()
    }
    sign = 1.0 if higher_is_better(metric) else -1.0
    refs = complete_variants({r: scores[r] for r in refs})
    ref = reference_scores([scores[r] for r in refs], sign)
    zero = scores[baseline] if baseline in schedulers and scores.get(baseline) else None
    scenario = {pair_key(r): str(r.get("scenario", "")) for r in rows}
    out = []
    for name in schedulers:
        if name in refs or name == baseline:
            continue
        (frac, (lo, hi), med), keys = fraction_on_pairs(
            scores[name], ref, zero, sign, scenario.__getitem__
        )
        above = sum(sign * (scores[name][k] - ref[k]) > 0 for k in keys)
        label = reference_label(refs)
        base = baseline if zero is not None else None
        out.append(OracleFraction(name, label, metric, base, frac, lo, hi, med, len(keys), above))
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
        order = tuple(sorted(schedulers, key=lambda s: (math.isnan(means[s]), sign * means[s])))
        pairs = paired_comparisons(scores, metric=metric, higher_is_better=higher, alpha=alpha)
        blocks = [k for k in scores[schedulers[0]] if all(k in scores[s] for s in schedulers)]
        fr = friedman([[scores[s][k] for k in blocks] for s in schedulers], higher)
        out.append(MetricRanking(metric, metric_label(metric), order, means, tuple(pairs), fr))
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
# a study's statistics, computed once, shown by compare (text) and report (Markdown, HTML, CSV)


@dataclass(frozen=True)
class StudyStats:
    """The paired tables, fractions of the oracle and rankings of one study.

    Attributes
    ----------
    policies : tuple of str
        The compared schedulers (every scheduler but the clairvoyant references).
    oracle : str or None
        The reference the fractions are taken of (:func:`reference_label`; None: no oracle in
        the study).
    metrics : tuple of str
        The metrics with a paired table, headline first.
    paired : dict of str -> list of PairedComparison
        Per metric, every pair of policies (Holm within the metric).
    fractions : list of OracleFraction
        Of the headline metric (empty without an oracle).
    rankings : list of MetricRanking
        One per ranking metric present.
    confidence : float
    """

    policies: tuple[str, ...]
    oracle: str | None
    metrics: tuple[str, ...]
    paired: dict[str, list[PairedComparison]]
    fractions: list[OracleFraction]
    rankings: list[MetricRanking]
    confidence: float = 0.95

    def separation(self) -> str:
        """:func:`separation` of the rankings."""
        return separation(self.rankings)

    def paired_records(self) -> list[dict[str, Any]]:
        """Every paired comparison as a flat dict (the report's ``paired.csv``)."""
        return [
            {
                "a": c.a,
                "b": c.b,
                "metric": c.metric,
                "pairs": c.n,
                "mean_diff": c.diff.mean,
                "ci": c.diff.half_width,
                "low": c.diff.low,
                "high": c.diff.high,
                "effect_dz": c.effect,
                "wins": c.wins,
                "ties": c.ties,
                "losses": c.losses,
                "p_wilcoxon": c.p,
                "p_holm": c.p_holm,
                "resolved": c.resolved,
                "pairs_needed_80": c.pairs_needed(),
                "verdict": c.verdict(),
            }
            for pairs in self.paired.values()
            for c in pairs
        ]

    def fraction_records(self) -> list[dict[str, Any]]:
        """Every fraction of the oracle as a flat dict."""
        return [
            {
                "scheduler": f.scheduler,
                "oracle": f.oracle,
                "metric": f.metric,
                "baseline": f.baseline,
                "pairs": f.n,
                "fraction": f.fraction,
                "low": f.low,
                "high": f.high,
                "median_pair": f.median_pair,
                "better_than_oracle": f.above,
            }
            for f in self.fractions
        ]

    def ranking_records(self) -> list[dict[str, Any]]:
        """Every ranking as a flat dict."""
        return [
            {
                "metric": r.metric,
                "ranking": r.chain(),
                "pairs": len(r.pairs),
                "pairs_differing": r.significant,
                "median_abs_dz": r.median_abs_effect,
                "friedman_p": r.friedman.p,
                "kendall_w": r.friedman.w,
                "blocks": r.friedman.blocks,
            }
            for r in self.rankings
        ]


def study_stats(
    rows: Rows,
    schedulers: Sequence[str],
    metrics: Sequence[str],
    pair_key: PairKey,
    *,
    references: Sequence[str] = (),
    oracle: str | None = None,
    confidence: float = 0.95,
    alpha: float = 0.05,
) -> StudyStats:
    """The :class:`StudyStats` of a study's completed episodes.

    Parameters
    ----------
    rows, schedulers, pair_key
        Completed episodes, every scheduler label in display order, the pairing (module
        docstring).
    metrics : sequence of str
        Metrics with a paired table; the first is the headline (fractions of the oracle).
    references : sequence of str
        Clairvoyant schedulers: not compared, not ranked.
    oracle : str, optional
        The one reference the fractions are taken of (default: the best of ``references`` on
        each instance).
    """
    policies = tuple(s for s in schedulers if s not in references)
    refs = [oracle] if oracle is not None else list(references)
    paired = {
        m: paired_table(rows, policies, m, pair_key, confidence=confidence, alpha=alpha)
        for m in metrics
    }
    fractions = (
        oracle_fractions(rows, policies, refs, metrics[0], pair_key) if refs and metrics else []
    )
    oracle = reference_label(refs) if refs else None
    rankings = metric_rankings(rows, policies, RANKING_METRICS, pair_key, alpha=alpha)
    return StudyStats(policies, oracle, tuple(metrics), paired, fractions, rankings, confidence)
