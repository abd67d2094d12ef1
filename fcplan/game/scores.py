"""Online scores: the manual's metrics of the game so far, recomputed at most once per tick.

The game shows the manual's scores while it is played (total negative reward, OFS, PS, AS, FPS,
NRR, final score and grade). :class:`OnlineScores` scores the live world's trace with
:func:`fcplan.metrics.compute_metrics` (definition ``"manual"``), so the online values are exactly
the ones the evaluation page and a recording give at the same tick. The result is cached until the
world advances: a frame asks for it several times, and the trace of a whole 180-s game is scored
in well under a millisecond, far below the cost of drawing a frame.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.metrics import compute_metrics
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> scores = OnlineScores(world)
>>> for _ in range(50):
...     _ = world.step()
>>> scores.metrics() == compute_metrics(world.trace())
True
>>> sorted(scores.panel())[:2]
['AS %', 'FPS %']
"""

from __future__ import annotations

from fcplan.metrics import Metrics, compute_metrics

__all__ = ["OnlineScores"]


class OnlineScores:
    """The manual metrics of a live :class:`fcplan.world.World`, cached per tick.

    Parameters
    ----------
    world : fcplan.world.World
    """

    def __init__(self, world) -> None:
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
        """Short labels to values for an information panel (the game shows NEG negated)."""
        m = self.metrics()
        return {
            "reward": -m.total_negative_reward,
            "OFS %": m.overall_firefighting,
            "PS %": m.perception,
            "AS %": m.action,
            "FPS %": m.facility_protection,
            "final": m.final_score,
        }
