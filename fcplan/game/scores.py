"""Online scores: the manual's metrics of the game so far, recomputed at most once per tick.

The game shows the manual's scores while it is played (total negative reward, OFS, PS, AS, FPS,
NRR, final score and grade). :class:`OnlineScores` scores the live world's trace with
:func:`fcplan.metrics.compute_metrics` (definition ``"manual"``), so the online values are exactly
the ones the evaluation page and a recording give at the same tick. The result is cached until the
world advances, because a frame asks for it several times.

What is shown comes from the metric table (:data:`fcplan.metrics.METRICS`): :data:`ONLINE_METRICS`
are the metrics of the in-game panel, in display order, and :func:`shown_value` /
:func:`shown_text` give a metric as the game displays it: penalties negated (the game's score is
``-NEG``), percentages with a ``%``.

Examples
--------
>>> from fcplan import load_scenario
>>> from fcplan.game import GameSession
>>> from fcplan.metrics import compute_metrics
>>> game = GameSession(load_scenario("practice"), seed=0)
>>> while game.tick < 50:
...     game.step()
>>> game.scores.metrics() == compute_metrics(game.world.trace())
True
>>> sorted(game.scores.panel())[:2]
['AS %', 'FPS %']
"""

from __future__ import annotations

from typing import Any

from fcplan.metrics import Metrics, MetricSpec, compute_metrics, metric_spec

__all__ = ["ONLINE_METRICS", "OnlineScores", "shown_text", "shown_value"]

ONLINE_METRICS: tuple[MetricSpec, ...] = tuple(
    metric_spec(name)
    for name in (
        "total_negative_reward",
        "overall_firefighting",
        "perception",
        "action",
        "facility_protection",
        "negative_reward_ratio",
        "final_score",
    )
)
"""The metrics the game shows while it is played, in display order."""


def shown_value(spec: MetricSpec, metrics: Metrics) -> float:
    """The value of ``spec`` in ``metrics`` as the game shows it (penalties negated).

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> m = compute_metrics(Trace.from_counts(ticks_per_second=1, active=[10], pruned=[0],
    ...                                       sensed_active=[0], sensed_ever=[0]))
    >>> shown_value(metric_spec("total_negative_reward"), m)
    -1.0
    """
    value = float(getattr(metrics, spec.name))
    return -value if spec.unit == "penalty" else value


def shown_text(spec: MetricSpec, metrics: Metrics, decimals: int) -> str:
    """:func:`shown_value` with ``decimals`` decimals, and `` %`` after a percentage.

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> m = compute_metrics(Trace.from_counts(ticks_per_second=1, active=[1], pruned=[1],
    ...                                       sensed_active=[1], sensed_ever=[2]))
    >>> shown_text(metric_spec("overall_firefighting"), m, 1)
    '50.0 %'
    """
    text = f"{shown_value(spec, metrics):.{decimals}f}"
    return f"{text} %" if spec.unit == "%" else text


class OnlineScores:
    """The manual metrics of a live :class:`fcplan.world.World`, cached per tick.

    Parameters
    ----------
    world : fcplan.world.World
    """

    def __init__(self, world: Any) -> None:
        self.world = world
        self._tick = -1
        self._metrics: Metrics | None = None

    def metrics(self) -> Metrics:
        """The manual metrics of the game so far (as :func:`fcplan.metrics.compute_metrics`)."""
        if self._tick != self.world.tick or self._metrics is None:
            self._metrics = compute_metrics(self.world.trace())
            self._tick = self.world.tick
        return self._metrics

    def panel(self) -> dict[str, float]:
        """The :data:`ONLINE_METRICS` as the game shows them, keyed by their short column labels
        (``"OFS %"``; the negative reward negated, as the game shows it)."""
        m = self.metrics()
        return {spec.column: shown_value(spec, m) for spec in ONLINE_METRICS}
