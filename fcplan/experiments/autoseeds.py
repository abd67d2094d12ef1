"""``--seeds auto``: add seeds in batches until every compared pair is resolved, or a cap.

A comparison with a fixed number of seeds either wastes episodes (the schedulers differ clearly
after 5 seeds) or cannot tell (their paired interval still contains 0). :class:`AutoSeeds` plays
seeds ``0 .. batch-1`` first, then ``batch .. 2 batch-1`` and so on, in that fixed order, and after
each batch looks at the paired differences of the headline metric
(:func:`~fcplan.experiments.analysis.paired_table`; the ``oracle`` is a reference, not a compared
policy). It stops when every pair is resolved, or when ``max_seeds`` seeds are played. A pair is
resolved when its paired interval excludes 0 *and* the Holm-adjusted Wilcoxon signed-rank test
agrees (both at the corrected level below), so that once the study stops every verdict of the
printed tables reads "<scheduler> better" rather than "ahead on the mean, not significant".

Looking after every batch and stopping at the first look where an interval excludes 0 is
*optional stopping*: with 10 looks at a 95 % interval, a pair with no true difference would be
declared resolved about one time in five, not one in twenty. The stopping rule therefore uses
intervals and a significance level corrected for the planned number of looks ``K = ceil(max_seeds
/ batch)`` (Bonferroni over the looks: level ``1 - (1 - confidence) / K``, alpha ``(1 -
confidence) / K``), so that a pair with no true difference stops the study as resolved with
probability at most ``1 - confidence``. The tables printed afterwards are the ordinary 95 %
intervals and 0.05-level verdicts of all the episodes played (what passed the corrected level
passes these too). The rank test also sets a floor: with ``n`` non-tied pairs its p-value is at
least ``2 / 2^n``, so resolving ``m`` pairs at alpha ``0.05 / K`` needs ``n >= log2(2 m K / 0.05)``
pairs (12 for 3 schedulers and 10 looks): with few scenarios, no study stops before that. The price: more seeds than a single
95 % look would need; fewer, larger batches mean fewer looks and a milder correction.

Everything is deterministic: the seeds and their order are fixed, each episode is a function of
its seed, so the same command stops at the same seed count on any machine and with any ``--jobs``.

Examples
--------
>>> plan = AutoSeeds(batch=5, max_seeds=50)
>>> plan.looks, round(plan.look_confidence, 4), plan.seeds(1), plan.seeds(2)[-1]
(10, 0.995, [0, 1, 2, 3, 4], 9)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from fcplan.errors import FcplanError
from fcplan.experiments.stats import PairedComparison

__all__ = ["AutoSeeds", "StopDecision"]


@dataclass(frozen=True)
class StopDecision:
    """Whether to stop adding seeds, and why (one sentence for the terminal).

    Attributes
    ----------
    stop : bool
    reason : str
    unresolved : tuple of str
        ``"a vs b"`` of the pairs whose corrected interval still contains 0.
    """

    stop: bool
    reason: str
    unresolved: tuple[str, ...] = ()


@dataclass(frozen=True)
class AutoSeeds:
    """The plan of a ``--seeds auto`` study (module docstring).

    Attributes
    ----------
    batch : int
        Seeds added per look (>= 2).
    max_seeds : int
        The cap (>= batch).
    metric : str
        The headline metric whose paired intervals decide.
    confidence : float
        The overall level; each look uses :attr:`look_confidence`.
    """

    batch: int = 5
    max_seeds: int = 50
    metric: str = "manual.final_score"
    confidence: float = 0.95

    def __post_init__(self) -> None:
        for name, low in (("batch", 2), ("max_seeds", 2)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise FcplanError(f"seeds auto: {name} must be an integer >= {low}, got {v!r}")
        if self.max_seeds < self.batch:
            raise FcplanError(
                f"seeds auto: max_seeds ({self.max_seeds}) must be >= the batch ({self.batch})"
            )
        if not 0 < self.confidence < 1:
            raise FcplanError(f"seeds auto: confidence must be in (0, 1), got {self.confidence!r}")

    @property
    def looks(self) -> int:
        """Planned looks ``ceil(max_seeds / batch)``."""
        return math.ceil(self.max_seeds / self.batch)

    @property
    def look_confidence(self) -> float:
        """The level of each look's intervals: ``1 - (1 - confidence) / looks``."""
        return 1.0 - (1.0 - self.confidence) / self.looks

    @property
    def look_alpha(self) -> float:
        """The significance level of each look's tests: ``(1 - confidence) / looks``."""
        return (1.0 - self.confidence) / self.looks

    def seeds(self, look: int) -> list[int]:
        """The seeds played after ``look`` looks (1-based): ``0 .. min(look batch, max) - 1``."""
        return list(range(min(look * self.batch, self.max_seeds)))

    def decide(self, pairs: Sequence[PairedComparison], look: int) -> StopDecision:
        """Stop when every pair is significant at the look's level (``pairs`` computed with
        ``confidence=`` :attr:`look_confidence` and ``alpha=`` :attr:`look_alpha`), or at the cap.

        Examples
        --------
        >>> from fcplan.experiments.stats import paired_comparisons
        >>> plan = AutoSeeds(batch=5, max_seeds=10)
        >>> pairs = paired_comparisons({"a": [1, 2, 3, 4, 5], "b": [1, 3, 2, 4, 6]},
        ...                            plan.look_confidence, alpha=plan.look_alpha)
        >>> plan.decide(pairs, 1).stop, plan.decide(pairs, 2).reason  # doctest: +ELLIPSIS
        (False, 'stopped at the cap of 10 seeds: 1 pair(s) still unresolved ...: a vs b')
        """
        n_seeds = len(self.seeds(look))
        level = f"{100 * self.look_confidence:.3g}%"
        if not pairs:
            return StopDecision(True, "stopped: fewer than two schedulers to compare")
        open_ = tuple(f"{c.a} vs {c.b}" for c in pairs if not c.significant)
        if not open_:
            return StopDecision(
                True,
                f"stopped at {n_seeds} seeds: every pair's {level} interval of {self.metric} "
                f"excludes 0 and its Holm-adjusted Wilcoxon p < {self.look_alpha:.2g} "
                f"({self.looks} planned looks, Bonferroni)",
            )
        if n_seeds >= self.max_seeds:
            return StopDecision(
                True,
                f"stopped at the cap of {self.max_seeds} seeds: {len(open_)} pair(s) still "
                f"unresolved at {level} ({self.metric}): {', '.join(open_)}",
                open_,
            )
        return StopDecision(False, f"{len(open_)} pair(s) unresolved at {n_seeds} seeds", open_)
