"""Summary statistics for comparing episodes: means with Student-t confidence intervals.

An episode's score is one draw from the distribution of scores a scheduler achieves over seeds
(and scenarios). With ``n`` draws ``x_1..x_n`` of sample mean ``m`` and sample standard deviation
``s`` (``ddof=1``), the two-sided confidence interval of the mean at level ``c`` (0.95 by default) is
``m +/- h`` with the half-width

    h = t_{(1 + c) / 2, n - 1} * s / sqrt(n),

``t_{q, k}`` being the ``q`` quantile of Student's t with ``k`` degrees of freedom
(:func:`scipy.stats.t.ppf`). This assumes independent draws and a roughly normal mean, which is
reasonable for scores averaged over a handful of seeds; it says nothing about scenarios that were
not run.

Edge cases, by design:

* ``n = 0``: the mean and the half-width are NaN.
* ``n = 1``: the mean is the value; the half-width is NaN (one draw says nothing about spread).
* a constant sample (``s = 0``): the half-width is 0.
* NaN values are not dropped: a NaN anywhere makes the mean and the half-width NaN, so a broken
  score is visible rather than silently ignored.

Paired comparisons (:func:`paired_mean_ci`) use the differences ``a_i - b_i`` of two schedulers run
on the same (scenario, seed) pairs, which removes the scenario-to-scenario variance both share and
gives much tighter intervals than comparing two independent means.

Examples
--------
>>> from fcplan.experiments.stats import mean_ci
>>> ci = mean_ci([1.0, 2.0, 3.0])
>>> round(ci.mean, 3), round(ci.half_width, 3), ci.n
(2.0, 2.484, 3)
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats as _st

__all__ = [
    "Friedman",
    "MeanCI",
    "PairedComparison",
    "friedman",
    "holm",
    "mean_ci",
    "paired_comparisons",
    "paired_mean_ci",
    "paired_t_power",
    "pairs_needed",
    "smallest_wilcoxon_p",
    "t_quantile",
    "wilcoxon_p",
]


@dataclass(frozen=True, slots=True)
class MeanCI:
    """The mean of a sample and the half-width of its confidence interval.

    Attributes
    ----------
    mean : float
        Sample mean (NaN for an empty sample).
    half_width : float
        ``h`` such that ``[mean - h, mean + h]`` is the confidence interval (NaN when ``n < 2``).
    n : int
        Sample size.
    std : float
        Sample standard deviation with ``ddof=1`` (NaN when ``n < 2``).
    confidence : float
        The interval's level, e.g. 0.95.
    """

    mean: float
    half_width: float
    n: int
    std: float
    confidence: float = 0.95

    @property
    def low(self) -> float:
        """Lower end of the interval."""
        return self.mean - self.half_width

    @property
    def high(self) -> float:
        """Upper end of the interval."""
        return self.mean + self.half_width

    def format(self, digits: int = 1) -> str:
        """``"mean ± h"`` (``"mean ± nan"`` when the half-width is undefined).

        Examples
        --------
        >>> MeanCI(12.345, 0.5, 5, 0.4).format()
        '12.3 ± 0.5'
        """
        return f"{self.mean:.{digits}f} ± {self.half_width:.{digits}f}"


def t_quantile(confidence: float, n: int) -> float:
    """Two-sided Student-t critical value ``t_{(1 + confidence) / 2, n - 1}`` (NaN for n < 2).

    Examples
    --------
    >>> round(t_quantile(0.95, 5), 4)
    2.7764
    """
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    if n < 2:
        return math.nan
    return float(_st.t.ppf((1.0 + confidence) / 2.0, n - 1))


def mean_ci(values: Iterable[float], confidence: float = 0.95) -> MeanCI:
    """Mean and Student-t confidence interval of the mean of ``values``.

    Parameters
    ----------
    values : iterable of float
        The sample (e.g. one score per episode).
    confidence : float
        Level of the two-sided interval, in (0, 1).

    Returns
    -------
    MeanCI
        See the module docstring for ``n = 0``, ``n = 1``, constant and NaN samples.

    Examples
    --------
    >>> mean_ci([5.0]).half_width
    nan
    >>> mean_ci([4.0, 4.0, 4.0]).half_width
    0.0
    """
    x = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, np.float64)
    x = x.ravel()
    n = int(x.size)
    if n == 0:
        return MeanCI(math.nan, math.nan, 0, math.nan, confidence)
    mean = float(x.mean())
    if n == 1:
        t_quantile(confidence, 2)  # validates ``confidence``
        return MeanCI(mean, math.nan, 1, math.nan, confidence)
    # a constant sample gives exactly 0 (np.std can leave rounding noise around the mean)
    std = 0.0 if np.all(x == x[0]) else float(x.std(ddof=1))
    half = t_quantile(confidence, n) * std / math.sqrt(n)
    return MeanCI(mean, float(half), n, std, confidence)


def paired_mean_ci(a: Iterable[float], b: Iterable[float], confidence: float = 0.95) -> MeanCI:
    """Mean and confidence interval of the paired differences ``a_i - b_i``.

    Use it for two schedulers run on the same (scenario, seed) pairs, in the same order.

    Raises
    ------
    ValueError
        If ``a`` and ``b`` have different lengths.

    Examples
    --------
    >>> d = paired_mean_ci([10.0, 20.0, 30.0], [9.0, 18.0, 27.0])
    >>> d.mean, d.n
    (2.0, 3)
    """
    xa = np.asarray(list(a), np.float64)
    xb = np.asarray(list(b), np.float64)
    if xa.shape != xb.shape:
        raise ValueError(f"paired samples differ in length: {xa.size} and {xb.size}")
    return mean_ci(xa - xb, confidence)


def holm(pvalues: Iterable[float]) -> np.ndarray:
    """Holm's step-down adjustment of ``m`` p-values (family-wise error control).

    Sort ascending, multiply the ``i``-th smallest (0-based) by ``m - i``, make the sequence
    non-decreasing and cap it at 1; NaN p-values stay NaN and do not count in ``m``.

    Examples
    --------
    >>> holm([0.01, 0.04, 0.03]).round(3).tolist()
    [0.03, 0.06, 0.06]
    """
    p = np.asarray(list(pvalues), np.float64)
    out = np.full(p.shape, np.nan)
    ok = np.flatnonzero(~np.isnan(p))
    m = ok.size
    if m == 0:
        return out
    order = ok[np.argsort(p[ok], kind="stable")]
    adjusted = np.maximum.accumulate(p[order] * (m - np.arange(m)))
    out[order] = np.minimum(adjusted, 1.0)
    return out


def wilcoxon_p(differences: Iterable[float]) -> float:
    """Two-sided Wilcoxon signed-rank p-value of paired differences.

    Zero differences are dropped (scipy's ``zero_method="wilcox"``; its default ``method="auto"``
    gives the exact null distribution for up to 50 non-zero differences). Every difference zero
    gives ``p = 1`` (no evidence of any difference); no difference at all, or a NaN difference,
    gives NaN.

    Examples
    --------
    >>> round(wilcoxon_p([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]), 4)
    0.0312
    >>> wilcoxon_p([0.0, 0.0, 0.0])
    1.0
    """
    d = np.asarray(list(differences), np.float64).ravel()
    if d.size == 0 or np.isnan(d).any():
        return math.nan
    if not np.any(d != 0):
        return 1.0
    with warnings.catch_warnings():  # scipy warns about ties and small samples; p is still right
        warnings.simplefilter("ignore")
        return float(_st.wilcoxon(d[d != 0]).pvalue)


def smallest_wilcoxon_p(n: int) -> float:
    """The smallest two-sided p-value the exact signed-rank test can give with ``n`` non-zero
    differences: ``2 / 2**n`` (all differences of one sign), 1 for ``n = 0``.

    With 5 pairs it is 0.0625, so no 5-pair comparison can reach p < 0.05.

    Examples
    --------
    >>> smallest_wilcoxon_p(5), smallest_wilcoxon_p(6)
    (0.0625, 0.03125)
    """
    return min(1.0, 2.0 / 2.0 ** max(int(n), 0))


def paired_t_power(effect: float, n: int, confidence: float = 0.95) -> float:
    """Power of the two-sided paired t-test (equivalently: the chance that the paired interval at
    level ``confidence`` excludes 0) with ``n`` pairs when the true standardised mean difference
    is ``effect`` (Cohen's ``d_z``): ``P(|T| > t_crit)`` for ``T`` noncentral t with ``n - 1``
    degrees of freedom and noncentrality ``d_z sqrt(n)``.

    Examples
    --------
    >>> round(paired_t_power(0.5, 33), 3), round(paired_t_power(0.5, 34), 3)
    (0.795, 0.808)
    """
    if n < 2 or not math.isfinite(effect):
        return math.nan
    crit = t_quantile(confidence, n)
    nc = abs(effect) * math.sqrt(n)
    return float(_st.nct.sf(crit, n - 1, nc) + _st.nct.cdf(-crit, n - 1, nc))


def pairs_needed(
    effect: float, power: float = 0.8, confidence: float = 0.95, limit: int = 10**7
) -> float:
    """The number of pairs at which a paired difference of standardised size ``effect`` (Cohen's
    ``d_z``) is resolved (its interval excludes 0) with probability ``power``.

    The smallest ``n >= 2`` with :func:`paired_t_power` ``>= power`` (bisection); ``inf`` for a
    zero effect or when more than ``limit`` pairs would be needed; NaN for a NaN effect. Read it
    as "if the true effect were the observed one": an effect estimated from a few pairs is itself
    uncertain.

    Examples
    --------
    >>> pairs_needed(0.5), pairs_needed(0.07)
    (34, 1604)
    """
    if not math.isfinite(effect):
        return math.nan
    if effect == 0 or paired_t_power(effect, limit, confidence) < power:
        return math.inf
    lo, hi = 1, 2  # power(lo) < power <= power(hi), lo = 1 meaning "no interval yet"
    while paired_t_power(effect, hi, confidence) < power:
        lo, hi = hi, min(2 * hi, limit)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if paired_t_power(effect, mid, confidence) >= power:
            hi = mid
        else:
            lo = mid
    return hi


@dataclass(frozen=True, slots=True)
class Friedman:
    """Friedman's rank test of ``k >= 3`` schedulers over ``n`` complete blocks (every scheduler
    played the same (scenario, seed)), with Kendall's ``W`` as its effect size.

    Attributes
    ----------
    p : float
        P-value of the chi-square approximation (tie-corrected; NaN when undefined: fewer than
        3 schedulers or 2 blocks, or every block a complete tie).
    w : float
        Kendall's coefficient of concordance ``chi2 / (n (k - 1))`` in [0, 1]: 0 when the blocks
        rank the schedulers at random, 1 when every block ranks them the same way.
    blocks : int
    mean_ranks : tuple of float
        Each scheduler's mean within-block rank (1 = best, in the metric's direction).
    """

    p: float
    w: float
    blocks: int
    mean_ranks: tuple[float, ...]


def friedman(columns: Sequence[Sequence[float]], higher_is_better: bool = True) -> Friedman:
    """Friedman's test and Kendall's ``W`` of ``k`` aligned columns (one per scheduler, one entry
    per block).

    Examples
    --------
    >>> f = friedman([[3, 3, 3, 3], [2, 2, 2, 2], [1, 1, 1, 1]])
    >>> round(f.w, 3), f.mean_ranks, f.p < 0.05
    (1.0, (1.0, 2.0, 3.0), True)
    """
    x = np.asarray(columns, np.float64)
    k = x.shape[0] if x.ndim == 2 else 0
    n = x.shape[1] if x.ndim == 2 else 0
    if k == 0 or n == 0:
        return Friedman(math.nan, math.nan, n, tuple(math.nan for _ in range(k)))
    ranks = _st.rankdata(-x if higher_is_better else x, axis=0)
    mean_ranks = tuple(float(r) for r in ranks.mean(axis=1))
    if k < 3 or n < 2 or np.isnan(x).any() or np.all(x == x[:1]):
        return Friedman(math.nan, math.nan, n, mean_ranks)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = _st.friedmanchisquare(*x)
    chi2 = float(res.statistic)
    return Friedman(float(res.pvalue), min(1.0, chi2 / (n * (k - 1))), n, mean_ranks)


@dataclass(frozen=True, slots=True)
class PairedComparison:
    """Scheduler ``a`` against ``b`` on the (scenario, seed) pairs both completed.

    Attributes
    ----------
    a, b : str
    diff : MeanCI
        Mean and confidence interval of ``a_i - b_i`` (``diff.n`` pairs).
    p : float
        Two-sided Wilcoxon signed-rank p-value (:func:`wilcoxon_p`).
    p_holm : float
        ``p`` after Holm's adjustment over every pair of the comparison (the family).
    effect : float
        Cohen's ``d_z``: the mean difference over the standard deviation of the differences
        (NaN when every difference is the same).
    metric : str
        The compared column (``""`` when not given).
    wins, ties, losses : int
        Pairs where ``a_i > b_i``, ``a_i == b_i``, ``a_i < b_i``.
    higher_is_better : bool
        The metric's direction (which scheduler a positive difference favours).
    alpha : float
        Significance level of :meth:`verdict`.
    family : int
        Number of pairs in the Holm family.
    median : float
        Median of the differences (the side the signed-rank test leans to).
    """

    a: str
    b: str
    diff: MeanCI
    p: float
    p_holm: float
    effect: float
    metric: str = ""
    wins: int = 0
    ties: int = 0
    losses: int = 0
    higher_is_better: bool = True
    alpha: float = 0.05
    family: int = 1
    median: float = math.nan

    @property
    def n(self) -> int:
        """Number of pairs."""
        return self.diff.n

    @property
    def resolved(self) -> bool:
        """Whether the interval excludes 0 (the sign of the difference is known)."""
        return bool(self.diff.low > 0 or self.diff.high < 0)

    @property
    def significant(self) -> bool:
        """Resolved and Holm-adjusted Wilcoxon ``p < alpha``: the difference both tests see."""
        return self.resolved and self.p_holm < self.alpha

    @property
    def leader(self) -> str | None:
        """The scheduler the mean difference favours (None for a zero or NaN mean)."""
        m = self.diff.mean
        if not m or m != m:
            return None
        return self.a if (m > 0) == self.higher_is_better else self.b

    def pairs_needed(self, power: float = 0.8) -> float:
        """:func:`pairs_needed` at the observed ``d_z`` and this interval's level."""
        return pairs_needed(self.effect, power, self.diff.confidence)

    def verdict(self) -> str:
        """What the pair says, in words (``"cbba better"``, ``"unresolved at n=5 (...)"``).

        * ``"<name> better"``: the interval excludes 0 and the Holm-adjusted p is below alpha;
        * ``"<name> ahead on the mean, not significant after Holm"``: the interval excludes 0
          but the signed-rank test, adjusted over the family, does not agree;
        * ``"unresolved at n=N"``: the interval contains 0 (too wide to tell), with the pairs an
          80 %-power study would need at the observed effect, a note when the signed-rank test
          (Holm-adjusted) does find a difference (the typical difference leans to one side while
          the mean difference is still unresolved), and a note when the signed-rank
          test cannot reach ``alpha`` with so few pairs (its smallest p is ``2 / 2^n``, times
          the family size after Holm);
        * ``"identical on all N pairs"``, ``"no pairs"``, ``"one pair: no interval"``.

        Examples
        --------
        >>> (c,) = paired_comparisons({"x": [5, 6, 7, 8, 9, 10], "y": [1, 2, 3, 4, 5, 6]})
        >>> c.verdict()
        'x better'
        >>> (c,) = paired_comparisons({"x": [1, 2, 3, 4], "y": [2, 1, 3, 3]})
        >>> c.verdict()
        'unresolved at n=4 (~118 pairs for 80% power at d_z=+0.26; Wilcoxon p >= 0.25 at 3 pairs)'
        """
        n = self.n
        if n == 0:
            return "no pairs"
        if n == 1:
            return "one pair: no interval"
        if self.ties == n:
            return f"identical on all {n} pairs"
        untied = n - self.ties
        least = smallest_wilcoxon_p(untied)
        floor = ""
        if least * self.family >= self.alpha:  # no pair of the family can pass Holm at alpha
            holm = " after Holm" if self.family > 1 else ""
            floor = f"Wilcoxon p >= {min(1.0, least * self.family):.2g}{holm} at {untied} pairs"
        if self.resolved:
            if self.p_holm < self.alpha:
                return f"{self.leader} better"
            text = f"{self.leader} ahead on the mean, not significant after Holm"
            return text + (f" ({floor})" if floor else "")
        notes = []
        need = self.pairs_needed()
        if need == need:
            size = f"d_z={self.effect:+.2f}"
            notes.append(
                f"~{need:,} pairs for 80% power at {size}"
                if math.isfinite(need)
                else f"no resolvable effect at {size}"
            )
        if self.p_holm < self.alpha and self.median == self.median and self.median != 0:
            side = self.a if (self.median > 0) == self.higher_is_better else self.b
            notes.append(f"but Wilcoxon favours {side}, Holm p={self.p_holm:.2g}")
        if floor:
            notes.append(floor)
        return f"unresolved at n={n}" + (f" ({'; '.join(notes)})" if notes else "")


Scores = Mapping[str, Mapping[Hashable, float]] | Mapping[str, Sequence[float]]


def _keyed(values: Mapping[Hashable, float] | Sequence[float] | np.ndarray) -> dict[Any, float]:
    if isinstance(values, Mapping):
        return {k: float(v) for k, v in values.items()}
    return {i: float(v) for i, v in enumerate(np.asarray(values, np.float64).ravel())}


def paired_comparisons(
    scores: Scores,
    confidence: float = 0.95,
    *,
    metric: str = "",
    higher_is_better: bool = True,
    alpha: float = 0.05,
) -> list[PairedComparison]:
    """Every pair of schedulers, with paired intervals, Wilcoxon and Holm-adjusted p-values.

    Parameters
    ----------
    scores : dict of name -> (sequence of float, or mapping of pair key -> float)
        Per scheduler, one score per (scenario, seed) pair. Sequences must be aligned (the same
        pairs in the same order for every scheduler, else ``ValueError``); mappings are keyed by
        the pair, and each two schedulers are compared on the keys both have (an episode that
        failed for one of them drops that pair from their comparison only).
    confidence : float
        Level of the paired intervals.
    metric, higher_is_better, alpha
        Recorded in each :class:`PairedComparison` for its :meth:`~PairedComparison.verdict`.

    Returns
    -------
    list of PairedComparison
        In the order ``(s0, s1), (s0, s2), ..., (s1, s2), ...``; the Holm family is this list.

    Examples
    --------
    >>> cmp = paired_comparisons({"x": [5, 6, 7, 8, 9, 10], "y": [1, 2, 3, 4, 5, 6]})
    >>> c = cmp[0]
    >>> (c.a, c.b, c.diff.mean, c.resolved, round(c.p_holm, 4), (c.wins, c.ties, c.losses))
    ('x', 'y', 4.0, True, 0.0312, (6, 0, 0))
    >>> paired_comparisons({"x": {"s0": 3.0, "s1": 4.0}, "y": {"s1": 1.0}})[0].n
    1
    """
    names = list(scores)
    keyed = {k: _keyed(v) for k, v in scores.items()}
    aligned = not any(isinstance(v, Mapping) for v in scores.values())
    rows = []
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            if aligned and len(keyed[a]) != len(keyed[b]):
                raise ValueError(f"{a} and {b} have different numbers of paired scores")
            common = [k for k in keyed[a] if k in keyed[b]]
            d = np.array([keyed[a][k] - keyed[b][k] for k in common], np.float64)
            ci = mean_ci(d, confidence)
            effect = ci.mean / ci.std if ci.std and ci.std > 0 else math.nan
            counts = (int((d > 0).sum()), int((d == 0).sum()), int((d < 0).sum()))
            median = float(np.median(d)) if d.size else math.nan
            rows.append((a, b, ci, wilcoxon_p(d), effect, counts, median))
    adjusted = holm([r[3] for r in rows])
    return [
        PairedComparison(
            a, b, ci, p, float(ph), eff, metric, *counts, higher_is_better, alpha, len(rows), med
        )
        for (a, b, ci, p, eff, counts, med), ph in zip(rows, adjusted, strict=True)
    ]
