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
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import stats as _st

__all__ = [
    "MeanCI",
    "PairedComparison",
    "holm",
    "mean_ci",
    "paired_comparisons",
    "paired_mean_ci",
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
    """Two-sided Wilcoxon signed-rank p-value of paired differences (zeros dropped; NaN when
    fewer than one non-zero difference, or with NaN differences).

    Examples
    --------
    >>> round(wilcoxon_p([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]), 4)
    0.0312
    """
    d = np.asarray(list(differences), np.float64)
    if np.isnan(d).any() or not np.any(d != 0):
        return math.nan
    return float(_st.wilcoxon(d[d != 0]).pvalue)


@dataclass(frozen=True, slots=True)
class PairedComparison:
    """Scheduler ``a`` against ``b`` on the same (scenario, seed) pairs.

    Attributes
    ----------
    a, b : str
    diff : MeanCI
        Mean and confidence interval of ``a_i - b_i``.
    p : float
        Two-sided Wilcoxon signed-rank p-value.
    p_holm : float
        ``p`` after Holm's adjustment over every pair of the comparison.
    effect : float
        Cohen's ``d_z``: mean difference over the standard deviation of the differences.
    """

    a: str
    b: str
    diff: MeanCI
    p: float
    p_holm: float
    effect: float

    @property
    def resolved(self) -> bool:
        """Whether the interval excludes 0 (the sign of the difference is known)."""
        return bool(self.diff.low > 0 or self.diff.high < 0)


def paired_comparisons(
    scores: dict[str, Iterable[float]], confidence: float = 0.95
) -> list[PairedComparison]:
    """Every pair of schedulers, with paired intervals, Wilcoxon and Holm-adjusted p-values.

    Parameters
    ----------
    scores : dict of name -> sequence of float
        One score per (scenario, seed) pair, the pairs in the same order for every scheduler.
    confidence : float
        Level of the paired intervals.

    Examples
    --------
    >>> cmp = paired_comparisons({"x": [5, 6, 7, 8, 9, 10], "y": [1, 2, 3, 4, 5, 6]})
    >>> c = cmp[0]
    >>> (c.a, c.b, c.diff.mean, c.resolved, round(c.p_holm, 4))
    ('x', 'y', 4.0, True, 0.0312)
    """
    names = list(scores)
    arrays = {k: np.asarray(list(v), np.float64) for k, v in scores.items()}
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
    rows = []
    for a, b in pairs:
        if arrays[a].shape != arrays[b].shape:
            raise ValueError(f"{a} and {b} have different numbers of paired scores")
        d = arrays[a] - arrays[b]
        ci = mean_ci(d, confidence)
        effect = ci.mean / ci.std if ci.std and ci.std > 0 else math.nan
        rows.append((a, b, ci, wilcoxon_p(d), effect))
    adjusted = holm([r[3] for r in rows])
    return [
        PairedComparison(a, b, ci, p, float(ph), eff)
        for (a, b, ci, p, eff), ph in zip(rows, adjusted, strict=True)
    ]
