"""Rewards of the environments: the manual's negative reward, as an injectable function.

Both environments give their agents one shared reward per step: minus the negative reward the
FireCommander manual charges over the ticks the step covered (one tick in the motion env, one
replan period in the task env). Per simulated second the manual charges the penalty rate

    ``rate(t) = w |A(t)| + sum_f PC_f n_f(t)``

(``w`` the scenario's propagation weight per active cell, ``PC_f`` each facility's penalty
coefficient, ``n_f`` its active cells: :func:`fcplan.metrics.penalty_rate`, the integrand of
:func:`fcplan.metrics.negative_reward_rate`),
so a step covering ticks ``start + 1 .. stop`` earns ``-(w sum|A| + sum_f PC_f sum n_f) / tps``.
Summed over an episode the rewards are minus the manual total negative reward (up to float
rounding). The counts are the world's trace rows, so the sum is exact integers until the one
multiplication by the weights.

An environment takes any :class:`RewardFn` (``reward_fn=...``; default :class:`PenaltyReward`),
as jumanji's environments take theirs; the environments' optional shaping terms (bonuses per
sensed or pruned cell, a cost per dump) are added to it.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.env.reward import PenaltyReward
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> reward = PenaltyReward()
>>> reward.reset(world)
>>> for _ in range(30):
...     _ = world.step()
>>> r = reward(world, 20)  # ticks 21..30
>>> bool(r < 0), r == -(0.1 * int(world.trace().active[20:30].sum())) / 10
(True, True)
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from fcplan.metrics import facility_penalty, penalty_rate
from fcplan.world import World

__all__ = ["RewardFn", "PenaltyReward"]


class RewardFn(Protocol):
    """A step reward computed from the world (what an environment's ``reward_fn`` is)."""

    def reset(self, world: World) -> None:
        """A new episode starts on ``world`` (just reset)."""

    def __call__(self, world: World, start: int) -> float:
        """The reward of the ticks ``start + 1 .. world.tick`` (the step just played)."""
        ...


class PenaltyReward:
    """Minus the manual's negative reward accrued over the step (module docstring).

    A one-tick step reads the world's current counts, and the facility term is reused while the
    facility counts do not change (they rarely do): the motion env's per-tick path.
    """

    def __init__(self) -> None:
        self._fb_last: list[int] | None = None
        self._fb_penalty = 0.0
        self._w = 0.1
        self._tps = 1.0
        self._penalties = np.zeros(0)

    def reset(self, world: World) -> None:
        """Take the scenario's weights from ``world`` and forget the last facility counts."""
        sc = world.scenario
        assert sc is not None
        self._w = sc.scoring.propagation_weight
        self._tps = float(sc.ticks_per_second)
        self._penalties = world.facility_penalties
        self._fb_last = None
        self._fb_penalty = 0.0

    def __call__(self, world: World, start: int) -> float:
        """The reward of the ticks ``start + 1 .. world.tick``."""
        stop = world.tick
        if stop - start == 1:  # one tick: the world's counts are the tick's trace row
            fb = world.facility_burning.tolist()
            if fb != self._fb_last:  # (facility counts change rarely: reuse the penalty sum)
                self._fb_last = fb
                self._fb_penalty = facility_penalty(world.facility_burning, self._penalties)
            rate = penalty_rate(world.fire.n_burning, self._fb_penalty, self._w)
        else:
            active = int(world.trace_sum("active", start, stop))
            in_fac = world.trace_sum("facility_burning", start, stop)
            rate = penalty_rate(active, facility_penalty(in_fac, self._penalties), self._w)
        return -rate / self._tps
