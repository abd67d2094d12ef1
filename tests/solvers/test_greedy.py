"""Tests for solvers.greedy: valid, feasible, role-respecting, deterministic plans."""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.plan import Plan, validate_plan
from fcplan.taskgraph import TaskGraph, TaskKind, build_task_graph, synthetic_task_graph
from fcplan.team import DRAIN_PER_PX, Command, Mode
from solvers.greedy import GreedyScheduler
from tests.solvers.graphs import SCENARIOS
from tests.solvers.graphs import episode_graphs as _episode_graphs

#: every shipped scenario, plus the open-world example (hybrids, 1000 px map)
#: replan ticks at which graphs are taken from a greedy episode
TICKS = (0, 100, 300, 600)


def episode_graphs(name) -> tuple[TaskGraph, ...]:
    """Task graphs at :data:`TICKS` of a greedy episode."""
    return _episode_graphs(name, TICKS)


def greedy_plan(g: TaskGraph, **settings) -> Plan:
    return GreedyScheduler(**settings).plan(g, time_limit=None, rng=np.random.default_rng(0))


def check_greedy_plan(g: TaskGraph, plan: Plan) -> None:
    validate_plan(plan, g)
    fire_owner: dict[str, str] = {}
    for a, route in plan.routes.items():
        i = g.agent_index[a]
        kinds = [g.task_kind[g.task_index[t]] for t in route]
        assert g.agent_mode[i] != Mode.HOMING, f"{a} is homing but routed"
        assert len(set(route)) == len(route), f"{a} visits a task twice"
        if any(k == TaskKind.SEARCH for k in kinds):
            assert g.agent_can_sense[i], f"{a} cannot sense but got a search task"
        n_fire = sum(k == TaskKind.FIRE for k in kinds)
        if g.agent_can_act[i]:
            assert n_fire <= g.agent_tank[i], f"{a}: {n_fire} fires for tank {g.agent_tank[i]}"
            for t, k in zip(route, kinds, strict=True):
                if k == TaskKind.FIRE:
                    assert t not in fire_owner, f"{t} given to {fire_owner.get(t)} and {a}"
                    fire_owner[t] = a
        need, have = g.route_length_px(i, route), g.agent_budget_px[i]
        assert g.route_ok(i, route), f"{a}: route + way home {need:.1f} px > {have:.1f} px"
    for a, z in plan.altitudes.items():
        i = g.agent_index[a]
        lo, hi = g.agent_alt_range[i]
        assert lo <= z <= hi, (a, z)
    assert not plan.home and not plan.patrol


@pytest.mark.parametrize("name", SCENARIOS)
def test_greedy_plans_are_valid_and_feasible(name):
    """On graphs from every shipped scenario, greedy's plan validates; each fire task goes to
    at most one action agent; no acting agent gets more fires than its tank; every route plus
    the way home fits the agent's battery from its start; search tasks only go to agents with a
    camera; altitudes are within bounds."""
    for g in episode_graphs(name):
        check_greedy_plan(g, greedy_plan(g))


@pytest.mark.parametrize("name", SCENARIOS)
def test_greedy_is_deterministic(name):
    """The same graph gives the same plan (greedy does not use the generator)."""
    for g in episode_graphs(name):
        a = GreedyScheduler().plan(g, time_limit=None, rng=np.random.default_rng(1))
        b = GreedyScheduler().plan(g, time_limit=0.01, rng=np.random.default_rng(2))
        assert dict(a.routes) == dict(b.routes)
        assert dict(a.altitudes) == dict(b.altitudes)


@pytest.mark.parametrize("name", SCENARIOS)
def test_without_known_fire_perception_agents_search_distinct_blocks(name):
    """At the start (nothing known), every perception agent is sent to search blocks, no block
    is given twice, and action-only agents stay put."""
    g = episode_graphs(name)[0]
    assert g.fire_tasks.size == 0
    plan = greedy_plan(g)
    check_greedy_plan(g, plan)
    taken: list[str] = []
    for i, a in enumerate(g.agent_ids):
        route = plan.routes.get(a, ())
        if g.agent_can_sense[i]:
            assert route, f"{a} has nothing to search"
            assert all(t.startswith("search:") for t in route)
            taken.extend(route)
        else:
            assert not route
    assert len(taken) == len(set(taken))
    firsts = [plan.routes[a][0] for a in plan.routes]
    assert len(firsts) == len(set(firsts))


@pytest.mark.parametrize("tank", [1, 2, 5])
def test_route_never_exceeds_the_tank(tank):
    """With many fires known and small tanks, no action agent gets more fire tasks than its
    tank holds."""
    g = known_fire_graph()
    g = dataclasses.replace(g, agent_tank=np.where(g.agent_can_act, tank, 0).astype(np.int64))
    plan = greedy_plan(g, route_length=10)
    check_greedy_plan(g, plan)
    n = [len(plan.routes.get(a, ())) for i, a in enumerate(g.agent_ids) if g.agent_can_act[i]]
    assert max(n) <= tank
    # every fire is within reach, so the tanks are used up before the fires run out
    assert sum(n) == min(g.fire_tasks.size, tank * len(n))


def test_route_respects_a_low_battery():
    """An active agent low on battery only gets tasks it can reach and still fly home from."""
    g = known_fire_graph()
    bat = g.agent_battery.copy()
    mode = g.agent_mode.copy()
    acting = np.flatnonzero(g.agent_can_act)
    bat[acting] = DRAIN_PER_PX * (g.task_home_distance[acting].min(axis=1) * 2 + 5.0)
    mode[acting] = Mode.ACTIVE
    g = dataclasses.replace(g, agent_battery=bat, agent_mode=mode)
    plan = greedy_plan(g)
    check_greedy_plan(g, plan)


@lru_cache(maxsize=1)
def known_fire_graph() -> TaskGraph:
    """Scenario #1 (own fire delayed) with a hand-lit 120 x 60 px fire at (450, 550) that P1 is
    watching from 100 m; the action agents wait at the depot."""
    sc = load_scenario(1)
    sc = sc.replace(regions=tuple(dataclasses.replace(r, delay_s=10_000.0) for r in sc.regions))
    world = World().reset(sc, seed=0)
    xs, ys = np.meshgrid(np.arange(390, 511, 2), np.arange(520, 581, 2), indexing="ij")
    world.ignite(np.stack([xs.ravel(), ys.ravel()], axis=1))
    belief = Belief(sc)
    cmd = {"P1": Command(route=((450.0, 550.0),), altitude=100.0)}
    for _ in range(40):
        belief.update(world.step(cmd))
        cmd = None
    g = build_task_graph(sc, world.team, belief)
    assert g.fire_tasks.size >= 4
    return g


def test_known_fire_gets_an_action_agent():
    """With known fire and idle action agents at the depot, greedy routes action agents to fire
    tasks, the most valuable reachable fire first among them, and a perception agent watches."""
    g = known_fire_graph()
    plan = greedy_plan(g)
    check_greedy_plan(g, plan)
    fire_ids = {g.task_ids[k] for k in g.fire_tasks}
    actors = [a for i, a in enumerate(g.agent_ids) if g.agent_can_act[i]]
    assert actors
    for a in actors:
        assert plan.routes.get(a), f"{a} is idle although fire is known"
        assert set(plan.routes[a]) <= fire_ids
    watchers = [
        a
        for i, a in enumerate(g.agent_ids)
        if g.agent_can_sense[i] and set(plan.routes.get(a, ())) & fire_ids
    ]
    assert watchers


def test_single_known_fire_is_taken_by_an_action_agent():
    """When exactly one fire task is known, exactly one action agent is sent to it."""
    g = known_fire_graph()
    keep = np.r_[g.fire_tasks[:1], g.search_tasks]
    g1 = dataclasses.replace(
        g,
        task_ids=tuple(g.task_ids[k] for k in keep),
        task_kind=g.task_kind[keep],
        task_pos=g.task_pos[keep],
        task_value=g.task_value[keep],
        task_cells=g.task_cells[keep],
        task_staleness=g.task_staleness[keep],
        task_threat=g.task_threat[keep],
        task_cluster=g.task_cluster[keep],
        task_block=np.where(
            g.task_block[keep] >= 0, g.task_block[keep] - (g.fire_tasks.size - 1), -1
        ),
        threat_time_s=g.threat_time_s[:1],
    )
    plan = greedy_plan(g1)
    check_greedy_plan(g1, plan)
    fire = g1.task_ids[0]
    acting = [a for i, a in enumerate(g1.agent_ids) if g1.agent_can_act[i]]
    assert sum(fire in plan.routes.get(a, ()) for a in acting) == 1


@pytest.mark.parametrize("name", SCENARIOS)
def test_episode_graphs_with_fire_dispatch_action_agents(name):
    """Whenever fire is known, not too stale, and an action agent sits idle at the depot with
    water and a full battery, greedy gives some action agent a fire task."""
    for g in episode_graphs(name):
        fresh = g.fire_tasks[g.task_staleness[g.fire_tasks] <= 5.0]
        idle = (
            g.agent_can_act
            & (g.agent_mode == Mode.IDLE)
            & (g.agent_tank > 0)
            & (g.agent_battery >= 0.999 * g.agent_full_range * DRAIN_PER_PX)
        )
        if fresh.size == 0 or not idle.any():
            continue
        if not g.in_round_trip[np.ix_(np.flatnonzero(idle), fresh)].any():
            continue
        plan = greedy_plan(g)
        fire_ids = {g.task_ids[k] for k in g.fire_tasks}
        assert any(
            set(plan.routes.get(a, ())) & fire_ids
            for i, a in enumerate(g.agent_ids)
            if g.agent_can_act[i]
        ), f"{name} tick {g.tick}: known fire but no action agent sent"


def _naive_assign(graph, agents, tasks, value, start, budget, limit, spread, spread_px):
    """The greedy pick loop written plainly: rebuild the whole score matrix before every pick."""
    value = value.astype(float).copy()
    pos = start[agents].copy()
    used = np.zeros(agents.size)
    elapsed = np.zeros(agents.size)
    count = np.zeros(agents.size, dtype=int)
    taken = np.zeros(tasks.size, dtype=bool)
    home = graph.task_home_distance[np.ix_(agents, tasks)]
    ok = graph.in_round_trip[np.ix_(agents, tasks)]
    routes = {int(a): [] for a in agents}
    tpos = graph.task_pos[tasks]
    while True:
        diff = pos[:, None, :] - tpos[None, :, :]
        d = np.sqrt(np.einsum("akc,akc->ak", diff, diff))
        eta = elapsed[:, None] + d / graph.agent_speed[agents][:, None]
        feas = (
            ok
            & ~taken[None, :]
            & (count < limit)[:, None]
            & (used[:, None] + d + home <= budget[agents][:, None])
            & (value[None, :] > 0)
        )
        score = np.where(feas, value[None, :] / (1 + eta), -np.inf)
        a, k = divmod(int(np.argmax(score)), tasks.size)
        if not np.isfinite(score[a, k]):
            return routes
        routes[int(agents[a])].append(int(tasks[k]))
        taken[k] = True
        count[a] += 1
        used[a] += d[a, k]
        elapsed[a] = eta[a, k]
        pos[a] = tpos[k]
        if spread:
            near = np.hypot(*(tpos - tpos[k]).T) < spread_px
            value[near] *= 0.3


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 8),
    n_tasks=st.integers(1, 60),
    spread=st.booleans(),
)
def test_incremental_picks_equal_full_recomputation(seed, n_agents, n_tasks, spread):
    """Greedy's incremental score updates pick exactly what rebuilding the whole (agent, task)
    score matrix before every pick would pick."""
    g = synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(seed))
    sched = GreedyScheduler()
    agents = np.arange(g.n_agents)
    tasks = np.arange(g.n_tasks)
    limit = np.full(g.n_agents, 3)
    start, budget = g.agent_start_pos, g.agent_budget_px
    fast, _ = sched._assign(g, agents, tasks, g.task_value, limit=limit, spread=spread)
    slow = _naive_assign(
        g, agents, tasks, g.task_value, start, budget, limit, spread, sched.spread_px
    )
    assert fast == slow


# ------------------------------------------------------------------ settings
@pytest.mark.parametrize(
    "setting, bad",
    [
        ("route_length", 0),
        ("route_length", 1001),
        ("route_length", 2.0),
        ("route_length", True),
        ("search_route_length", 0),
        ("fresh_s", 0.0),
        ("fresh_s", float("nan")),
        ("watch_altitude", -5.0),
        ("search_altitude", float("inf")),
        ("max_watch_fraction", -0.1),
        ("max_watch_fraction", float("nan")),
        ("spread_px", "wide"),
    ],
)
def test_meaningless_settings_are_refused_at_construction(setting, bad):
    """Every setting is checked at construction: wrong types, NaN and values outside the
    documented range (e.g. route_length=0, which used to score -108 silently) raise a
    SettingError naming the setting."""
    from fcplan.scheduling import SettingError

    with pytest.raises(SettingError) as exc:
        GreedyScheduler(**{setting: bad})
    assert exc.value.setting == setting and "\n" not in str(exc.value)


def test_settings_at_the_edges_of_their_ranges_are_accepted():
    """The ends of each documented range are valid settings and give valid plans."""
    g = synthetic_task_graph(6, 20, np.random.default_rng(3))
    for kw in (
        dict(route_length=1, search_route_length=1, max_watch_fraction=0.0, spread_px=0.0),
        dict(route_length=1000, search_route_length=1000, max_watch_fraction=1.0),
    ):
        validate_plan(GreedyScheduler(**kw).plan(g, rng=None), g)
