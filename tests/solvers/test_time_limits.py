"""Every registered scheduler at a time limit it cannot meet (1e-6 s) on scenario #24: the
team still acts, because a time-out is a fallback (fcplan.scheduling.solve), never an idle team.

Timing itself is never asserted here (the machine is shared): ``bench/bench_time_limits.py``
measures solve times against the limits.
"""

from __future__ import annotations

from functools import cache

import pytest

from fcplan import run_episode
from fcplan.scheduling import available_schedulers

#: every scheduler registered in fcplan's entry-point table but the one that idles on purpose
ACTING = [n for n in available_schedulers() if n != "idle"]


@cache
def idle_final() -> float:
    return run_episode(24, "idle", seed=0, time_limit=1e-6).metrics["manual"].final_score


@pytest.mark.parametrize("name", ACTING)
def test_a_scheduler_out_of_time_still_leaves_the_team_acting(name):
    """At ``time_limit=1e-6`` on #24 every scheduler's episode scores above the idle team's
    (the manual's final score), each replan's plan is valid (the episode ran), and every replan
    whose plan is not the scheduler's own says why (fallback with a message)."""
    res = run_episode(24, name, seed=0, time_limit=1e-6)
    assert res.metrics["manual"].final_score > idle_final() + 50.0
    assert all(s.message for s in res.solves if s.status == "fallback")
    assert all(s.time_limit_s == 1e-6 for s in res.solves)


def test_the_idle_team_at_a_tiny_limit_is_its_own_decision():
    """``idle`` declares its plans independent of the clock: at 1e-6 s its empty plans stand
    (no fallback), so it keeps the idle team's score."""
    res = run_episode(24, "idle", seed=0, time_limit=1e-6)
    assert res.fallbacks == 0
    assert res.metrics["manual"].final_score == idle_final()
