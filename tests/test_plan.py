"""Tests for fcplan.plan: plan validation (PlanError naming the agent/task) and plan_commands."""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.errors import FcplanError, PlanError
from fcplan.plan import Plan, plan_commands, validate_plan
from fcplan.scenario import Role
from fcplan.taskgraph import TaskGraph, TaskKind, build_task_graph
from fcplan.team import Command, Mode


def graph_for(scenario, *, ticks: int = 0, commands=None, ignite=None) -> TaskGraph:
    """Task graph of ``scenario`` after ``ticks`` ticks (``commands`` applied on the first)."""
    world = World().reset(scenario, seed=0)
    if ignite is not None:
        world.ignite(ignite)
    belief = Belief(scenario)
    for _ in range(ticks):
        belief.update(world.step(commands))
        commands = None
    return build_task_graph(scenario, world.team, belief)


@lru_cache(maxsize=1)
def start_graph() -> TaskGraph:
    """Scenario #1 at tick 0: everyone at the depot, no known fire."""
    return graph_for(load_scenario(1))


@lru_cache(maxsize=1)
def fire_graph() -> TaskGraph:
    """Scenario #1 (own fire delayed) with a hand-lit fire at (500, 500) that P1 has sensed."""
    sc = load_scenario(1)
    sc = sc.replace(regions=tuple(dataclasses.replace(r, delay_s=10_000.0) for r in sc.regions))
    xs, ys = np.meshgrid(np.arange(470, 531, 2), np.arange(480, 521, 2), indexing="ij")
    cells = np.stack([xs.ravel(), ys.ravel()], axis=1)
    g = graph_for(
        sc,
        ticks=40,
        commands={"P1": Command(route=((500.0, 500.0),), altitude=100.0)},
        ignite=cells,
    )
    assert g.fire_tasks.size > 0
    return g


@lru_cache(maxsize=1)
def tiny_battery_graph() -> TaskGraph:
    """Scenario #1 where every agent has a battery of 50 (500 px of flight)."""
    sc = load_scenario(1)
    sc = sc.replace(agents=tuple(dataclasses.replace(a, battery=50.0) for a in sc.agents))
    return graph_for(sc)


def raises_naming(plan: Plan, graph: TaskGraph, *names: str) -> PlanError:
    with pytest.raises(PlanError) as exc:
        validate_plan(plan, graph)
    msg = str(exc.value)
    for n in names:
        assert n in msg, (n, msg)
    assert "\n" not in msg
    assert isinstance(exc.value, FcplanError)
    return exc.value


# ---------------------------------------------------------------------- rejections
def test_unknown_agent_is_rejected():
    """A route, altitude, patrol or home entry for an agent not in the graph raises PlanError
    naming it."""
    g = start_graph()
    raises_naming(Plan(routes={"Z9": ("search:A-01",)}), g, "Z9")
    raises_naming(Plan(altitudes={"P7": 50.0}), g, "P7")
    raises_naming(Plan(patrol=frozenset({"Q1"})), g, "Q1")
    raises_naming(Plan(home=frozenset({"A3"})), g, "A3")


def test_unknown_task_is_rejected():
    """A route with a task id that is not in the graph raises PlanError naming agent and task."""
    g = start_graph()
    raises_naming(Plan(routes={"P1": ("search:A-01", "search:Z-99")}), g, "P1", "search:Z-99")
    raises_naming(Plan(routes={"A1": ("fire:1:1",)}), g, "A1", "fire:1:1")


def test_search_task_for_action_agent_is_rejected():
    """A search block in an action agent's route raises PlanError naming agent and task."""
    g = start_graph()
    raises_naming(Plan(routes={"A1": ("search:B-05",)}), g, "A1", "search:B-05")
    g = fire_graph()
    fire = g.task_ids[g.fire_tasks[0]]
    raises_naming(Plan(routes={"A2": (fire, "search:E-05")}), g, "A2", "search:E-05")


@pytest.mark.parametrize("z", [5.0, 9.9, 100.5, 500.0, float("nan"), float("inf"), -30.0])
def test_altitude_outside_bounds_is_rejected(z):
    """A perception agent's altitude outside its bounds (10..100 m in #1), or not finite,
    raises PlanError naming the agent."""
    raises_naming(Plan(altitudes={"P2": z}), start_graph(), "P2")


@pytest.mark.parametrize("z", [10.0, 55.5, 100.0])
def test_altitude_at_or_within_bounds_is_accepted(z):
    """Altitudes within the agent's bounds, including both ends, are accepted."""
    validate_plan(Plan(altitudes={"P1": z}), start_graph())


def test_routed_and_sent_home_is_rejected():
    """An agent both given a (non-empty) route and sent home raises PlanError naming it; an
    empty route with home is fine."""
    g = start_graph()
    raises_naming(Plan(routes={"P1": ("search:B-05",)}, home=frozenset({"P1", "A1"})), g, "P1")
    validate_plan(Plan(routes={"P1": ()}, home=frozenset({"P1"})), g)


def test_task_beyond_full_battery_round_trip_is_rejected():
    """With a 500 px battery, a task more than 250 px from the agent's depot slot raises
    PlanError naming agent and task; a nearby one is accepted."""
    g = tiny_battery_graph()
    assert np.allclose(g.agent_full_range, 500.0)
    raises_naming(Plan(routes={"P1": ("search:L-12",)}), g, "P1", "search:L-12")
    # the far task later in the route is caught too
    raises_naming(Plan(routes={"P2": ("search:A-05", "search:E-05")}), g, "P2", "search:E-05")
    validate_plan(Plan(routes={"P1": ("search:A-05", "search:B-05")}), g)


def test_first_task_beyond_remaining_battery_is_rejected():
    """An agent that cannot reach its first task and fly home on its remaining battery is
    rejected, unless it is on a forced return (it recharges first)."""
    g = start_graph()
    low = g.agent_battery.copy()
    i = g.agent_index["P1"]
    low[i] = 20.0  # 200 px of flight left
    weak = dataclasses.replace(g, agent_battery=low)
    plan = Plan(routes={"P1": ("search:D-05",)})
    raises_naming(plan, weak, "P1", "search:D-05")
    validate_plan(Plan(routes={"P1": ("search:A-05",)}), weak)
    mode = g.agent_mode.copy()
    mode[i] = Mode.RETURNING
    validate_plan(plan, dataclasses.replace(weak, agent_mode=mode))


def test_route_given_as_string_is_rejected():
    """A route given as a bare string (not a sequence of ids) raises PlanError naming the agent."""
    raises_naming(Plan(routes={"P1": "search:D-05"}), start_graph(), "P1")


def test_non_plan_is_rejected():
    """Anything that is not a Plan raises PlanError naming its type."""
    raises_naming({"P1": ("search:D-05",)}, start_graph(), "dict")


# ---------------------------------------------------------------------- acceptance
def test_valid_plans_are_accepted():
    """Empty plans, search routes for perception agents, fire routes for action agents,
    patrols and home commands are valid."""
    g = fire_graph()
    fires = [g.task_ids[k] for k in g.fire_tasks]
    validate_plan(Plan(), g)
    validate_plan(
        Plan(
            routes={
                "P1": (fires[0], "search:F-05"),
                "P2": ("search:C-03", "search:C-04"),
                "A1": tuple(fires[:2]),
            },
            altitudes={"P1": 35.0, "P2": 90.0, "A2": 30.0},
            patrol=frozenset({"P2"}),
            home=frozenset({"A2"}),
        ),
        g,
    )


@st.composite
def feasible_plans(draw, graph: TaskGraph):
    """Random plans built only from choices validate_plan must accept (the feasibility views
    of the graph, tested against their definitions in tests/taskgraph)."""
    ok = graph.can_do & graph.in_round_trip
    first_ok = graph.reachable
    routes, alts, home, patrol = {}, {}, set(), set()
    for i, a in enumerate(graph.agent_ids):
        what = draw(st.sampled_from(["skip", "route", "home"]))
        if what == "home":
            home.add(a)
        elif what == "route" and first_ok[i].any():
            first = draw(st.sampled_from(np.flatnonzero(first_ok[i]).tolist()))
            rest = draw(st.lists(st.sampled_from(np.flatnonzero(ok[i]).tolist()), max_size=4))
            routes[a] = tuple(graph.task_ids[k] for k in [first, *rest])
            if draw(st.booleans()):
                patrol.add(a)
        if graph.agent_can_sense[i] and draw(st.booleans()):
            lo, hi = graph.agent_alt_range[i]
            alts[a] = draw(st.floats(float(lo), float(hi)))
    return Plan(routes=routes, altitudes=alts, patrol=frozenset(patrol), home=frozenset(home))


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_feasible_random_plans_are_accepted(data):
    """Any plan whose tasks suit the roles, lie within a full-battery round trip, whose first
    task is reachable on the remaining battery and whose altitudes are in bounds is valid."""
    g = data.draw(st.sampled_from([start_graph(), fire_graph(), tiny_battery_graph()]))
    plan = data.draw(feasible_plans(g))
    validate_plan(plan, g)


# ---------------------------------------------------------------------- commands
def test_plan_commands_maps_tasks_to_positions_in_order():
    """Each route becomes a Command whose goals are the task positions, in route order."""
    g = fire_graph()
    fire = g.task_ids[g.fire_tasks[0]]
    route = ("search:D-05", fire, "search:A-01", "search:L-12")
    cmds = plan_commands(Plan(routes={"P1": route}), g)
    assert set(cmds) == {"P1"}
    assert cmds["P1"].route == (
        (350.0, 450.0),
        tuple(float(v) for v in g.task_pos[g.task_index[fire]]),
        (50.0, 50.0),
        (1150.0, 1150.0),
    )
    assert cmds["P1"].patrol is False and cmds["P1"].home is False
    assert cmds["P1"].altitude is None


def test_plan_commands_passes_altitude_patrol_and_home():
    """Altitudes, patrol flags and home orders reach the commands; an altitude alone gives a
    command that keeps the route (route None); unmentioned agents get no command."""
    g = fire_graph()
    fire = g.task_ids[g.fire_tasks[0]]
    plan = Plan(
        routes={"P1": ("search:B-02", "search:C-02"), "A1": (fire,), "A2": ()},
        altitudes={"P1": 42.0, "P2": 77.0},
        patrol=frozenset({"P1"}),
        home=frozenset({"A2"}),
    )
    validate_plan(plan, g)
    cmds = plan_commands(plan, g)
    assert set(cmds) == {"P1", "P2", "A1", "A2"}
    assert cmds["P1"] == Command(route=((150.0, 150.0), (250.0, 150.0)), patrol=True, altitude=42.0)
    assert cmds["P2"] == Command(route=None, patrol=False, altitude=77.0)
    assert cmds["A1"].route == (tuple(float(v) for v in g.task_pos[g.task_index[fire]]),)
    assert cmds["A1"].patrol is False and cmds["A1"].altitude is None
    assert cmds["A2"].home is True and not cmds["A2"].route
    assert plan_commands(Plan(), g) == {}


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_plan_commands_follow_any_valid_plan(data):
    """For any valid plan: one command per mentioned agent, routes are the task positions in
    order, home agents get home commands, patrol and altitude are carried over."""
    g = data.draw(st.sampled_from([start_graph(), fire_graph()]))
    plan = data.draw(feasible_plans(g))
    cmds = plan_commands(plan, g)
    assert set(cmds) == set(plan.routes) | set(plan.altitudes) | set(plan.home)
    for a, c in cmds.items():
        assert c.altitude == plan.altitudes.get(a)
        if a in plan.home:
            assert c.home
            continue
        assert not c.home
        assert c.patrol == (a in plan.patrol)
        if a in plan.routes:
            exp = [tuple(g.task_pos[g.task_index[t]]) for t in plan.routes[a]]
            assert list(c.route) == exp
        else:
            assert c.route is None


def test_commands_drive_the_world():
    """Commands from a plan are accepted by World.step and move the routed agent toward its
    task."""
    sc = load_scenario(1)
    world = World().reset(sc, seed=0)
    g = build_task_graph(sc, world.team, Belief(sc))
    i = world.team.index("P1")
    before = np.hypot(*(world.team.pos[i] - [350.0, 450.0]))
    world.step(plan_commands(Plan(routes={"P1": ("search:D-05",)}), g))
    after = np.hypot(*(world.team.pos[i] - [350.0, 450.0]))
    assert after < before
    assert g.task_kind[g.task_index["search:D-05"]] == TaskKind.SEARCH
    assert Role(int(g.agent_role[i])) is Role.PERCEPTION


# ---------------------------------------------------------------------- route length cap
def test_routes_longer_than_the_cap_are_refused_before_their_tasks_are_read():
    """A route of more than MAX_ROUTE_LENGTH goals (even of valid tasks, even 10^6 of them) and
    a route that is not a sized sequence (a generator) raise one-line PlanErrors naming the
    agent; a route of exactly MAX_ROUTE_LENGTH valid goals passes."""
    from fcplan.plan import MAX_ROUTE_LENGTH

    g = start_graph()
    p1 = "P1"
    task = g.task_ids[int(np.flatnonzero(g.reachable[g.agent_index[p1]])[0])]
    validate_plan(Plan(routes={p1: (task,) * MAX_ROUTE_LENGTH}), g)
    raises_naming(Plan(routes={p1: (task,) * (MAX_ROUTE_LENGTH + 1)}), g, p1, "MAX_ROUTE_LENGTH")
    raises_naming(Plan(routes={p1: ("no-such-task",) * 10**6}), g, p1, "1000000 tasks")
    raises_naming(Plan(routes={p1: (t for t in [task])}), g, p1, "sequence")


def test_solve_falls_back_on_a_runaway_route():
    """solve() turns a scheduler's over-long route into a greedy fallback that names the cap."""
    from fcplan.plan import MAX_ROUTE_LENGTH
    from fcplan.scheduling import solve

    g = start_graph()
    task = g.task_ids[int(np.flatnonzero(g.reachable[g.agent_index["P1"]])[0])]

    class Runaway:
        name = "runaway"

        def plan(self, graph, *, time_limit, rng):
            return Plan(routes={"P1": (task,) * (10 * MAX_ROUTE_LENGTH)})

    out = solve(Runaway(), g, time_limit=None, rng=np.random.default_rng(0))
    assert out.stats.status == "fallback" and "MAX_ROUTE_LENGTH" in out.stats.message
