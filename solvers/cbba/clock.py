"""When a CBBA run stops early: the wall clock of one ``plan()`` call.

In wall mode (a ``time_limit`` was given and ``deterministic=False``) every auction asks a
:class:`Clock` before each agent's bundle construction and before each neighbour slot of a
consensus round whether it may go on, so no step runs long past the limit (one bundle
construction or one slot: about a millisecond on 100 agents x 2,000 tasks). The answer keeps
back the time the greedy completion will need: an auction stops once

``now + pending_work * unit_s >= soft``

where ``pending_work`` is the *work* of the bidders that hold nothing yet (each costs about one
bundle construction to complete; the work of a bundle construction is the number of items the
agent may bid on plus :data:`BUILD_OVERHEAD` for the fixed cost of a pass) and ``unit_s`` the
seconds per unit of work measured so far in this call. ``soft`` is the stage's deadline (the
dump auction gets a share of the limit, the sense auction the rest). The greedy completion may
run until ``hard`` (the limit + 10 % + 5 ms, less a millisecond for the plan); when the
completion it still has to do would end past ``hard``, it gives up at once (so the fallback has
time) and raises :class:`CBBATimeLimitError`, and :func:`fcplan.scheduling.solve` falls back to
greedy.

In deterministic mode there is no clock at all (``None``): only the round cap stops an auction,
and the wall time is never read, so plans are identical under any machine load.

Examples
--------
>>> import time
>>> clock = Clock.start(0.5)
>>> clock.past(), clock.past_hard()
(False, False)
>>> clock.record(0.01, work=1000)  # one bundle construction over 900 items took 10 ms
>>> clock.past(pending_work=100 * 1000)  # 100 of them would take 1 s: stop now
True
"""

from __future__ import annotations

import time
from dataclasses import dataclass

__all__ = ["BUILD_OVERHEAD", "CBBATimeLimitError", "Clock"]

#: Wall time kept back after the greedy completion for turning routes into a plan (s).
PLAN_MARGIN_S = 0.001
#: Work units of the fixed cost of a bundle construction (numpy call overheads), in items.
BUILD_OVERHEAD = 100


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
    build_s, work : float
        Total time and work of the bundle constructions measured so far.
    """

    t0: float
    limit: float
    soft: float
    hard: float
    build_s: float = 0.0
    work: float = 0.0

    @classmethod
    def start(cls, limit: float) -> Clock:
        """A clock for a call that starts now and may take ``limit`` seconds."""
        t0 = time.perf_counter()
        hard = t0 + 1.1 * limit + 0.005 - PLAN_MARGIN_S
        return cls(t0=t0, limit=limit, soft=t0 + limit, hard=hard)

    def stage_deadline(self, share: float) -> None:
        """Let the next auction run until ``share`` of the limit has passed since the start."""
        self.soft = self.t0 + share * self.limit

    def record(self, seconds: float, work: float) -> None:
        """Count one bundle construction of ``work`` units that took ``seconds``."""
        self.build_s += seconds
        self.work += work

    @property
    def unit_s(self) -> float:
        """Seconds per unit of work so far (0 before any was measured)."""
        return self.build_s / self.work if self.work else 0.0

    def past(self, pending_work: float = 0.0) -> bool:
        """Should the auction stop, keeping back time for ``pending_work`` of completion?"""
        return time.perf_counter() + pending_work * self.unit_s >= self.soft

    def past_hard(self, pending_work: float = 0.0) -> bool:
        """Would ``pending_work`` of completion, started now, end past ``hard``?"""
        return time.perf_counter() + pending_work * self.unit_s >= self.hard
