"""Tests for solvers.routing: feasible, role-respecting, near-optimal and reproducible routes."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fcplan
from fcplan.errors import FcplanError
from fcplan.plan import Plan, validate_plan
from fcplan.scheduling import SolveStats, make_scheduler, solve
from fcplan.taskgraph import TaskGraph, TaskKind, synthetic_task_graph
from fcplan.team import Mode
from solvers.routing import RoutingFailedError, RoutingScheduler, solve_routes
from tests.solvers.graphs import SCENARIOS, episode_graphs
from tests.solvers.test_greedy import known_fire_graph

#: replan ticks of the greedy episodes the real graphs come from (shared with test_greedy's cache)
TICKS = (0, 100, 300, 600)

#: fast settings for feasibility tests (feasibility does not depend on the search effort)
FAST = {"deterministic": True, "solution_limit": 20, "branch_limit": 1000}


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
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 6),
    n_tasks=st.integers(0, 30),
    battery=st.sampled_from([40.0, 120.0, 500.0]),
    data=st.data(),
)
def test_routes_are_feasible_on_random_graphs(seed, n_agents, n_tasks, battery, data):
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
    check_routing_plan(g, plan_of(g, **FAST))


@pytest.mark.parametrize("name", SCENARIOS)
def test_routes_are_feasible_on_episode_graphs(name):
    """On graphs from every shipped scenario (and the open-world example with hybrids), the plan
    validates and respects tanks, ranges and roles (see :func:`check_routing_plan`)."""
    for g in episode_graphs(name, TICKS):
        check_routing_plan(g, plan_of(g, **FAST))


def test_hybrids_act_while_they_have_water_and_search_without():
    """A hybrid with water is routed over fires only and gets no altitude; with an empty tank it
    is routed like a perception agent (search blocks, with an altitude)."""
    g = next(g for g in episode_graphs("open_world_example", TICKS) if g.fire_tasks.size)
    hybrids = np.flatnonzero(g.agent_can_act & g.agent_can_sense)
    assert hybrids.size
    plan = plan_of(g, **FAST)
    check_routing_plan(g, plan)
    for i in hybrids:
        a = g.agent_ids[i]
        if plan.routes.get(a):
            assert all(g.task_kind[g.task_index[t]] == TaskKind.FIRE for t in plan.routes[a])
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


def test_top_n_candidates_bound_the_model():
    """With ``max_nodes`` the models hold at most that many task nodes per role, and the plan
    stays feasible."""
    g = synthetic_task_graph(6, 200, np.random.default_rng(3))
    plan = plan_of(g, max_nodes=15, **FAST)
    check_routing_plan(g, plan)
    assert plan.stats.size["nodes"] <= 2 * 15
    assert plan.stats.size["vehicles"] == 6


# ---------------------------------------------------------------------------- tour quality
def brute_force_path(start, end, pts) -> float:
    """Shortest open path start -> every point -> end, by enumerating all orders."""
    n = len(pts)
    perms = np.array(list(itertools.permutations(range(n))))
    seq = pts[perms]  # (P, n, 2)
    legs = np.linalg.norm(np.diff(seq, axis=1), axis=2).sum(axis=1)
    legs += np.linalg.norm(seq[:, 0] - start, axis=1) + np.linalg.norm(seq[:, -1] - end, axis=1)
    return float(legs.min())


@pytest.mark.parametrize("n", range(4, 10))
@pytest.mark.parametrize("seed", range(3))
def test_single_vehicle_tour_is_within_2_percent_of_optimum(n, seed):
    """One vehicle, ``n`` mandatory stops (4..9), open path from its start to its depot slot: the
    routing model's tour is within 2 % of the brute-force optimum (deterministic mode)."""
    rng = np.random.default_rng(100 * n + seed)
    start, end = rng.uniform(0, 1000, (1, 2)), rng.uniform(0, 1000, (1, 2))
    pts = rng.uniform(0, 1000, (n, 2))
    sol = solve_routes(
        start, end, pts, np.full(n, np.inf), np.array([1e6]),
        charge_return=True, deterministic=True, solution_limit=2000, branch_limit=50_000,
    )  # fmt: skip
    assert sorted(sol.routes[0]) == list(range(n))
    best = brute_force_path(start[0], end[0], pts)
    assert sol.travel_px <= 1.02 * best + 1e-6
    assert sol.objective_px == pytest.approx(sol.travel_px, abs=0.1 * (n + 1))


def test_solve_routes_collects_prizes_within_budget_and_capacity():
    """Prize collecting on plain arrays: a stop worth less than its detour is dropped, one worth
    more is visited, a stop beyond the budget is never visited whatever its prize, and the
    capacity caps the visits; the objective is travel plus dropped penalties."""
    start = end = np.zeros((1, 2))
    pts = np.array([[100.0, 0.0], [0.0, 300.0], [2000.0, 0.0], [100.0, 10.0], [110.0, 0.0]])
    penalty = np.array([1e5, 10.0, 1e9, 1e5, 1e5])
    sol = solve_routes(start, end, pts, penalty, np.array([1000.0]), deterministic=True)
    assert set(sol.routes[0]) == {0, 3, 4}
    assert sol.dropped_px == pytest.approx(10.0 + 1e9)
    assert sol.objective_px == pytest.approx(sol.travel_px + sol.dropped_px, abs=1.0)
    capped = solve_routes(
        start, end, pts, penalty, np.array([1000.0]), capacity=np.array([2]), deterministic=True
    )
    assert len(capped.routes[0]) == 2
    assert set(capped.routes[0]) <= {0, 3, 4}


def test_solve_routes_respects_allowed_vehicles_and_empty_inputs():
    """A node only one vehicle may serve goes to that vehicle; no nodes or no vehicles give
    empty routes."""
    start = end = np.array([[0.0, 0.0], [1000.0, 0.0]])
    pts = np.array([[990.0, 0.0]])
    allowed = np.array([[True], [False]])
    sol = solve_routes(start, end, pts, np.array([1e6]), np.array([5000.0, 5000.0]),
                       allowed=allowed, deterministic=True)  # fmt: skip
    assert sol.routes == ((0,), ())
    empty = solve_routes(start, end, np.zeros((0, 2)), np.zeros(0), np.array([1.0, 1.0]))
    assert empty.routes == ((), ()) and empty.objective_px == 0.0


# ---------------------------------------------------------------------------- reproducibility
@pytest.mark.parametrize("name", [1, 9, 21, "open_world_example"])
def test_deterministic_mode_gives_identical_plans(name):
    """In deterministic mode the same graph gives the same routes, altitudes and objective."""
    for g in episode_graphs(name, TICKS):
        a, b = plan_of(g, deterministic=True), plan_of(g, deterministic=True)
        assert dict(a.routes) == dict(b.routes)
        assert dict(a.altitudes) == dict(b.altitudes)
        assert a.stats.objective == b.stats.objective


def test_deterministic_mode_on_a_synthetic_graph():
    """Deterministic mode is reproducible on a 6 x 30 synthetic graph too."""
    g = synthetic_task_graph(6, 30, np.random.default_rng(7))
    a, b = plan_of(g, deterministic=True), plan_of(g, deterministic=True)
    assert dict(a.routes) == dict(b.routes) and a.stats.objective == b.stats.objective


@pytest.mark.parametrize("name", [1, 12, 21, "open_world_example"])
def test_one_millisecond_limit_never_crashes(name):
    """With a 1 ms limit, :func:`fcplan.scheduling.solve` returns a valid plan: routing's own
    (feasible or time_limit) or greedy's, recorded as a fallback with the reason."""
    sched = make_scheduler("routing")
    graphs = list(episode_graphs(name, TICKS)) + [
        synthetic_task_graph(6, 30, np.random.default_rng(1))
    ]
    for g in graphs:
        plan = solve(sched, g, time_limit=0.001, rng=np.random.default_rng(0))
        validate_plan(plan, g)
        assert plan.stats.status in ("feasible", "time_limit", "fallback")
        assert plan.stats.time_limit_s == 0.001
        if plan.stats.status == "fallback":
            assert plan.stats.message


def test_exhausted_limit_is_rescued_or_raises():
    """When the wall-time limit ends the search before any solution, ``solve_routes`` returns
    the first-solution heuristic's feasible routes flagged ``rescued`` with status
    ``time_limit`` (default), or raises :class:`RoutingFailedError` with ``rescue=False``; the
    scheduler's failure becomes a recorded greedy fallback in :func:`fcplan.scheduling.solve`."""
    rng = np.random.default_rng(0)
    start = rng.uniform(0, 1000, (3, 2))
    pts = rng.uniform(0, 1000, (30, 2))
    args = (start, start, pts, np.full(30, 500.0), np.full(3, 5000.0))
    sol = solve_routes(*args, time_limit=1e-6, max_visits=4)
    assert sol.rescued and sol.status == "time_limit"
    assert all(len(r) <= 4 for r in sol.routes)
    with pytest.raises(RoutingFailedError, match="no routing solution"):
        solve_routes(*args, time_limit=1e-6, rescue=False)
    g = known_fire_graph()
    plan = solve(RoutingScheduler(rescue=False), g, time_limit=1e-6, rng=rng)
    validate_plan(plan, g)
    assert plan.stats.status == "fallback"
    assert "RoutingFailedError" in plan.stats.message


def test_registry_and_settings():
    """``make_scheduler("routing")`` builds the scheduler, passes settings, and rejects unknown
    settings and OR-Tools strategy names."""
    s = make_scheduler("routing", time_limit=0.05, max_visits=3, deterministic=True)
    assert s.name == "routing" and s.time_limit == 0.05 and s.max_visits == 3 and s.deterministic
    with pytest.raises(FcplanError):
        make_scheduler("routing", no_such_setting=1)
    with pytest.raises(ValueError, match="first_solution"):
        RoutingScheduler(first_solution="NOPE")
    with pytest.raises(ValueError, match="metaheuristic"):
        RoutingScheduler(metaheuristic="NOPE")


def test_stats_report_size_and_objective():
    """The plan carries SolveStats with the model size and a finite objective in px."""
    g = known_fire_graph()
    plan = plan_of(g, **FAST)
    s = plan.stats
    assert s.size["models"] == 2
    assert s.size["vehicles"] == g.n_agents
    assert s.size["nodes"] > 0 and s.size["dimensions"] >= 2
    assert np.isfinite(s.objective) and s.objective > 0


def test_episode_completes_and_prunes_fire():
    """An episode of scenario #1 with the routing scheduler (20 ms per replan to keep the test
    short) completes without fallbacks and puts fire out (OFS > 0)."""
    r = fcplan.run_episode(1, "routing", seed=0, time_limit=0.02)
    assert r.fallbacks == 0
    assert r.metrics["manual"].overall_firefighting > 0
