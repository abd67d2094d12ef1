"""Tests for the CBBA scheduler's limits: settings checked at construction, the deterministic
round cap, the wall clock (driven by a fake clock: no timing assertions here; the measured times
are in ``bench/bench_cbba.py``), and the greedy completion of auctions cut short."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fcplan
from fcplan.errors import FcplanError
from fcplan.plan import Plan
from fcplan.scheduling import make_scheduler, solve
from fcplan.taskgraph import synthetic_task_graph
from solvers.cbba import CBBAResult, CBBAScheduler
from solvers.cbba.auction import insertion_scores
from solvers.cbba.clock import CBBATimeLimitError
from solvers.cbba.settings import CBBASettingsError
from tests.solvers.test_cbba import check_result

CLOCKED = ("solvers.cbba.clock.time", "solvers.cbba.auction.time", "solvers.cbba.assembly.time")


class FakeTime:
    """A ``time`` module whose ``perf_counter`` moves ``step`` seconds at every reading."""

    def __init__(self, step: float) -> None:
        self.now, self.step, self.reads = 1000.0, step, 0

    def perf_counter(self) -> float:
        self.now += self.step
        self.reads += 1
        return self.now


class NoClock:
    """A ``time`` module that must not be read."""

    def perf_counter(self) -> float:
        raise AssertionError("the wall clock was read")


def patched(fake):
    """Context manager: the CBBA modules read ``fake`` for the time."""
    stack = [mock.patch(target, fake) for target in CLOCKED]

    class _Ctx:
        def __enter__(self):
            for p in stack:
                p.start()
            return fake

        def __exit__(self, *exc):
            for p in reversed(stack):
                p.stop()

    return _Ctx()


def graph(seed: int, n_agents: int = 8, n_tasks: int = 40, comm: float | None = None):
    return synthetic_task_graph(
        n_agents, n_tasks, np.random.default_rng(seed), fire_share=0.5, comm_range=comm
    )


def routes_of(plan) -> dict:
    return {a: tuple(r) for a, r in plan.routes.items()}


def nobody_idle_beside_free_work(res: CBBAResult) -> None:
    """After a cut: no bidder holds nothing while an item nobody holds would score > 0 for it."""
    for auc, stage, asm in zip(res.auctions, res.stages, res.assemblies, strict=True):
        if stage.converged:
            continue
        held = {j for p in asm.paths for j in p}
        for i in np.flatnonzero(auc.eligible.any(axis=1)).tolist():
            if asm.paths[i]:
                continue
            free = np.array([j for j in np.flatnonzero(auc.eligible[i]) if j not in held])
            if free.size:
                score, _ = insertion_scores(auc, i, [], free)
                assert not (score > 0).any(), f"{stage.name}: agent {i} idle beside free work"


# ---------------------------------------------------------------------- settings
BAD = [
    ("bundle_length", 0),
    ("bundle_length", 2.5),
    ("bundle_length", True),
    ("bundle_length", "3"),
    ("half_life_s", 0.0),
    ("half_life_s", float("nan")),
    ("half_life_s", float("inf")),
    ("fresh_s", -1.0),
    ("watch_weight", float("nan")),
    ("watch_weight", -0.5),
    ("watch_altitude", float("nan")),
    ("search_altitude", float("nan")),
    ("search_altitude", -5.0),
    ("max_rounds", 0),
    ("max_rounds", 1.5),
    ("time_limit", 0.0),
    ("time_limit", -1.0),
    ("time_limit", float("nan")),
    ("deterministic", "yes"),
    ("deterministic", 1),
]


@pytest.mark.parametrize(("name", "value"), BAD)
def test_bad_settings_are_rejected_in_one_line(name, value):
    """A setting of the wrong type, out of range or NaN raises at construction an
    FcplanError (and ValueError) whose one-line message names the setting, the allowed range
    and the value."""
    with pytest.raises(CBBASettingsError) as err:
        CBBAScheduler(**{name: value})
    msg = str(err.value)
    assert isinstance(err.value, FcplanError) and isinstance(err.value, ValueError)
    assert "\n" not in msg and msg.startswith(f"cbba: {name} must be ") and repr(value) in msg


def test_settings_from_a_scheduler_spec():
    """Settings written as a CLI spec are checked the same way, and good ones are kept."""
    with pytest.raises(FcplanError, match="search_altitude"):
        make_scheduler("cbba:search_altitude=nan")
    s = make_scheduler("cbba:deterministic=true:max_rounds=4:time_limit=0.5")
    assert (s.deterministic, s.max_rounds, s.time_limit) == (True, 4, 0.5)


def test_a_bad_time_limit_argument_is_refused():
    """``plan(time_limit=nan)`` or a negative limit raises (``solve`` then falls back)."""
    g = graph(0)
    for bad in (float("nan"), -1.0):
        with pytest.raises(ValueError, match="time_limit"):
            CBBAScheduler().plan(g, time_limit=bad, rng=None)


# ---------------------------------------------------------------------- deterministic mode
@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rounds=st.integers(1, 6))
def test_deterministic_mode_never_reads_the_clock(seed, rounds):
    """With ``deterministic=True`` the wall clock is never read, whatever time limit is passed
    (the clock here raises if read), and the plan is the same with any limit or none."""
    g = graph(seed)
    cbba = CBBAScheduler(deterministic=True, max_rounds=rounds)
    with patched(NoClock()):
        a = cbba.plan(g, time_limit=1e-9, rng=None)
        b = cbba.plan(g, time_limit=None, rng=None)
    assert routes_of(a) == routes_of(b) and a.altitudes == b.altitudes and a.stats == b.stats


def _plan_routes(args):
    seed, rounds = args
    cbba = CBBAScheduler(deterministic=True, max_rounds=rounds)
    return routes_of(cbba.plan(graph(seed, 30, 200), time_limit=1e-3, rng=None))


def test_deterministic_plans_are_identical_in_another_process():
    """The same graph and round cap give the same plan in this process and in a worker
    process (a 30-agent graph, caps that cut the auction and one that does not)."""
    jobs = [(1, 1), (2, 3), (3, 500)]
    with ProcessPoolExecutor(1) as pool:
        there = list(pool.map(_plan_routes, jobs))
    assert there == [_plan_routes(j) for j in jobs]


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rounds=st.integers(1, 3),
    comm=st.sampled_from([None, 300.0, 150.0]),
)
def test_a_round_cap_cut_is_completed_greedily(seed, rounds, comm):
    """When ``max_rounds`` stops an auction, the plan is still valid and conflict-free, says
    ``feasible`` and ``max_rounds``, and no bidder is left idle while a task nobody holds
    would score for it (the greedy completion)."""
    g = graph(seed, comm=comm)
    cbba = CBBAScheduler(deterministic=True, max_rounds=rounds)
    res = cbba.run(g)
    plan = cbba.plan(g, time_limit=None, rng=None)
    check_result(g, res, plan, cbba)
    nobody_idle_beside_free_work(res)
    if res.converged:
        assert plan.stats.status == "heuristic" and res.completed == 0
    else:
        assert plan.stats.status == "feasible" and plan.stats.size["stopped_by"] == "max_rounds"
        assert plan.stats.size["completed"] == res.completed


def test_episode_in_deterministic_mode_ignores_the_time_limit():
    """A whole episode with ``deterministic=True`` and a tiny round cap, given a 1 us limit per
    replan, runs without a fallback and gives the same trace twice."""
    cbba = CBBAScheduler(deterministic=True, max_rounds=2)
    one = fcplan.run_episode(1, cbba, seed=0, time_limit=1e-6)
    two = fcplan.run_episode(1, cbba, seed=0, time_limit=1e-6)
    assert one.fallbacks == 0
    assert [s.size for s in one.solves] == [s.size for s in two.solves]
    assert one.metrics["manual"].final_score == two.metrics["manual"].final_score


# ---------------------------------------------------------------------- wall clock
def test_a_generous_limit_changes_nothing():
    """With a limit the (fake) clock never reaches, the plan equals the unlimited one."""
    g = graph(4)
    free = CBBAScheduler().plan(g, time_limit=None, rng=None)
    with patched(FakeTime(1e-6)):
        timed = CBBAScheduler().plan(g, time_limit=10.0, rng=None)
    assert routes_of(timed) == routes_of(free) and timed.stats.status == "heuristic"


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    limit_ms=st.floats(0.0, 30.0),
    comm=st.sampled_from([None, 300.0]),
)
def test_a_wall_clock_cut_is_valid_or_raises(seed, limit_ms, comm):
    """Under a fake clock that moves 0.1 ms per reading and limits from 0 to 30 ms: either the
    plan is valid and conflict-free, says ``time_limit`` when it was cut, and leaves no bidder
    idle beside free work, or :class:`CBBATimeLimitError` is raised, in which case ``solve``
    falls back to greedy and says why. The run ends by the hard deadline (the limit + 10 % +
    5 ms) but for the few readings of the step under way."""
    g = graph(seed, comm=comm)
    cbba = CBBAScheduler()
    limit = limit_ms / 1e3
    with patched(FakeTime(1e-4)) as clock:
        start = clock.now
        try:
            res = cbba.run(g, time_limit=limit)
        except CBBATimeLimitError as exc:
            assert "time limit" in str(exc)
            res = None
        used = clock.now - start
    assert used <= 1.1 * limit + 0.005 + 1e-4 * 50
    if res is None:
        with patched(FakeTime(1e-4)):
            plan = solve(cbba, g, time_limit=limit, rng=np.random.default_rng(0))
        assert plan.stats.status == "fallback" and "CBBATimeLimitError" in plan.stats.message
        return
    plan = Plan(
        routes={g.agent_ids[i]: tuple(g.task_ids[k] for k in r) for i, r in res.routes.items()}
    )
    check_result(g, res, plan, cbba)
    nobody_idle_beside_free_work(res)
    assert res.converged or res.timed_out


def test_too_short_a_limit_raises_early_and_solve_falls_back():
    """When completing the agents left with nothing would end past the hard deadline (a fake
    clock moving 1 ms per reading, 40 agents, no time), the run gives up before the deadline with
    :class:`CBBATimeLimitError`, and ``solve`` returns greedy's plan with status ``fallback``
    and the reason."""
    g = graph(0, 40, 300)
    with patched(FakeTime(1e-3)) as clock:
        start, clock.reads = clock.now, 0
        with pytest.raises(CBBATimeLimitError, match="too short"):
            CBBAScheduler().plan(g, time_limit=0.0, rng=None)
        assert clock.now - start < 0.010 and clock.reads < 12  # one agent completed, not 20
    with patched(FakeTime(1e-3)):
        plan = solve(CBBAScheduler(), g, time_limit=0.0, rng=np.random.default_rng(0))
    assert plan.stats.status == "fallback" and "too short" in plan.stats.message
    assert plan.routes
