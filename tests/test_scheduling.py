"""Tests for fcplan.scheduling: the registry, the Scheduler protocol and solve's fallbacks."""

from __future__ import annotations

import importlib
import math
import tomllib
from functools import lru_cache
from importlib.metadata import EntryPoint, PackageNotFoundError
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fcplan
from fcplan import scheduling
from fcplan.belief import Belief
from fcplan.errors import FcplanError, UnknownNameError
from fcplan.plan import Plan, validate_plan
from fcplan.scheduling import (
    STATUSES,
    Scheduler,
    SolveStats,
    available_schedulers,
    make_scheduler,
    register_scheduler,
    solve,
)
from fcplan.taskgraph import TaskGraph, build_task_graph

BUILTINS = ("greedy", "idle", "random")


@lru_cache(maxsize=1)
def graph() -> TaskGraph:
    sc = fcplan.load_scenario(1)
    world = fcplan.World().reset(sc, seed=0)
    return build_task_graph(sc, world.team, Belief(sc))


def rng() -> np.random.Generator:
    return np.random.default_rng(0)


class Raising:
    """A scheduler whose every call fails."""

    name = "raising"

    def plan(self, graph, *, time_limit=None, rng=None):
        raise RuntimeError("solver exploded")


class NotAPlan:
    """A scheduler returning a dict instead of a Plan."""

    name = "not-a-plan"

    def plan(self, graph, *, time_limit=None, rng=None):
        return {"P1": ("search:A-01",)}


class Invalid:
    """A scheduler sending an action agent to a search block."""

    name = "invalid"

    def plan(self, graph, *, time_limit=None, rng=None):
        return Plan(routes={"A1": ("search:D-05",)})


class Reporting:
    """A valid scheduler reporting its own (wrong) wall time."""

    name = "reporting"

    def __init__(self, objective: float = 7.0) -> None:
        self.objective = objective

    def plan(self, graph, *, time_limit=None, rng=None):
        return Plan(
            routes={"P1": ("search:B-05",)},
            stats=SolveStats(status="optimal", objective=self.objective, wall_time_s=-1.0),
        )


# ---------------------------------------------------------------------- registry
@pytest.mark.parametrize("name", BUILTINS)
def test_make_scheduler_finds_builtins(name):
    """make_scheduler returns the built-in greedy/idle/random scheduler with that name."""
    s = make_scheduler(name)
    assert s.name == name
    assert name in available_schedulers()
    assert fcplan.make_scheduler is make_scheduler


def _pyproject_table() -> dict[str, str]:
    doc = tomllib.loads((Path(scheduling.__file__).parents[1] / "pyproject.toml").read_text())
    return doc["project"]["entry-points"][scheduling.GROUP]


def test_source_checkout_reads_the_pyproject_table(monkeypatch, request):
    """Without fcplan's package metadata (a source checkout on PYTHONPATH, nothing installed)
    the registry is exactly pyproject.toml's entry-point table, and its names make schedulers."""

    def no_metadata(name):
        raise PackageNotFoundError(name)

    scheduling._entry_points.cache_clear()
    request.addfinalizer(scheduling._entry_points.cache_clear)  # runs before monkeypatch's undo
    monkeypatch.setattr(scheduling, "distribution", no_metadata)
    monkeypatch.setattr(scheduling, "entry_points", lambda group: [])
    monkeypatch.setattr(scheduling, "_RUNTIME", {})
    table = _pyproject_table()
    assert available_schedulers() == sorted(table)
    assert {"greedy", "idle", "random", "routing", "milp", "cbba"} <= set(table)
    for name in BUILTINS:
        assert make_scheduler(name).name == name


def test_every_table_entry_names_a_scheduler_factory():
    """Each pyproject.toml entry point loads a factory whose scheduler has the entry's name."""
    for name, target in _pyproject_table().items():
        module, _, attr = target.partition(":")
        factory = getattr(importlib.import_module(module), attr)
        assert factory().name == name


@pytest.mark.parametrize("name", BUILTINS)
def test_builtins_satisfy_the_runtime_checkable_protocol(name):
    """Every built-in scheduler is an instance of the runtime-checkable Scheduler protocol."""
    assert isinstance(make_scheduler(name), Scheduler)


def test_protocol_rejects_objects_without_plan():
    """Objects lacking ``plan`` (or ``name``) are not Schedulers."""

    class NoPlan:
        name = "x"

    class NoName:
        def plan(self, graph, *, time_limit, rng):
            return Plan()

    assert not isinstance(NoPlan(), Scheduler)
    assert not isinstance(NoName(), Scheduler)
    assert isinstance(Raising(), Scheduler)


def test_a_plugin_installed_after_the_first_lookup_is_found(monkeypatch, request):
    """The entry-point table is read once per process, but a name not in it is looked up again:
    a scheduler installed after the first lookup (a notebook's pip install) is found."""
    available_schedulers()  # the table is read and kept
    real = scheduling.entry_points
    late = EntryPoint("late-plugin", "solvers.greedy:GreedyScheduler", scheduling.GROUP)
    monkeypatch.setattr(scheduling, "entry_points", lambda group: [*real(group=group), late])
    request.addfinalizer(scheduling._entry_points.cache_clear)  # runs before monkeypatch's undo
    assert "late-plugin" not in available_schedulers()
    assert make_scheduler("late-plugin").name == "greedy"
    assert "late-plugin" in available_schedulers()


def test_unknown_name_lists_known_schedulers():
    """An unknown scheduler name raises UnknownNameError (a KeyError and FcplanError) whose
    one-line message names it and lists the known schedulers."""
    with pytest.raises(UnknownNameError) as exc:
        make_scheduler("no-such-solver")
    msg = str(exc.value)
    assert "no-such-solver" in msg
    for name in BUILTINS:
        assert name in msg
    assert "\n" not in msg
    assert isinstance(exc.value, KeyError) and isinstance(exc.value, FcplanError)


def test_bad_settings_raise_fcplan_error():
    """Settings the factory does not accept raise FcplanError naming the scheduler."""
    with pytest.raises(FcplanError, match="greedy"):
        make_scheduler("greedy", no_such_option=3)


def test_settings_reach_the_factory():
    """Keyword settings are passed to the scheduler's factory."""
    s = make_scheduler("random", keep_probability=0.25)
    assert s.keep_probability == 0.25


def test_register_scheduler_for_a_user_class(monkeypatch):
    """register_scheduler makes a user class available by name (with settings), listed by
    available_schedulers and usable by solve and run_episode."""
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))
    register_scheduler("test-user-scheduler", Reporting)
    assert "test-user-scheduler" in available_schedulers()
    s = make_scheduler("test-user-scheduler", objective=3.0)
    assert isinstance(s, Reporting) and s.objective == 3.0
    plan = solve(s, graph(), time_limit=None, rng=rng())
    assert plan.stats.status == "optimal" and plan.stats.objective == 3.0
    sc = fcplan.load_scenario(1).replace(duration_s=2)
    result = fcplan.run_episode(sc, "test-user-scheduler", seed=0)
    assert result.scheduler == "reporting"
    assert result.fallbacks == 0


# ---------------------------------------------------------------------- solve
@pytest.mark.parametrize(
    ("scheduler", "fragment"),
    [
        (Raising(), "solver exploded"),
        (NotAPlan(), "dict"),
        (Invalid(), "A1"),
    ],
    ids=["raises", "not-a-plan", "invalid-plan"],
)
def test_solve_falls_back_to_greedy(scheduler, fragment):
    """When a scheduler raises, returns a non-Plan or returns an invalid plan, solve returns
    greedy's (valid) plan with status 'fallback' and a message saying why."""
    g = graph()
    plan = solve(scheduler, g, time_limit=1.0, rng=rng())
    assert isinstance(plan, Plan)
    validate_plan(plan, g)
    assert plan.stats.status == "fallback"
    assert fragment in plan.stats.message
    greedy = make_scheduler("greedy").plan(g, time_limit=None, rng=rng())
    assert dict(plan.routes) == dict(greedy.routes)
    assert dict(plan.altitudes) == dict(greedy.altitudes)
    assert plan.stats.wall_time_s >= 0.0


@pytest.mark.parametrize("name", BUILTINS)
def test_solve_records_wall_time(name):
    """solve attaches SolveStats whose wall time is measured by solve itself (finite, >= 0)
    and whose status is one of STATUSES."""
    plan = solve(make_scheduler(name), graph(), time_limit=None, rng=rng())
    st = plan.stats
    assert isinstance(st, SolveStats)
    assert math.isfinite(st.wall_time_s) and st.wall_time_s >= 0.0
    assert st.status in STATUSES and st.status != "fallback"


def test_solve_overrides_reported_wall_time_and_keeps_the_rest():
    """A scheduler's own stats are kept (status, objective) but the wall time is solve's."""
    plan = solve(Reporting(), graph(), time_limit=None, rng=rng())
    assert plan.stats.status == "optimal"
    assert plan.stats.objective == 7.0
    assert plan.stats.wall_time_s >= 0.0
    assert plan.routes == {"P1": ("search:B-05",)}


def test_solve_gives_default_stats_to_plans_without_them():
    """A valid plan with no stats gets default SolveStats ('heuristic')."""

    class Bare:
        name = "bare"

        def plan(self, graph, *, time_limit=None, rng=None):
            return Plan(routes={"P2": ("search:A-04",)})

    plan = solve(Bare(), graph(), time_limit=None, rng=rng())
    assert plan.stats.status == "heuristic"
    assert plan.routes == {"P2": ("search:A-04",)}


def test_solve_passes_time_limit_and_rng():
    """solve hands the scheduler the graph, the time limit and the generator it was given."""
    seen = {}

    class Spy:
        name = "spy"

        def plan(self, graph, *, time_limit=None, rng=None):
            seen.update(graph=graph, time_limit=time_limit, rng=rng)
            return Plan()

    g, r = graph(), rng()
    solve(Spy(), g, time_limit=2.5, rng=r)
    assert seen == {"graph": g, "time_limit": 2.5, "rng": r}


def test_episode_survives_an_always_failing_scheduler():
    """An episode whose scheduler raises at every replan runs to the end; every replan is a
    counted fallback and greedy's plans still fight the fire."""
    sc = fcplan.load_scenario(1).replace(duration_s=20)
    result = fcplan.run_episode(sc, Raising(), seed=0)
    assert result.ticks == sc.n_ticks
    assert len(result.solves) >= 20
    assert result.fallbacks == len(result.solves)
    assert all(s.status == "fallback" and "RuntimeError" in s.message for s in result.solves)
    assert result.summary()["fallbacks"] == result.fallbacks
    assert result.trace.sensed_ever[-1] > 0


def test_scheduler_specs_carry_settings():
    """A spec "name:key=value" creates the scheduler with those settings (bools, ints, floats,
    strings parsed), keyword settings override the spec, and a malformed spec is a one-line
    FcplanError."""
    from fcplan.errors import FcplanError
    from fcplan.scheduling import parse_scheduler_spec

    assert parse_scheduler_spec("greedy:route_length=2:fresh_s=2.5:x=abc:y=TRUE") == (
        "greedy",
        {"route_length": 2, "fresh_s": 2.5, "x": "abc", "y": True},
    )
    g = make_scheduler("greedy:route_length=1:search_altitude=90")
    assert g.route_length == 1 and g.search_altitude == 90.0
    assert make_scheduler("greedy:route_length=1", route_length=4).route_length == 4
    with pytest.raises(FcplanError, match="name:key=value"):
        make_scheduler("greedy:route_length")
    with pytest.raises(FcplanError, match="bad setting no_such_setting=1: unknown setting"):
        make_scheduler("greedy:no_such_setting=1")


# ------------------------------------------------------------------ one validation path for specs
def _one_line_setting_error(spec: str, setting: str) -> str:
    from fcplan.scheduling import SettingError

    with pytest.raises(SettingError) as exc:
        make_scheduler(spec)
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) < 400
    assert exc.value.setting == setting and exc.value.scheduler == spec.split(":")[0]
    assert msg.startswith(f"scheduler {spec.split(':')[0]!r}: bad setting {setting}")
    return msg


@pytest.mark.parametrize(
    "spec, setting",
    [
        ("greedy:route_length=0", "route_length"),
        ("greedy:route_length=2.5", "route_length"),
        ("greedy:route_length=true", "route_length"),
        ("greedy:route_length=x", "route_length"),
        ("greedy:fresh_s=nan", "fresh_s"),
        ("greedy:fresh_s=-1", "fresh_s"),
        ("greedy:search_altitude=inf", "search_altitude"),
        ("greedy:max_watch_fraction=1.5", "max_watch_fraction"),
        ("greedy:spread_px=-0.1", "spread_px"),
        ("greedy:search_route_length=0", "search_route_length"),
        ("random:keep_probability=nan", "keep_probability"),
        ("random:keep_probability=2", "keep_probability"),
        ("idle:anything=1", "anything"),
        ("routing:time_limit=nan", "time_limit"),
        ("routing:time_limit=0", "time_limit"),
        ("routing:time_limit=-1", "time_limit"),
        ("milp:slots=0", "slots"),
    ],
)
def test_bad_settings_are_one_line_setting_errors(spec, setting):
    """Every refused setting (a helper's check, a factory's own ValueError, an unknown keyword)
    comes out of make_scheduler as one SettingError line naming scheduler, setting and value."""
    msg = _one_line_setting_error(spec, setting)
    assert spec.split(":", 1)[1].split("=")[0] in msg


def test_factory_exceptions_name_the_setting_they_mention():
    """A factory raising a plain exception is reported against the setting its message names,
    or the only setting given; without settings it is a 'cannot be created' line."""
    from fcplan.scheduling import SettingError, register_scheduler

    def picky(a: int = 1, b: int = 2):
        if a < 0:
            raise RuntimeError("a must be >= 0")
        if b < 0:
            raise ZeroDivisionError("nope")
        raise OSError("broken plug-in")

    register_scheduler("picky-test", picky)
    with pytest.raises(SettingError, match="bad setting a=-1: RuntimeError: a must be >= 0"):
        make_scheduler("picky-test", a=-1, b=3)
    with pytest.raises(SettingError, match="bad setting b=-1: ZeroDivisionError: nope"):
        make_scheduler("picky-test", b=-1)
    with pytest.raises(FcplanError, match="cannot be created: OSError: broken plug-in"):
        make_scheduler("picky-test")


def test_supports_deterministic_reads_the_attribute_or_the_signature():
    """supports_deterministic is True for factories with a deterministic parameter or a
    supports_deterministic = True attribute, False otherwise (greedy, idle, random)."""
    from fcplan.scheduling import register_scheduler, supports_deterministic

    def with_flag(**settings):  # hides its signature
        return make_scheduler("idle")

    with_flag.supports_deterministic = True  # type: ignore[attr-defined]
    register_scheduler("flagged-test", with_flag)
    assert supports_deterministic("routing")
    assert supports_deterministic("flagged-test:x=1")
    assert not any(supports_deterministic(n) for n in ("greedy", "idle", "random"))


# ---------------------------------------------------------------------- time-outs
def _synthetic(seed: int = 0, n_agents: int = 6, n_tasks: int = 30) -> TaskGraph:
    from fcplan.taskgraph import synthetic_task_graph

    return synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(seed))


class Canned:
    """A wall-clock scheduler returning a fixed plan with fixed stats (``deterministic`` False
    unless asked), optionally after sleeping."""

    name = "canned"
    time_limit = 0.25

    def __init__(self, plan: Plan, sleep_s: float = 0.0, deterministic: bool = False) -> None:
        self.fixed, self.sleep_s, self.deterministic = plan, sleep_s, deterministic

    def plan(self, graph, *, time_limit=None, rng=None):
        if self.sleep_s:
            import time

            time.sleep(self.sleep_s)
        return self.fixed


def _greedy_plan(g: TaskGraph) -> Plan:
    return make_scheduler("greedy").plan(g, time_limit=None, rng=rng())


def test_an_empty_plan_from_a_time_out_becomes_greedys():
    """A plan the scheduler itself marks as stopped by the clock (status time_limit) that routes
    nobody, on a graph where both roles have reachable work, is replaced by greedy's plan:
    status 'fallback', timed_out, and a message naming the time-out and the idle team."""
    g = _synthetic()
    plan = solve(Canned(Plan(stats=SolveStats(status="time_limit"))), g, time_limit=0.5, rng=rng())
    assert plan.stats.status == "fallback" and plan.stats.timed_out
    assert "time-out" in plan.stats.message and "action agents" in plan.stats.message
    assert dict(plan.routes) == dict(_greedy_plan(g).routes)


def test_a_clock_bound_scheduler_that_used_up_its_limit_and_routed_nobody_falls_back():
    """Without any status from the scheduler, a call of a clock-bound scheduler (no
    ``deterministic = True``) that took its whole limit and left the team idle is a time-out
    and falls back; the limit it was held to and the overrun are recorded."""
    g = _synthetic(1)
    plan = solve(Canned(Plan(), sleep_s=0.02), g, time_limit=0.01, rng=rng())
    assert plan.stats.status == "fallback" and plan.stats.timed_out
    assert plan.stats.time_limit_s == 0.01
    assert plan.stats.overrun_s >= 0.01 and plan.stats.solver_s >= 0.02


class TimingOut(Raising):
    """A scheduler that says the clock stopped it: ``TimeoutError`` on every call."""

    def plan(self, graph, *, time_limit=None, rng=None):
        raise TimeoutError("model not built in time")


def test_a_timeout_error_is_a_time_out_and_other_errors_are_not():
    """A scheduler that raises ``TimeoutError`` (how the MILPs say their model could not be
    built in time) falls back with ``timed_out`` set; any other exception falls back without it,
    and both messages name the exception."""
    g = _synthetic(3)
    clock = solve(TimingOut(), g, time_limit=0.1, rng=rng())
    assert clock.stats.status == "fallback" and clock.stats.timed_out
    assert clock.stats.message == "TimeoutError: model not built in time"
    bug = solve(Raising(), g, time_limit=0.1, rng=rng())
    assert bug.stats.status == "fallback" and not bug.stats.timed_out
    assert bug.stats.message == "RuntimeError: solver exploded"
    assert dict(clock.routes) == dict(bug.routes) == dict(_greedy_plan(g).routes)


def test_an_idle_role_without_a_time_out_is_a_decision():
    """The same empty plan stands when nothing says the clock stopped the scheduler: a
    heuristic status within the limit, or a scheduler that declares ``deterministic = True``
    even when its call took longer than the limit (``idle`` at any limit)."""
    g = _synthetic(2)
    within = solve(Canned(Plan(stats=SolveStats())), g, time_limit=60.0, rng=rng())
    assert within.stats.status == "heuristic" and not within.stats.timed_out
    assert dict(within.routes) == {}
    slow = solve(Canned(Plan(), sleep_s=0.02, deterministic=True), g, time_limit=0.01, rng=rng())
    assert slow.stats.status == "heuristic" and dict(slow.routes) == {}
    idle = solve(make_scheduler("idle"), g, time_limit=1e-9, rng=rng())
    assert idle.stats.status == "heuristic" and dict(idle.routes) == {}


def test_a_partial_plan_falls_back_even_when_the_team_acts():
    """A plan its scheduler marks ``partial`` (its limit stopped it before the plan was
    complete) is replaced by greedy's even though it routes agents of every role."""
    g = _synthetic(3)
    half = _greedy_plan(g)
    plan = solve(Canned(half.with_stats(SolveStats(status="time_limit", partial=True))), g,
                 time_limit=0.5, rng=rng())  # fmt: skip
    assert plan.stats.status == "fallback" and "partial" in plan.stats.message


def test_a_time_out_that_routes_some_agent_with_work_stands():
    """A plan from a time-out that routes some agent with work is the scheduler's answer
    (timed_out is recorded, no fallback), even when it routes one role only (a scheduler that
    knows it stopped before planning a role says ``partial``)."""
    g = _synthetic(4)
    full = _greedy_plan(g)
    plan = solve(Canned(full.with_stats(SolveStats(status="time_limit"))), g,
                 time_limit=0.5, rng=rng())  # fmt: skip
    assert plan.stats.status == "time_limit" and plan.stats.timed_out
    actors = {a: r for a, r in full.routes.items() if a.startswith("A")}
    one_role = solve(Canned(Plan(routes=actors, stats=SolveStats(status="time_limit"))), g,
                     time_limit=0.5, rng=rng())  # fmt: skip
    assert one_role.stats.status == "time_limit" and dict(one_role.routes) == actors


def test_the_limit_recorded_is_the_callers_else_the_schedulers_own():
    """``time_limit_s`` is the caller's limit, else the scheduler's ``time_limit`` attribute
    (None for a scheduler without one); overruns are measured against it."""
    g = _synthetic(5)
    own = solve(Canned(_greedy_plan(g), sleep_s=0.01), g, time_limit=None, rng=rng())
    assert own.stats.time_limit_s == Canned.time_limit and own.stats.overrun_s == 0.0
    assert solve(make_scheduler("greedy"), g, time_limit=None, rng=rng()).stats.time_limit_s is None
    assert solve(make_scheduler("greedy"), g, time_limit=2.0, rng=rng()).stats.time_limit_s == 2.0


@given(
    seed=st.integers(0, 10_000),
    keep=st.lists(st.booleans(), min_size=8, max_size=8),
    status=st.sampled_from(["time_limit", "feasible", "heuristic"]),
)
@settings(max_examples=40, deadline=None)
def test_no_time_out_leaves_a_role_with_work_idle(seed, keep, status):
    """For any subset of greedy's routes returned by a scheduler that ran out of time (or says
    the clock stopped it), the plan solve returns does not leave the team idle, and it is the
    scheduler's own unless that subset routed nobody."""
    g = _synthetic(seed, n_agents=8, n_tasks=24)
    full = _greedy_plan(g)
    routes = {a: r for a, r in full.routes.items() if keep[g.agent_ids.index(a)]}
    plan = Plan(routes=routes, altitudes={a: full.altitudes[a] for a in routes if a in full.altitudes},
                stats=SolveStats(status=status))  # fmt: skip
    out = solve(Canned(plan), g, time_limit=0.0, rng=rng())
    assert scheduling.idle_team(out, g) == ""
    assert (out.stats.status == "fallback") == (
        not routes and bool(scheduling.idle_team(Plan(), g))
    )


@pytest.mark.parametrize("name", ["idle", "random", "greedy"])
def test_solve_records_the_graph_size_of_every_scheduler(name):
    """solve() records every replan's graph size (agents, tasks) whatever the scheduler reports,
    so schedulers that report none (idle, random) are drawn on the solve-time plots too."""
    g = _synthetic(3, n_agents=5, n_tasks=20)
    stats = solve(make_scheduler(name), g, time_limit=None, rng=rng()).stats
    assert stats.size["agents"] == g.n_agents == 5
    assert stats.size["tasks"] == g.n_tasks == 20


def test_deterministic_settings_and_spec_are_one_rule():
    """deterministic_settings adds deterministic=True exactly for schedulers with that setting
    and only when the settings do not set it; deterministic_spec is the same rule on a spec
    string (appended, the rest of the spec as written), and the scheduler it makes has
    ``deterministic`` True."""
    from fcplan.scheduling import deterministic_settings, deterministic_spec

    assert deterministic_settings("cbba", {"max_rounds": 5}) == {
        "max_rounds": 5,
        "deterministic": True,
    }
    assert deterministic_settings("cbba", {"deterministic": False}) == {"deterministic": False}
    assert deterministic_settings("greedy", {"route_length": 2}) == {"route_length": 2}
    assert deterministic_spec("cbba:max_rounds=5") == "cbba:max_rounds=5:deterministic=true"
    assert deterministic_spec("cbba:deterministic=false") == "cbba:deterministic=false"
    assert deterministic_spec("greedy:route_length=2") == "greedy:route_length=2"
    assert make_scheduler(deterministic_spec("routing")).deterministic is True
