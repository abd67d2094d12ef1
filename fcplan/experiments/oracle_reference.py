"""The clairvoyant reference of a benchmark tier, and each scheduler's fraction of it.

A study runs one or more oracle variants (``oracle``: greedy planning on the true fire;
``oracle[routing]``, ...) beside the policies. No single clairvoyant planner is best everywhere (a
greedy inner planner can be distracted by fire it cannot reach), so the **reference** on each
(scenario, seed) is the best score of the variants run on it (:func:`reference_scores`), as a
best-known solution is in a routing benchmark.

A scheduler's **fraction of the oracle** (:func:`fraction_of_oracle`) is ``F = sum_i (s_i -
idle_i) / sum_i (oracle_i - idle_i)`` over the pairs ``i`` where it, the reference and the idle
team all completed: a ratio of means, with a bootstrap interval that resamples seeds within each
scenario (the module docstring of :mod:`fcplan.experiments.leaderboard` explains the choice;
scenarios with a single pair are resampled together). The reference is made of the variants that
have played every pair of the most complete one (:func:`complete_variants`): one still being
played joins when it has caught up.
:func:`on_top` is the tier check's test that the reference is at least as good as a policy.

Examples
--------
>>> ref = reference_scores([{("h", 0): 1.0, ("h", 1): 4.0}, {("h", 0): 3.0, ("h", 1): 2.0}])
>>> ref
{('h', 0): 3.0, ('h', 1): 4.0}
>>> round(fraction_of_oracle([2.0, 3.0], list(ref.values()), [0.0, 0.0])[0], 3)
0.714
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

__all__ = [
    "BOOTSTRAP_DRAWS",
    "complete_variants",
    "fraction_of_oracle",
    "fraction_on_pairs",
    "on_top",
    "reference_scores",
]

BOOTSTRAP_DRAWS = 2000

K = TypeVar("K", bound=Hashable)


def fraction_of_oracle(
    score: Sequence[float],
    oracle: Sequence[float],
    idle: Sequence[float],
    strata: Sequence[Any] | None = None,
    *,
    draws: int = BOOTSTRAP_DRAWS,
    seed: int = 0,
) -> tuple[float, tuple[float, float], float]:
    """Fraction of the oracle's improvement over idle, its bootstrap interval, and the median of
    the per-pair ratios (see the module docstring).

    The arrays hold one value per (scenario, seed) pair, in the same order; ``strata`` (the
    scenario of each pair) makes the bootstrap resample within each scenario.

    Examples
    --------
    >>> f, (lo, hi), med = fraction_of_oracle([5, 6, 7, 8], [10, 10, 10, 10], [0, 0, 0, 0])
    >>> f, lo <= f <= hi, round(med, 3)
    (0.65, True, 0.65)
    """
    s, o, z = (np.asarray(x, np.float64) for x in (score, oracle, idle))
    gain, best = s - z, o - z
    if s.size == 0 or not np.isfinite(gain).all() or not np.isfinite(best).all():
        return math.nan, (math.nan, math.nan), math.nan
    total = best.sum()
    frac = float(gain.sum() / total) if total > 0 else math.nan
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = np.where(best > 0, gain / best, np.nan)
    median = float(np.nanmedian(ratios)) if np.isfinite(ratios).any() else math.nan
    groups = [np.arange(s.size)]
    if strata is not None:
        labels = np.asarray([str(x) for x in strata])
        groups = [np.flatnonzero(labels == u) for u in dict.fromkeys(labels.tolist())]
        # a stratum of one pair resamples to itself, adding no spread: such strata are pooled
        # (all of them singletons: the plain bootstrap), else the interval shrinks to a point
        alone = [g for g in groups if g.size == 1]
        groups = [g for g in groups if g.size > 1] + ([np.concatenate(alone)] if alone else [])
    rng = np.random.default_rng(seed)
    picks = np.concatenate(
        [g[rng.integers(0, g.size, size=(draws, g.size))] for g in groups], axis=1
    )
    num, den = gain[picks].sum(axis=1), best[picks].sum(axis=1)
    boot = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
    boot = boot[np.isfinite(boot)]
    if boot.size < draws // 2:
        return frac, (math.nan, math.nan), median
    lo, hi = np.percentile(boot, [2.5, 97.5])
    return frac, (float(lo), float(hi)), median


def fraction_on_pairs(
    mine: Mapping[K, float],
    reference: Mapping[K, float],
    idle: Mapping[K, float] | None,
    sign: float,
    stratum: Callable[[K], Any],
) -> tuple[tuple[float, tuple[float, float], float], list[K]]:
    """:func:`fraction_of_oracle` of one scheduler's scores ``mine`` (pair key -> value) on the
    pairs it shares with ``reference`` and ``idle`` (None: a zero baseline), in ``mine``'s order,
    with ``sign`` -1 for a lower-is-better metric and ``stratum(key)`` the pair's scenario; also
    returns those pairs.

    Examples
    --------
    >>> (f, _, _), keys = fraction_on_pairs({("h", 0): 5.0, ("h", 1): 7.0}, {("h", 0): 10.0},
    ...                                     {("h", 0): 0.0}, 1.0, lambda k: k[0])
    >>> f, keys
    (0.5, [('h', 0)])
    """
    keys = [k for k in mine if k in reference and (idle is None or k in idle)]
    zero = [sign * idle[k] for k in keys] if idle is not None else [0.0] * len(keys)
    frac = fraction_of_oracle(
        [sign * mine[k] for k in keys],
        [sign * reference[k] for k in keys],
        zero,
        strata=[stratum(k) for k in keys],
    )
    return frac, keys


def complete_variants(variants: Mapping[str, Mapping[K, float]]) -> list[str]:
    """The oracle variants that make up the reference: those that have played every pair of the
    variant with the most pairs (in ``variants``' order).

    :func:`reference_scores` keeps only the pairs every variant it is given completed, so a
    variant still being played would shrink the reference to its few pairs (and the fractions
    and their intervals with it); it joins once it has caught up.

    Examples
    --------
    >>> complete_variants({"oracle": {1: 0.0, 2: 0.0}, "oracle[milp]": {1: 0.0}})
    ['oracle']
    >>> complete_variants({"oracle": {1: 0.0}, "oracle[milp]": {1: 0.0, 2: 0.0}})
    ['oracle[milp]']
    """
    if not variants:
        return []
    sizes = {k: len(v) for k, v in variants.items()}
    most = set(variants[max(sizes, key=sizes.__getitem__)])
    return [k for k, v in variants.items() if most <= set(v)]


def reference_scores(variants: Sequence[Mapping[K, float]], sign: float = 1.0) -> dict[K, float]:
    """The clairvoyant reference per (scenario, seed): the best score of the oracle variants
    (``oracle``, ``oracle[routing]``, ...) over the pairs where every variant completed.

    No single clairvoyant planner is best everywhere (a greedy inner planner can be distracted by
    fire it cannot reach), so the reference is the best of those run, like a best-known solution.

    Examples
    --------
    >>> reference_scores([{("h", 0): 1.0, ("h", 1): 5.0}, {("h", 0): 3.0}])
    {('h', 0): 3.0}
    >>> reference_scores([{("h", 0): 1.0}, {("h", 0): 3.0}], sign=-1.0)  # lower is better
    {('h', 0): 1.0}
    """
    keys = set(variants[0]).intersection(*variants[1:]) if variants else set()
    pick = max if sign > 0 else min
    try:
        order = sorted(keys)  # type: ignore[type-var]
    except TypeError:  # keys that do not compare (a results row's None beside a string)
        order = sorted(keys, key=repr)
    return {k: pick(v[k] for v in variants) for k in order}


def on_top(
    reference: Mapping[tuple[str, int], float],
    mine: Mapping[tuple[str, int], float] | None,
    mean: float,
    sign: float,
) -> bool:
    """Whether the reference's mean is at least a policy's, over the (scenario, seed) pairs both
    have (a study still running has them on different pairs); without per-pair scores, the
    reference's mean against the policy's ``mean``."""
    if mine is not None and (keys := [k for k in reference if k in mine]):
        diff = np.mean([reference[k] for k in keys]) - np.mean([mine[k] for k in keys])
        return bool(sign * diff >= 0)
    return bool(sign * (float(np.mean(list(reference.values()))) - mean) >= 0)
