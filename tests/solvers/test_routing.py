"""Tests for solvers.routing: feasible, role-respecting, near-optimal and reproducible routes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fcplan
from fcplan.errors import FcplanError
from fcplan.plan import Plan, validate_plan
from fcplan.scenario import Role
from fcplan.scheduling import SolveStats, make_scheduler, solve
from fcplan.taskgraph import TaskGraph, TaskKind, synthetic_task_graph
from fcplan.team import Mode
from solvers.routing import PyVRPRoutingScheduler, RoutingScheduler
from tests.solvers.graphs import SCENARIOS, episode_graphs
from tests.solvers.test_greedy import known_fire_graph

#: replan ticks of the greedy episodes the real graphs come from (shared with test_greedy's cache)
TICKS = (0, 100, 300, 600)
#: two consecutive replans (one simulated second apart)
CONSECUTIVE = (300, 310)

#: fast settings for feasibility tests (feasibility does not depend on the search effort)
FAST = {"deterministic": True, "solution_limit": 20, "branch_limit": 1000, "iterations": 50}

BACKENDS = ["ortools", "pyvrp"]


def check_routing_plan(g: TaskGraph, plan: Plan, max_visits: int = 4) -> None:
    """Every rule a routing plan must satisfy on ``g``."""
    validate_plan(plan, g)
    assert isinstance(plan.stats, SolveStats)
    assert plan.stats.status in ("feasible", "time_limit")
    fire_owner: dict[str, str] = {}
    for a, route in plan.routes.items():
        i = g.agent_index[a]
        kinds = [g.task_kind[g.task_index[t]] for t in route]
        assert route, f"{a}: empty routes are left out of the plan"
        assert g.agent_mode[i] != Mode.HOMING, f"{a} is homing but routed"
        assert len(set(route)) == len(route), f"{a} visits a task twice"
        assert len(route) <= max_visits, f"{a}: {len(route)} visits > {max_visits}"
        if any(k == TaskKind.SEARCH for k in kinds):
            assert g.agent_can_sense[i], f"{a} cannot sense but got a search task"
        if g.agent_can_act[i] and g.agent_tank[i] > 0:
            assert all(k == TaskKind.FIRE for k in kinds), f"{a} acts, but got a search task"
            assert len(route) <= g.agent_tank[i], (
                f"{a}: {len(route)} fires > tank {g.agent_tank[i]}"
            )
            for t in route:
                assert t not in fire_owner, f"{t} given to {fire_owner.get(t)} and {a}"
                fire_owner[t] = a
        else:
            assert g.agent_can_sense[i], f"{a} has no water and no camera but got a route"
        need, have = g.route_length_px(i, route), g.agent_budget_px[i]
        assert g.route_ok(i, route), f"{a}: route + way home {need:.1f} px > {have:.1f} px"
    for a, z in plan.altitudes.items():
        i = g.agent_index[a]
        lo, hi = g.agent_alt_range[i]
        assert lo <= z <= hi, (a, z)
        assert g.agent_can_sense[i]
    assert not plan.home and not plan.patrol


def plan_of(g: TaskGraph, **settings_) -> Plan:
    return RoutingScheduler(**settings_).plan(g, time_limit=None, rng=np.random.default_rng(0))


# ---------------------------------------------------------------------------- feasibility
@pytest.mark.parametrize("backend", BACKENDS)
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 6),
    n_tasks=st.integers(0, 30),
    battery=st.sampled_from([40.0, 120.0, 500.0]),
    data=st.data(),
)
def test_routes_are_feasible_on_random_graphs(backend, seed, n_agents, n_tasks, battery, data):
    """On random synthetic graphs (up to 6 agents x 30 tasks, any mix of modes, small tanks and
    batteries), the plan validates; action routes hold at most the tank's dumps and only fires;
    every route from the agent's start (its depot slot on a forced return) through its tasks and
    home fits its remaining range; search tasks only go to camera agents."""
    g = synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(seed), battery=battery)
    modes = data.draw(st.lists(st.sampled_from(list(Mode)), min_size=n_agents, max_size=n_agents))
    tanks = data.draw(st.lists(st.integers(0, 3), min_size=n_agents, max_size=n_agents))
    g = dataclasses.replace(
        g,
        agent_mode=np.array(modes, dtype=np.int8),
        agent_tank=np.where(g.agent_can_act, tanks, 0).astype(np.int64),
    )
    check_routing_plan(g, plan_of(g, backend=backend, **FAST))


@pytest.mark.parametrize("name", SCENARIOS)
def test_routes_are_feasible_on_episode_graphs(name):
    """On graphs from every shipped scenario (and the open-world example with hybrids), the plan
    of either backend validates and respects tanks, ranges and roles (see
    :func:`check_routing_plan`)."""
    for g in episode_graphs(name, TICKS):
        for backend in BACKENDS:
            check_routing_plan(g, plan_of(g, backend=backend, **FAST))


def test_hybrids_act_while_they_have_water_and_search_without():
    """A hybrid with water is routed over fires only and flies them at its dump altitude (the
    top of its bounds by default); with an empty tank it is routed like a perception agent
    (search blocks, with an altitude)."""
    g = next(g for g in episode_graphs("open_world_example", TICKS) if g.fire_tasks.size)
    hybrids = np.flatnonzero(g.agent_can_act & g.agent_can_sense)
    assert hybrids.size
    plan = plan_of(g, **FAST)
    check_routing_plan(g, plan)
    for i in hybrids:
        a = g.agent_ids[i]
        if plan.routes.get(a):
            assert all(g.task_kind[g.task_index[t]] == TaskKind.FIRE for t in plan.routes[a])
            assert plan.altitudes[a] == g.dump_altitude(int(i)) == g.agent_alt_range[i][1]
        else:
            assert a not in plan.altitudes
    dry = dataclasses.replace(g, agent_tank=np.where(g.agent_can_sense, 0, g.agent_tank))
    plan = plan_of(dry, **FAST)
    check_routing_plan(dry, plan)
    for i in hybrids:
        a = g.agent_ids[i]
        assert plan.routes.get(a), f"dry hybrid {a} has nothing to do"
        assert a in plan.altitudes


def test_action_agents_fight_and_a_perception_agent_watches():
    """With known fire and idle action agents at the depot, every action agent gets fire tasks
    and a perception agent watches a fire an action agent is heading to first: a one-task route
    at the (low) watch altitude."""
    g = known_fire_graph()
    plan = plan_of(g, deterministic=True)
    check_routing_plan(g, plan)
    firsts = set()
    for i, a in enumerate(g.agent_ids):
        if g.agent_can_act[i]:
            assert plan.routes.get(a), f"{a} is idle although fire is known"
            firsts.add(plan.routes[a][0])
    watchers = [
        a
        for i, a in enumerate(g.agent_ids)
        if g.agent_can_sense[i] and plan.routes.get(a, ("",))[0] in firsts
    ]
    assert watchers
    for a in watchers:
        assert len(plan.routes[a]) == 1
        assert plan.altitudes[a] == pytest.approx(35.0)


def _watchers(g: TaskGraph, plan: Plan) -> list[str]:
    """Perception-only agents whose route starts at a fire (they hover over it)."""
    return [
        a
        for a, route in plan.routes.items()
        if route
        and g.agent_can_sense[g.agent_index[a]]
        and not g.agent_can_act[g.agent_index[a]]
        and g.task_kind[list(g.task_ids).index(route[0])] == TaskKind.FIRE
    ]


@pytest.mark.parametrize("tick", [1200, 2400])
def test_watching_is_capped_for_stale_fires_too(tick):
    """Once a fight has run for a while most known fires are stale; at most
    ``max_watch_fraction`` of the perception agents (here 2 of 4) are offered a fire to watch,
    so the others keep searching (the cap used to cover only fires being fought: with
    ``cap_all_watch=False`` 3 and 4 of the 4 hovered over fires on these graphs of hard-03)."""
    g = episode_graphs("hard-03", (tick,))[0]
    sensors = int((g.agent_can_sense & ~g.agent_can_act).sum())
    cap = max(1, int(0.5 * sensors))
    plan = plan_of(g, deterministic=True)
    check_routing_plan(g, plan)
    assert len(_watchers(g, plan)) <= cap
    uncapped = plan_of(g, deterministic=True, cap_all_watch=False)
    assert len(_watchers(g, uncapped)) > cap


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), fraction=st.sampled_from([0.0, 0.25, 0.5, 1.0]))
def test_watchers_never_exceed_the_cap(seed, fraction):
    """On any graph, at most ``max(1, int(max_watch_fraction * perception agents))``
    perception agents watch a fire, whatever the fires' staleness."""
    g = synthetic_task_graph(6, 40, np.random.default_rng(seed), fire_share=0.6)
    plan = plan_of(g, **FAST, max_watch_fraction=fraction)
    check_routing_plan(g, plan)
    sensors = int((g.agent_can_sense & ~g.agent_can_act).sum())
    assert len(_watchers(g, plan)) <= max(1, int(fraction * sensors))


def test_top_n_candidates_bound_the_model():
    """With ``max_nodes`` the models hold at most that many task nodes per role, and the plan
    stays feasible."""
    g = synthetic_task_graph(6, 200, np.random.default_rng(3))
    plan = plan_of(g, max_nodes=15, **FAST)
    check_routing_plan(g, plan)
    assert plan.stats.size["nodes"] <= 2 * 15
    assert plan.stats.size["vehicles"] == 6


@pytest.mark.parametrize("backend", BACKENDS)
def test_equal_values_offer_the_nearest_candidates(backend):
    """Among candidates of equal value the model takes those nearest its vehicles: at t = 0 on
    fcplan-bench-v1/scale-06 every one of 2,304 search blocks is worth the same, the first in
    task order lie 2,170 px or more from every perception vehicle (beyond its prize), and still
    every perception vehicle gets a route, to a block nearer than any of those."""
    g = episode_graphs("fcplan-bench-v1/scale-06", (0,))[0]
    plan = make_scheduler("routing", backend=backend, deterministic=True).plan(g)
    check_routing_plan(g, plan)
    perception = [a for a, r in zip(g.agent_ids, g.agent_role, strict=True) if r == Role.PERCEPTION]
    assert perception and set(perception) <= set(plan.routes)
    for aid in perception:
        a, k = g.agent_index[aid], g.task_index[plan.routes[aid][0]]
        assert np.hypot(*(g.task_pos[k] - g.agent_start_pos[a])) < 2170.0


# ---------------------------------------------------------------------------- reproducibility
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", [1, 9, 21, "open_world_example"])
def test_deterministic_mode_gives_identical_plans(name, backend):
    """In deterministic mode the same graph gives the same routes, altitudes and objective."""
    for g in episode_graphs(name, TICKS):
        a, b = (plan_of(g, deterministic=True, backend=backend) for _ in range(2))
        assert dict(a.routes) == dict(b.routes)
        assert dict(a.altitudes) == dict(b.altitudes)
        assert a.stats.objective == b.stats.objective


@pytest.mark.parametrize("backend", BACKENDS)
def test_deterministic_episode_replans_are_identical(backend):
    """Two schedulers replanning the same sequence of graphs in deterministic mode (each warm
    started from its own last plan) make identical plans at every replan."""
    graphs = episode_graphs(21, TICKS)
    a, b = (RoutingScheduler(deterministic=True, backend=backend) for _ in range(2))
    for g in graphs:
        pa, pb = (s.plan(g, time_limit=None, rng=None) for s in (a, b))
        assert dict(pa.routes) == dict(pb.routes) and pa.stats.objective == pb.stats.objective


# ---------------------------------------------------------------------------- warm start
def test_warm_start_from_the_last_plan_and_reset_on_a_new_episode():
    """With ``warm_start="search"``, from the second replan on each model's search starts from
    the scheduler's last plan (said in the message); a graph whose time does not advance (a new
    episode) drops that memory; the default ``"fallback"`` and ``"off"`` never start from it."""
    g0, g1 = episode_graphs(21, CONSECUTIVE)
    sched = RoutingScheduler(warm_start="search", **FAST)
    assert "warm start" not in sched.plan(g0, time_limit=None, rng=None).stats.message
    assert "from the warm start" in sched.plan(g1, time_limit=None, rng=None).stats.message
    assert "warm start" not in sched.plan(g0, time_limit=None, rng=None).stats.message
    for mode in ("fallback", "off"):
        cold = RoutingScheduler(warm_start=mode, **FAST)
        for g in (g0, g1):
            assert "warm start" not in cold.plan(g, time_limit=None, rng=None).stats.message
    with pytest.raises(ValueError, match="warm_start"):
        RoutingScheduler(warm_start="nope")


# ---------------------------------------------------------------------------- time limit
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", [1, 12, 21, "open_world_example"])
def test_tiny_limits_still_make_the_team_act(name, backend):
    """With a 1 microsecond or 1 millisecond limit, :func:`fcplan.scheduling.solve` returns a
    valid plan of routing's own (from its warm start, completed routes or insertion; never a
    fallback) that gives some agent a route whenever greedy would. An empty plan never stands
    for a search cut by the clock."""
    sched = make_scheduler("routing", backend=backend)
    graphs = list(episode_graphs(name, TICKS)) + [
        synthetic_task_graph(6, 30, np.random.default_rng(1))
    ]
    for limit in (1e-6, 1e-3):
        for g in graphs:
            plan = solve(sched, g, time_limit=limit, rng=np.random.default_rng(0))
            validate_plan(plan, g)
            assert plan.stats.status in ("feasible", "time_limit", "fallback")
            assert plan.stats.time_limit_s == limit
            assert plan.stats.status != "fallback", plan.stats.message
            greedy = solve(make_scheduler("greedy"), g, time_limit=None, rng=None)
            if greedy.routes:
                assert plan.routes, f"{name} t={g.time_s}: nobody acts"


@pytest.mark.parametrize("backend", BACKENDS)
def test_time_out_keeps_the_warm_start_or_builds_by_insertion(backend):
    """A replan with no time left and no earlier plan is answered by cheapest insertion on the
    scheduler's own models (status ``time_limit``, said in the message; no fallback); after a
    plan, the same replan keeps that plan's routes instead of handing back an empty plan."""
    g0, g1 = episode_graphs(21, CONSECUTIVE)
    sched = RoutingScheduler(backend=backend)
    plan = solve(sched, g1, time_limit=1e-9, rng=np.random.default_rng(0))
    assert plan.stats.status == "time_limit" and "built by insertion" in plan.stats.message
    assert plan.routes
    sched = RoutingScheduler(backend=backend)
    first = sched.plan(g0, time_limit=2.0, rng=None)  # (ample, even on a loaded machine)
    kept = sched.plan(g1, time_limit=1e-9, rng=None)
    validate_plan(kept, g1)
    assert kept.stats.status == "time_limit" and "warm start kept" in kept.stats.message
    assert kept.routes and set(kept.routes) <= set(first.routes) | set(g1.agent_ids)


def test_registry_and_settings():
    """``make_scheduler("routing")`` builds the scheduler, passes settings, and rejects unknown
    settings, backends and OR-Tools strategy names; ``PyVRPRoutingScheduler`` is the same
    scheduler on PyVRP, named ``routing-pyvrp``."""
    s = make_scheduler("routing", time_limit=0.05, max_visits=3, deterministic=True)
    assert s.name == "routing" and s.time_limit == 0.05 and s.max_visits == 3 and s.deterministic
    p = PyVRPRoutingScheduler(iterations=10)
    assert p.name == "routing-pyvrp" and p.backend == "pyvrp" and p.iterations == 10
    with pytest.raises(FcplanError):
        make_scheduler("routing", no_such_setting=1)
    with pytest.raises(ValueError, match="backend"):
        RoutingScheduler(backend="nope")
    with pytest.raises(ValueError, match="first_solution"):
        RoutingScheduler(first_solution="NOPE")
    with pytest.raises(ValueError, match="metaheuristic"):
        RoutingScheduler(metaheuristic="NOPE")


@pytest.mark.parametrize("backend", BACKENDS)
def test_stats_report_size_and_objective(backend):
    """The plan carries SolveStats with the model size, a finite objective in px and the
    backend in its message."""
    g = known_fire_graph()
    plan = plan_of(g, backend=backend, **FAST)
    s = plan.stats
    assert s.size["models"] == 2
    assert s.size["vehicles"] == g.n_agents
    assert s.size["nodes"] > 0
    assert np.isfinite(s.objective) and s.objective > 0
    assert backend in s.message


def test_uncapped_settings_route_every_reachable_task():
    """With ``max_visits=0`` and ``max_nodes=0`` routes and candidates are uncapped: a lone
    perception agent (the other one is sent home) with a large battery and large prizes visits
    every search block, in one route."""
    g = synthetic_task_graph(2, 12, np.random.default_rng(5), battery=5000.0)
    g = dataclasses.replace(
        g, agent_can_sense=np.array([True, False]), agent_can_act=np.array([False, True]),
        agent_mode=np.array([Mode.IDLE, Mode.HOMING], dtype=np.int8),
        task_kind=np.full(12, TaskKind.SEARCH, np.int8), task_value=np.full(12, 1e4),
    )  # fmt: skip
    assert g.in_round_trip[0].all()
    plan = plan_of(g, max_visits=0, max_nodes=0, charge_return=True, deterministic=True)
    check_routing_plan(g, plan, max_visits=12)
    assert sorted(plan.routes[g.agent_ids[0]]) == sorted(g.task_ids)


@pytest.mark.parametrize("backend", BACKENDS)
def test_episode_completes_and_prunes_fire(backend):
    """An episode of scenario #1 with either backend (deterministic mode, small work limits)
    completes without fallbacks and puts fire out (OFS > 0)."""
    r = fcplan.run_episode(1, RoutingScheduler(backend=backend, **FAST), seed=0)
    assert r.fallbacks == 0
    assert r.metrics["manual"].overall_firefighting > 0
