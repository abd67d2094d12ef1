"""Tests for the MILP schedulers' settings, limits, determinism and warm start (milp, milp-cvxpy)."""

from __future__ import annotations

import contextlib
import json
import math
import subprocess
import sys
import time

import numpy as np
import pytest

import fcplan
from fcplan.plan import validate_plan
from fcplan.scheduling import SettingError, make_scheduler, solve
from fcplan.taskgraph import TaskGraph
from solvers.milp import MilpScheduler
from solvers.milp_cvxpy import MilpCvxpyScheduler
from solvers.milp_model import IncompletePlanError
from solvers.milp_model import scheduler as scheduler_module
from tests.solvers.graphs import episode_graphs as _episode_graphs

NAMES = ("milp", "milp-cvxpy")


def episode_graphs(name) -> tuple[TaskGraph, ...]:
    return _episode_graphs(name, (0, 100, 300, 600))


# ---------------------------------------------------------------------------------------- settings
@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize(
    ("settings", "match"),
    [
        ({"slots": 0}, r"bad setting slots=0: must be an integer in 1\.\.4$"),
        ({"slots": 2.5}, r"bad setting slots=2\.5: must be an integer in 1\.\.4$"),
        ({"time_limit": math.nan}, r"bad setting time_limit=nan: must be a finite number > 0 s$"),
        ({"time_limit": -1}, r"bad setting time_limit=-1: must be a finite number > 0 s$"),
        ({"time_limit": "1"}, r"bad setting time_limit=1: must be a finite number > 0 s$"),
        ({"work_limit": 0}, r"bad setting work_limit=0: must be "),
        ({"seed": -1}, r"bad setting seed=-1: must be an integer in 0\.\.2147483647$"),
        ({"deterministic": "yes"}, r"bad setting deterministic=yes: must be true or false$"),
        ({"horizon_s": math.inf}, r"bad setting horizon_s=inf: must be a finite number > 0 s$"),
        ({"prune_confidence": 1.5}, r"prune_confidence=1\.5: must be a number in \[0, 1\]$"),
        (
            {"search_weight": -0.1},
            r"bad setting search_weight=-0\.1: must be a finite number >= 0$",
        ),
        (
            {"search_altitude": math.nan},
            r"search_altitude=nan: must be a number in \(0, 10000\] m$",
        ),
        ({"slot": 2}, r"bad setting slot=2: unknown setting; milp(-cvxpy)? takes: deterministic, "),
    ],
)
def test_bad_settings_raise_one_line_errors(name, settings, match):
    """Settings are checked at construction: a wrong type, a value out of range or NaN raises a
    one-line SettingError (a ValueError) naming the scheduler, the setting, its value and the
    allowed range (unknown names too)."""
    with pytest.raises(SettingError, match=match) as info:
        make_scheduler(name, **settings)
    assert "\n" not in str(info.value)
    assert str(info.value).startswith(f"scheduler {name!r}: bad setting ")
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("limit", [math.nan, -1.0])
def test_bad_time_limit_argument_falls_back(limit):
    """A bad ``time_limit`` passed to plan() raises, so solve() falls back to greedy and says
    why."""
    g = episode_graphs(1)[1]
    with pytest.raises(ValueError, match="time_limit"):
        MilpScheduler().plan(g, time_limit=limit)
    plan = solve(MilpScheduler(), g, time_limit=limit, rng=np.random.default_rng(0))
    assert plan.stats.status == "fallback" and "time_limit" in plan.stats.message


# ---------------------------------------------------------------------------------------- determinism
@pytest.mark.parametrize("cls", [MilpScheduler, MilpCvxpyScheduler])
def test_deterministic_mode_gives_the_same_plans(cls):
    """Without a time limit, two schedulers give the same plans on the same graphs (routes,
    altitudes, objective), whatever the generator: the search stops on a work limit."""
    for name in (1, 12, 24, "open_world_example"):
        for g in episode_graphs(name):
            a = cls().plan(g, time_limit=None, rng=np.random.default_rng(1))
            b = cls().plan(g, time_limit=None, rng=np.random.default_rng(2))
            assert dict(a.routes) == dict(b.routes)
            assert dict(a.altitudes) == dict(b.altitudes)
            assert a.stats.objective == b.stats.objective


_CHILD = """
import json, sys
from solvers.milp import MilpScheduler
from tests.solvers.graphs import episode_graphs
s = MilpScheduler()
out = [dict(s.plan(g).routes) for g in episode_graphs(24, (0, 100, 300, 600))]
print(json.dumps(out))
"""


def test_deterministic_mode_is_the_same_in_another_process():
    """A fresh process under whatever load the machine has gives the very same sequence of
    plans (the warm start included) as this one."""
    s = MilpScheduler()
    here = [dict(s.plan(g).routes) for g in episode_graphs(24)]
    here = json.loads(json.dumps(here))
    out = subprocess.run(
        [sys.executable, "-c", _CHILD], capture_output=True, text=True, check=True
    ).stdout
    assert json.loads(out) == here


def test_warm_start_does_not_change_the_optimum():
    """Planning a graph after its predecessors (warm start from the previous plan) reaches the
    same objective as a fresh scheduler: the hint only speeds the search up; the previous plan
    is forgotten when a graph from an earlier time comes (a new episode)."""
    graphs = episode_graphs(12)
    s = MilpScheduler()
    for g in graphs:
        warm = s.plan(g)
        cold = MilpScheduler().plan(g)
        assert warm.stats.objective == pytest.approx(cold.stats.objective, rel=1e-9)
    assert s._previous
    s.plan(graphs[0])
    assert s._previous_time == graphs[0].time_s


# ---------------------------------------------------------------------------------------- limits
@pytest.mark.parametrize("name", NAMES)
def test_tiny_time_limit_finishes_its_own_plan_late(name):
    """With a 1e-6 s limit the clock has run out before anything is built: the scheduler
    finishes its own plan past the deadline (the smallest model, the warm start, no solve), so
    solve() keeps it: not a fallback, status time_limit, size["late"] = 1, the reason in the
    message, a valid plan with routes, and no role with work left idle."""
    from fcplan.scheduling import idle_team
    from solvers.milp_model.scheduler import MODEL_STEPS

    sched = make_scheduler(name)
    for g in episode_graphs(24) + episode_graphs("open_world_example"):
        plan = solve(sched, g, time_limit=1e-6, rng=np.random.default_rng(0))
        validate_plan(plan, g)
        st = plan.stats
        assert st.status == "time_limit" and st.size["late"] == 1
        assert st.size["model_step"] == len(MODEL_STEPS) - 1
        assert st.message.startswith("finished past the deadline")
        assert plan.n_assignments > 0 and not idle_team(plan, g)
        assert st.bound >= st.objective


@pytest.mark.parametrize("name", NAMES)
def test_tiny_time_limit_without_finish_late_falls_back(name):
    """With finish_late=False a 1e-6 s limit leaves the scheduler without a plan; it raises and
    solve() falls back to greedy (status 'fallback', reason recorded): the team still acts,
    with greedy's assignments."""
    sched = make_scheduler(name, finish_late=False)
    greedy = make_scheduler("greedy")
    for g in episode_graphs(24):
        plan = solve(sched, g, time_limit=1e-6, rng=np.random.default_rng(0))
        validate_plan(plan, g)
        assert plan.stats.status == "fallback" and plan.stats.message
        assert plan.n_assignments == greedy.plan(g, time_limit=None, rng=None).n_assignments


@pytest.mark.parametrize("cls", [MilpScheduler, MilpCvxpyScheduler])
def test_a_plan_cut_short_is_completed_late_or_raises(cls, monkeypatch):
    """A backend result that a limit stopped (status time_limit) with every agent idle is
    completed with routes of positive gain, so no agent that has work is left idle and the
    status says the limit stopped it; if the completion cannot run either (the deadline passed
    before the warm start was complete: it stopped at the deadline), plan() completes it past
    the deadline (size["late"] = 1, the idle agents named in the message), or, with
    finish_late=False, raises IncompletePlanError naming them, so solve() falls back."""
    from fcplan.scheduling import idle_team
    from solvers.milp_model import solve as solve_module

    g = episode_graphs(12)[1]
    monkeypatch.setattr(solve_module, "_solve_part", _empty_part)
    plan = cls().plan(g)
    assert plan.stats.status == "time_limit" and "late" not in plan.stats.size
    assert plan.routes and validate_plan(plan, g) is None

    def cut(model, x, deadline=None):  # the deadline passes before the completion adds a route
        while deadline is not None and time.perf_counter() < deadline:
            time.sleep(0.002)
        return x

    monkeypatch.setattr(solve_module, "complete", cut)
    late = cls().plan(g, time_limit=0.5)
    assert late.stats.size["late"] == 1 and "idle with routes to fly" in late.stats.message
    assert late.routes and validate_plan(late, g) is None and not idle_team(late, g)
    with pytest.raises(IncompletePlanError, match="idle"):
        cls(finish_late=False).plan(g, time_limit=0.5)


def _empty_part(sub, hint, positions, backend, limits, seed, settings):
    """A part whose solve the clock stopped before anything was found, warm start discarded."""
    return np.zeros_like(hint), "time_limit", 0.0, {}


def test_model_building_past_the_limit_finishes_late_or_raises(monkeypatch):
    """In wall-clock mode, when building the model uses up the limit, plan() builds the
    smallest model without a deadline and finishes its plan late (size["late"] = 1, the
    smallest step); with finish_late=False it raises TimeoutError (solve() then falls back)."""
    from solvers.milp_model.scheduler import MODEL_STEPS

    real = scheduler_module.build_milp_model

    def slow(graph, params, **kw):
        time.sleep(0.05)
        return real(graph, params, **kw)

    monkeypatch.setattr(scheduler_module, "build_milp_model", slow)
    g = episode_graphs(12)[1]
    plan = MilpScheduler().plan(g, time_limit=0.02)
    assert plan.stats.size["late"] == 1 and plan.stats.size["model_step"] == len(MODEL_STEPS) - 1
    assert plan.routes and validate_plan(plan, g) is None
    with pytest.raises(TimeoutError):
        MilpScheduler(finish_late=False).plan(g, time_limit=0.02)


def test_deterministic_plans_never_finish_late():
    """The deterministic mode has no deadline, so no plan carries the late marker."""
    for g in episode_graphs(24):
        assert "late" not in MilpScheduler().plan(g).stats.size


@pytest.mark.parametrize("name", NAMES)
def test_wall_clock_limit_is_kept(name):
    """With a 50 ms wall-clock limit every call on real graphs returns a plan or a fallback, and
    the scheduler's own call stays within the limit plus 10 % and 5 ms, or raised (timings
    are checked loosely here; bench/bench_milp.py measures them)."""
    sched = make_scheduler(name)
    for g in episode_graphs(24) + episode_graphs(12):
        t0 = time.perf_counter()
        with contextlib.suppress(IncompletePlanError, TimeoutError):
            sched.plan(g, time_limit=0.05)
        assert time.perf_counter() - t0 < 5.0  # generous: the machine may be loaded


@pytest.mark.parametrize("name", NAMES)
def test_episode_completes_and_prunes_fire(name):
    """A whole episode of scenario #1 runs with the scheduler, and the team puts fire out."""
    result = fcplan.run_episode(1, name, seed=0)
    assert result.ticks == fcplan.load_scenario(1).n_ticks
    assert len(result.solves) > 0
    assert result.trace.pruned[-1] > 0
    assert result.metrics["manual"].overall_firefighting > 0
    assert any(s.status == "optimal" for s in result.solves)


def test_wall_clock_limit_sizes_the_model():
    """Under a wall-clock limit the scheduler picks the largest model size predicted to fit
    its share of the time (on a fresh scheduler the prediction is the measured priors: the
    configured model for 4 agents at 0.1 s, the smallest for 24), the configured model under a
    generous limit and always in the deterministic mode; each size caps the settings, never
    raises them; the plan's stats name the size."""
    from fcplan.taskgraph import synthetic_task_graph

    s = MilpScheduler()
    before = 0.1 * (1.0 - s.reserve_share)
    assert s._step(4, before) == 0 and s._step(24, before) == 3 and s._step(24, 30.0) == 0
    g = synthetic_task_graph(8, 60, np.random.default_rng(0))
    assert MilpScheduler().plan(g, time_limit=30.0).stats.size["model_step"] == 0
    assert MilpScheduler().plan(g).stats.size["model_step"] == 0
    small = MilpScheduler(search_candidates=2, slots=1)
    assert all(p.search_candidates == 2 and p.slots == 1 for p in small._steps)
    assert MilpScheduler()._steps[3].max_scored_ends == 16


def test_a_slow_build_teaches_the_prediction():
    """A build slower than predicted raises the scheduler's factor (so a later replan of the
    same size under the same limit gets a smaller model); a faster one lowers it."""
    from fcplan.taskgraph import synthetic_task_graph

    g = synthetic_task_graph(4, 40, np.random.default_rng(0))
    s = MilpScheduler()
    s._log_factor = -3.0  # as after builds far faster than their priors
    s._build(g, 0, [], deadline=time.perf_counter() + 30.0)
    assert s._log_factor > -3.0
    s._log_factor = 3.0
    s._build(g, 0, [], deadline=time.perf_counter() + 30.0)
    assert s._log_factor < 3.0
    assert s._step(4, 0.085) == 3  # e^3 times the priors: only the smallest size is left
