"""Tests for fcplan.episode: the replan loop and its result."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan import compute_all, make_scheduler, run_episode
from fcplan.errors import UnknownNameError


@pytest.mark.parametrize("scheduler", ["greedy", "idle", "random"])
def test_practice_episode_completes_with_every_baseline(scheduler):
    """An episode of the practice scenario runs its 180 s and is scored with both definitions."""
    res = run_episode("practice", scheduler, seed=0)
    assert res.ticks == 1800 and res.trace.n_ticks == 1800
    assert set(res.metrics) == {"manual", "reference2020"}
    assert res.scheduler == scheduler
    assert res.fallbacks == 0
    assert len(res.solves) == len(res.replan_ticks) >= 180


def test_metrics_are_recomputable_from_the_trace_alone():
    """The result's metrics equal compute_all of its trace."""
    res = run_episode(3, "greedy", seed=1)
    again = compute_all(res.trace)
    assert {k: m.as_dict() for k, m in again.items()} == {
        k: m.as_dict() for k, m in res.metrics.items()
    }


def test_periodic_replans_follow_the_period():
    """Without event replans the loop replans exactly every replan_period simulated seconds."""
    res = run_episode(1, "greedy", seed=0, replan_period=2.5, event_replans=False)
    np.testing.assert_array_equal(res.replan_ticks, np.arange(0, 1800, 25))


def test_new_fire_triggers_extra_replans():
    """Sensing fire outside every current fire task triggers a replan before the next period."""
    res = run_episode(1, "greedy", seed=0, replan_period=5.0)
    periodic = set(range(0, 1800, 50))
    extra = [t for t in res.replan_ticks.tolist() if t not in periodic]
    assert extra, "no event-driven replan happened"


def test_scheduler_instance_and_settings_are_accepted():
    """A scheduler object with custom settings can be passed instead of a name."""
    sched = make_scheduler("greedy", route_length=1, search_altitude=100.0)
    res = run_episode("practice", sched, seed=0)
    assert res.scheduler == "greedy"


def test_bad_arguments_raise_clear_errors():
    """Unknown scheduler names and non-positive replan periods are rejected with clear errors."""
    with pytest.raises(UnknownNameError, match="greedy"):
        run_episode(1, "nope")
    with pytest.raises(ValueError, match="replan_period"):
        run_episode(1, "idle", replan_period=0)


def test_idle_team_scores_nothing_and_greedy_prunes():
    """Doing nothing prunes nothing (NRR 100, OFS 0); greedy prunes fire on an easy scenario."""
    idle = run_episode(1, "idle", seed=0).metrics["manual"]
    assert idle.overall_firefighting == 0 and idle.negative_reward_ratio == pytest.approx(100)
    greedy = run_episode(1, "greedy", seed=0).metrics["manual"]
    assert greedy.overall_firefighting > 50 and greedy.final_score > idle.final_score


def test_summary_has_headline_numbers():
    """EpisodeResult.summary flattens both metric definitions and the solve statistics."""
    s = run_episode("practice", "greedy", seed=0).summary()
    assert {"manual.final_score", "reference2020.final_score", "solve_p95_ms", "fallbacks"} <= set(
        s
    )
