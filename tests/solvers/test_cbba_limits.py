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
from fcplan.settings import SettingError, show_value
from fcplan.taskgraph import synthetic_task_graph
from solvers.cbba import CBBAResult, CBBAScheduler, CBBASettingsError
from solvers.cbba.auction import insertion_scores
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
    ("search_altitude", 0.0),
    ("watch_altitude", 10_001.0),
    ("dump_altitude", 0.0),
    ("dump_altitude", 1e6),
    ("dump_altitude", float("inf")),
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
    """A setting of the wrong type, out of range or NaN raises at construction the shared
    SettingError (an FcplanError and ValueError; CBBASettingsError is its old name) whose
    one-line message names the setting, the value and the allowed range (altitudes: the range
    every scheduler takes, (0, 10000] m)."""
    with pytest.raises(SettingError) as err:
        CBBAScheduler(**{name: value})
    msg = str(err.value)
    assert isinstance(err.value, FcplanError) and isinstance(err.value, ValueError)
    assert CBBASettingsError is SettingError and err.value.setting == name
    assert "\n" not in msg and msg.startswith(f"bad setting {name}={show_value(value)}: must be ")
    if name.endswith("_altitude"):
        assert msg.endswith("must be a number in (0, 10000] m")


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
def test_a_wall_clock_cut_is_valid_and_ends_by_the_limit(seed, limit_ms, comm):
    """Under a fake clock that moves 0.1 ms per reading and limits from 0 to 30 ms, the plan is
    valid and conflict-free, says ``time_limit`` when it was cut, and leaves no bidder idle
    beside free work; the run ends by the limit but for the few readings of the step under way
    (the completion's first pass reads no clock)."""
    g = graph(seed, comm=comm)
    cbba = CBBAScheduler()
    limit = limit_ms / 1e3
    with patched(FakeTime(1e-4)) as clock:
        start = clock.now
        res = cbba.run(g, time_limit=limit)
        used = clock.now - start
    assert used <= limit + 1e-4 * 20
    plan = Plan(
        routes={g.agent_ids[i]: tuple(g.task_ids[k] for k in r) for i, r in res.routes.items()}
    )
    check_result(g, res, plan, cbba)
    nobody_idle_beside_free_work(res)
    assert res.converged or res.timed_out


def test_no_time_at_all_still_gives_every_bidder_work_and_no_fallback():
    """With no time at all (a fake clock moving 1 ms per reading, 40 agents, limit 0) the run
    reads the clock a few times only, every bidder with free work gets one item by the
    completion's vectorised first pass, and ``solve`` keeps CBBA's plan (a time-out that leaves
    the team busy: status ``time_limit``, no fallback)."""
    g = graph(0, 40, 300)
    with patched(FakeTime(1e-3)) as clock:
        start, clock.reads = clock.now, 0
        res = CBBAScheduler().run(g, time_limit=0.0)
        assert clock.now - start < 0.010 and clock.reads < 10
    nobody_idle_beside_free_work(res)
    assert res.completed > 0 and res.timed_out
    with patched(FakeTime(1e-3)):
        plan = solve(CBBAScheduler(), g, time_limit=0.0, rng=np.random.default_rng(0))
    assert plan.stats.status == "time_limit" and plan.stats.timed_out
    assert len(plan.routes) >= res.completed


def test_the_first_pass_is_sequential_greedy_on_empty_path_scores():
    """The completion's first pass picks, among (agent, item) pairs of empty bidders and free
    items, the highest insertion score on an empty path, removes that agent and item, and
    repeats: each pick's score is the auction's own insertion score and is the best left."""
    from solvers.cbba.assembly import first_items
    from solvers.cbba.static import StaticInstance, static_auction

    for seed in range(5):
        inst = StaticInstance.random(np.random.default_rng(seed), n_agents=5, n_tasks=9)
        auc = static_auction(inst)
        agents, free = np.arange(5), np.ones(9, dtype=bool)
        left, items = set(agents.tolist()), set(range(9))
        for i, j, score in first_items(auc, agents, free):
            s, _ = insertion_scores(auc, i, [], np.array([j]))
            assert s[0] == score
            for a in left:
                cand = np.array(sorted(items & set(np.flatnonzero(auc.eligible[a]).tolist())))
                if cand.size:
                    assert insertion_scores(auc, a, [], cand)[0].max() <= score
            left.discard(i)
            items.discard(j)
