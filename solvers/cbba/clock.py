"""When a CBBA run stops early: the wall clock of one ``plan()`` call.

In wall mode (a ``time_limit`` was given and ``deterministic=False``) every auction asks a
:class:`Clock` before each agent's bundle construction and before each neighbour slot of a
consensus round whether it may go on, so no step runs long past the limit (one bundle
construction or one slot: about a millisecond on 100 agents x 2,000 tasks). The answer keeps
back the time the greedy completion will need: an auction stops once

``now + pending * mean_build_s >= soft``

where ``pending`` is the number of bidders that hold nothing yet (each costs about one bundle
construction to complete) and ``mean_build_s`` the mean time of the bundle constructions
measured so far in this call. ``soft`` is the stage's deadline (the dump auction gets a share of
the limit, the sense auction the rest). The greedy completion itself may run until ``hard``
(the limit + 10 % + 5 ms, less a millisecond for the plan); past it the run gives up and
raises :class:`CBBATimeLimitError`, so :func:`fcplan.scheduling.solve` falls back to greedy.

In deterministic mode there is no clock at all (``None``): only the round cap stops an auction,
and the wall time is never read, so plans are identical under any machine load.

Examples
--------
>>> import time
>>> clock = Clock.start(0.5)
>>> clock.past(), clock.past_hard()
(False, False)
>>> clock.record(0.01)  # one bundle construction took 10 ms
>>> clock.past(pending=100)  # 100 of them would take 1 s: stop now
True
"""

from __future__ import annotations

import time
from dataclasses import dataclass

__all__ = ["CBBATimeLimitError", "Clock"]

#: Wall time kept back after the greedy completion for turning routes into a plan (s).
PLAN_MARGIN_S = 0.001


class CBBATimeLimitError(RuntimeError):
    """The time limit ran out before every agent that could bid had a route (the caller falls
    back to another scheduler)."""


@dataclass
class Clock:
    """Wall-clock deadlines of one ``plan()`` call (``time.perf_counter`` seconds).

    Attributes
    ----------
    t0 : float
        When the call started.
    limit : float
        Seconds allowed.
    soft : float
        When the current auction should stop (see the module docstring).
    hard : float
        When the greedy completion must have finished: ``t0 + 1.1 * limit + 0.005`` less
        :data:`PLAN_MARGIN_S`.
    build_s, builds : float, int
        Total time and number of the bundle constructions measured so far.
    """

    t0: float
    limit: float
    soft: float
    hard: float
    build_s: float = 0.0
    builds: int = 0

    @classmethod
    def start(cls, limit: float) -> Clock:
        """A clock for a call that starts now and may take ``limit`` seconds."""
        t0 = time.perf_counter()
        hard = t0 + 1.1 * limit + 0.005 - PLAN_MARGIN_S
        return cls(t0=t0, limit=limit, soft=t0 + limit, hard=hard)

    def stage_deadline(self, share: float) -> None:
        """Let the next auction run until ``share`` of the limit has passed since the start."""
        self.soft = self.t0 + share * self.limit

    def record(self, seconds: float) -> None:
        """Count one bundle construction that took ``seconds``."""
        self.build_s += seconds
        self.builds += 1

    def past(self, pending: int = 0) -> bool:
        """Should the auction stop, keeping back time to complete ``pending`` bidders?"""
        mean = self.build_s / self.builds if self.builds else 0.0
        return time.perf_counter() + pending * mean >= self.soft

    def past_hard(self) -> bool:
        """Is it too late even for the greedy completion?"""
        return time.perf_counter() >= self.hard
