"""Tests for solvers.baselines (idle, random), every scheduler's plan validity on every shipped
scenario, and the outcome check that greedy beats both baselines."""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import fcplan
from fcplan.plan import Plan, plan_commands, validate_plan
from fcplan.scheduling import available_schedulers, make_scheduler, solve
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode
from solvers.baselines import IdleScheduler, RandomScheduler
from tests.solvers.graphs import SCENARIOS
from tests.solvers.graphs import episode_graphs as _episode_graphs

TICKS = (0, 150, 450)
BUILTINS = ("greedy", "idle", "random")


def episode_graphs(name) -> tuple[TaskGraph, ...]:
    """Task graphs at :data:`TICKS` of a greedy episode."""
    return _episode_graphs(name, TICKS)


def same_plan(a: Plan, b: Plan) -> bool:
    return dict(a.routes) == dict(b.routes) and dict(a.altitudes) == dict(b.altitudes)


# ---------------------------------------------------------------------- every scheduler
@pytest.mark.parametrize("name", SCENARIOS)
def test_every_scheduler_plan_is_valid(name):
    """On graphs from every shipped scenario, the plan of every registered built-in scheduler
    passes validate_plan, and solve never has to fall back."""
    schedulers = [make_scheduler(n) for n in BUILTINS]
    assert set(BUILTINS) <= set(available_schedulers())
    for g in episode_graphs(name):
        for s in schedulers:
            for seed in (0, 1):
                plan = s.plan(g, time_limit=1.0, rng=np.random.default_rng(seed))
                assert isinstance(plan, Plan)
                validate_plan(plan, g)
            solved = solve(s, g, time_limit=1.0, rng=np.random.default_rng(0))
            assert solved.stats.status != "fallback", solved.stats.message


# ---------------------------------------------------------------------- idle
@pytest.mark.parametrize("name", ["practice", 1, 13, 24, "open_world_example"])
def test_idle_returns_an_empty_plan(name):
    """Idle plans nothing: no routes, altitudes, patrols or home orders."""
    for g in episode_graphs(name):
        plan = IdleScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
        assert not plan.routes and not plan.altitudes and not plan.patrol and not plan.home
        assert plan.n_assignments == 0
        assert plan_commands(plan, g) == {}


# ---------------------------------------------------------------------- random
@pytest.mark.parametrize("name", ["practice", 1, 13, 24, "open_world_example"])
def test_random_is_reproducible_for_a_seed(name):
    """The random scheduler gives the same plan for generators with the same seed."""
    for g in episode_graphs(name):
        for seed in (0, 7, 123):
            a = RandomScheduler().plan(g, rng=np.random.default_rng(seed))
            b = RandomScheduler().plan(g, rng=np.random.default_rng(seed))
            assert same_plan(a, b)


@pytest.mark.parametrize("name", ["practice", 1, 13, 24, "open_world_example"])
def test_random_differs_across_seeds(name):
    """Different seeds give different plans (among 5 seeds on the start graph, at least 4
    distinct plans)."""
    g = episode_graphs(name)[0]
    plans = [RandomScheduler().plan(g, rng=np.random.default_rng(s)) for s in range(5)]
    distinct = {repr(sorted(p.routes.items())) + repr(sorted(p.altitudes.items())) for p in plans}
    assert len(distinct) >= 4


@pytest.mark.parametrize("name", SCENARIOS)
def test_random_gives_one_feasible_task_to_each_free_agent(name):
    """With keep_probability 0, every agent not sent home that has some task its role can do
    and its battery allows gets exactly one such task (the others get nothing); perception
    agents get an altitude within bounds."""
    for g in episode_graphs(name):
        plan = RandomScheduler(keep_probability=0.0).plan(g, rng=np.random.default_rng(3))
        validate_plan(plan, g)
        options = g.reachable  # (the feasibility rule: exactly what validate_plan accepts)
        for i, a in enumerate(g.agent_ids):
            route = plan.routes.get(a)
            if g.agent_mode[i] == Mode.HOMING or not options[i].any():
                assert route is None
                continue
            assert route is not None and len(route) == 1, (a, route)
            k = g.task_index[route[0]]
            assert options[i, k]
            if g.task_kind[k] == TaskKind.SEARCH:
                assert g.agent_can_sense[i]
            if g.agent_can_sense[i]:
                lo, hi = g.agent_alt_range[i]
                assert lo <= plan.altitudes[a] <= hi
            else:
                assert a not in plan.altitudes


# ---------------------------------------------------------------------- outcome
def _final_score(job: tuple[int, str, int]) -> float:
    n, name, seed = job
    return fcplan.run_episode(n, name, seed=seed).metrics["manual"].final_score


def test_greedy_beats_idle_and_random_on_average():
    """Outcome: over scenarios 1-24 with seeds 0 and 1, greedy's mean manual final score is
    higher than idle's and random's. (144 full episodes, ~20-60 s; run on up to 4 processes.)"""
    jobs = [(n, name, s) for name in BUILTINS for n in range(1, 25) for s in (0, 1)]
    workers = min(4, os.cpu_count() or 1)
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            scores = list(pool.map(_final_score, jobs, chunksize=4))
    else:
        scores = [_final_score(j) for j in jobs]
    mean = {
        name: float(np.mean([s for (_, nm, _), s in zip(jobs, scores, strict=True) if nm == name]))
        for name in BUILTINS
    }
    assert all(np.isfinite(v) for v in mean.values()), mean
    assert mean["greedy"] > mean["idle"], mean
    assert mean["greedy"] > mean["random"], mean


@pytest.mark.parametrize("bad", [float("nan"), -0.1, 1.5, "half", True, None])
def test_random_keep_probability_is_checked_at_construction(bad):
    """keep_probability outside [0, 1], NaN or not a number is a SettingError naming it; the
    ends 0 and 1 are accepted."""
    from fcplan.scheduling import SettingError

    with pytest.raises(SettingError, match="keep_probability"):
        RandomScheduler(keep_probability=bad)
    assert RandomScheduler(keep_probability=0).keep_probability == 0.0
    assert RandomScheduler(keep_probability=1).keep_probability == 1.0


def test_idle_takes_no_settings():
    """idle refuses any setting with a one-line SettingError listing that it takes none."""
    from fcplan.scheduling import SettingError

    with pytest.raises(SettingError, match="idle takes: none"):
        make_scheduler("idle:speed=2")


def test_baselines_and_greedy_declare_they_do_not_depend_on_wall_time():
    """greedy, idle and random have deterministic = True (no time-limited search), which the
    comparison tables record."""
    for name in BUILTINS:
        assert make_scheduler(name).deterministic is True
