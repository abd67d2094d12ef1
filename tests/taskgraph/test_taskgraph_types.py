"""Tests for fcplan.taskgraph.types: numpy and networkx views, distances, and the feasibility
rule's views against their plain definitions."""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.taskgraph import (
    FEASIBILITY_TOL_PX,
    SharedMemo,
    TaskGraph,
    TaskKind,
    synthetic_task_graph,
)
from fcplan.team import DRAIN_PER_PX, Mode
from tests.taskgraph.worlds import (
    block_cells,
    fire_far_away,
    fire_near_house,
    graph_of,
    hover_world,
    quiet_scenario,
)

SETTINGS = settings(max_examples=30, deadline=None)


# ---------------------------------------------------------------------- views
def test_numpy_and_networkx_views_agree():
    """The networkx view has one node per entry of node_ids (agents, depot, tasks, facilities)
    at the same positions and with the same kinds as the numpy arrays; ``can_do`` edges match
    the can_do matrix."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    G = g.graph
    n_fac = len(g.facility_kinds)
    assert G.number_of_nodes() == len(g.node_ids) == g.n_agents + 1 + g.n_tasks + n_fac
    assert g.positions.shape == (len(g.node_ids), 2)
    for row, nid in enumerate(g.node_ids):
        np.testing.assert_allclose(G.nodes[nid]["pos"], g.positions[row])
    kinds = [G.nodes[n]["kind"] for n in g.node_ids]
    assert kinds == (
        ["agent"] * g.n_agents
        + ["depot"]
        + ["fire" if k == TaskKind.FIRE else "search" for k in g.task_kind]
        + ["facility"] * n_fac
    )
    for k, t in enumerate(g.task_ids):
        assert G.nodes[t]["cells"] == g.task_cells[k]
    np.testing.assert_allclose(G.nodes["depot"]["pos"], world.scenario.depot.center)
    can = [(a, t) for a, t, d in G.edges(data=True) if d["kind"] == "can_do"]
    assert len(can) == int(g.can_do.sum())
    for a, t in can:
        assert g.can_do[g.agent_index[a], g.task_index[t]]
    for a, t, d in G.edges(data=True):
        if d["kind"] == "can_do":
            i, k = g.agent_index[a], g.task_index[t]
            assert d["time_s"] == pytest.approx(g.agent_task_distance[i, k] / g.agent_speed[i])


points = st.lists(
    st.tuples(st.floats(0, 1199, allow_nan=False), st.floats(0, 1199, allow_nan=False)),
    min_size=1,
    max_size=8,
)


@lru_cache(maxsize=1)
def base_graph() -> TaskGraph:
    world, belief = fire_far_away()
    return graph_of(world, belief)


@SETTINGS
@given(agents=points, tasks=points)
def test_distances_are_straight_lines(agents, tasks):
    """agent_task_distance[i, k] is the Euclidean distance between agent i and task k;
    task_distance is the symmetric Euclidean matrix with a zero diagonal."""
    g0 = base_graph()
    a = np.array(agents, dtype=np.float64)
    t = np.array(tasks, dtype=np.float64)
    n_a, n_t = len(a), len(t)
    g = dataclasses.replace(
        g0,
        agent_ids=tuple(f"X{i}" for i in range(n_a)),
        agent_pos=a,
        agent_home=np.zeros((n_a, 2)),
        agent_speed=np.full(n_a, 200.0),
        agent_can_sense=np.ones(n_a, bool),
        task_ids=tuple(f"t{k}" for k in range(n_t)),
        task_pos=t,
        task_kind=np.full(n_t, TaskKind.SEARCH, np.int8),
    )
    d = g.agent_task_distance
    assert d.shape == (n_a, n_t)
    for i in range(n_a):
        for k in range(n_t):
            assert d[i, k] == pytest.approx(math.dist(a[i], t[k]), abs=1e-9)
            assert g.task_home_distance[i, k] == pytest.approx(math.hypot(*t[k]), abs=1e-9)
    td = g.task_distance
    np.testing.assert_allclose(td, td.T)
    np.testing.assert_allclose(np.diag(td), 0.0, atol=1e-9)
    np.testing.assert_allclose(g.agent_task_time, d / 200.0)


def test_agent_task_distance_from_the_real_team():
    """On a built graph, agent_task_distance equals the distance from the team's positions."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    exp = np.hypot(
        world.team.pos[:, None, 0] - g.task_pos[None, :, 0],
        world.team.pos[:, None, 1] - g.task_pos[None, :, 1],
    )
    np.testing.assert_allclose(g.agent_task_distance, exp, atol=1e-9)
    np.testing.assert_allclose(g.agent_pos, world.team.pos)


@pytest.mark.parametrize("name", [1, "open_world_example"])
def test_can_do_forbids_search_for_action_only_agents(name):
    """Action-only agents can do fire tasks only; perception and hybrid agents can do
    everything."""
    if name == 1:
        world, belief = fire_near_house()
    else:
        sc = quiet_scenario(name)
        world, belief = hover_world(block_cells((500, 500)), (500, 500), scenario=sc)
    g = graph_of(world, belief)
    from fcplan.scenario import Role

    fire = g.task_kind == TaskKind.FIRE
    assert fire.any() and (~fire).any()
    for i in range(g.n_agents):
        role = Role(int(g.agent_role[i]))
        if role is Role.ACTION:
            assert not g.can_do[i, ~fire].any()
            assert g.can_do[i, fire].all()
            assert not g.agent_can_sense[i]
        else:
            assert g.can_do[i].all()


# ---------------------------------------------------------------------- feasibility
def graph_with_modes(seed: int, n_agents: int, n_tasks: int) -> TaskGraph:
    """A synthetic graph with a random battery and random agent modes (forced returns too)."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, n_tasks, rng, battery=float(rng.uniform(60.0, 600.0)))
    mode = rng.choice([int(m) for m in Mode], size=n_agents).astype(np.int8)
    return dataclasses.replace(g, agent_mode=mode)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 7), n_tasks=st.integers(0, 30))
def test_feasibility_views_follow_their_definitions(seed, n_agents, n_tasks):
    """Pair by pair: a route starts at the depot slot with a full battery on a forced return,
    else where the agent is with battery / DRAIN_PER_PX px; a task is in round trip when twice
    its way home fits a full battery; it is reachable when the role fits, it is in round trip,
    and (unless on a forced return) the agent can fly there and home on what it has left."""
    g = graph_with_modes(seed, n_agents, n_tasks)
    for i in range(g.n_agents):
        forced = g.agent_mode[i] == Mode.RETURNING
        start = g.agent_home[i] if forced else g.agent_pos[i]
        budget = g.agent_full_range[i] if forced else g.agent_battery[i] / DRAIN_PER_PX
        assert np.array_equal(g.agent_start_pos[i], start)
        assert g.agent_budget_px[i] == budget
        for k in range(g.n_tasks):
            home = math.dist(g.task_pos[k], g.agent_home[i])
            there = math.dist(g.task_pos[k], g.agent_pos[i])
            assert g.start_task_distance[i, k] == pytest.approx(math.dist(start, g.task_pos[k]))
            in_trip = 2.0 * home <= g.agent_full_range[i] + FEASIBILITY_TOL_PX
            assert g.in_round_trip[i, k] == pytest.approx(in_trip)
            role = g.task_kind[k] == TaskKind.FIRE or g.agent_can_sense[i]
            battery = there + home <= g.agent_battery[i] / DRAIN_PER_PX + FEASIBILITY_TOL_PX
            assert g.reachable[i, k] == (role and in_trip and (forced or battery))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 6), length=st.integers(0, 4))
def test_route_ok_is_the_route_length_within_the_budget(seed, n_agents, length):
    """route_length_px is the length of the polyline start -> tasks -> depot slot (by task row
    or id alike), and route_ok says whether it fits the agent's budget."""
    g = graph_with_modes(seed, n_agents, 12)
    rng = np.random.default_rng(seed)
    for i in range(g.n_agents):
        rows = [int(k) for k in rng.integers(0, g.n_tasks, length)]
        pts = [g.agent_start_pos[i], *g.task_pos[rows], g.agent_home[i]]
        want = sum(math.dist(p, q) for p, q in zip(pts[:-1], pts[1:], strict=True))
        ids = [g.task_ids[k] for k in rows]
        assert g.route_length_px(i, rows) == pytest.approx(want, abs=1e-9)
        assert g.route_length_px(g.agent_ids[i], ids) == g.route_length_px(i, rows)
        fits = g.route_length_px(i, rows) <= g.agent_budget_px[i] + FEASIBILITY_TOL_PX
        assert g.route_ok(i, rows) == g.route_ok(g.agent_ids[i], ids) == fits
    if length == 1:  # a one-task route the rule allows is flyable as a whole
        for i, k in np.argwhere(g.reachable):
            assert g.route_ok(int(i), [int(k)])


def test_clip_altitude_keeps_within_bounds():
    """clip_altitude returns z inside the agent's bounds, the nearest bound outside them."""
    g = synthetic_task_graph(3, 4, np.random.default_rng(0))
    for i in range(g.n_agents):
        lo, hi = g.agent_alt_range[i]
        assert g.clip_altitude(i, -5.0) == lo
        assert g.clip_altitude(i, 1e6) == hi
        assert g.clip_altitude(i, (lo + hi) / 2) == (lo + hi) / 2
        assert type(g.clip_altitude(i, 50)) is float


def test_builder_graphs_keep_shared_views_read_only():
    """On a graph of a builder without known fire, the round-trip views come from the builder's
    memo (the same read-only array for the next graph); a replaced graph has no memo and
    computes its own, equal, views."""
    from fcplan import World, load_scenario
    from fcplan.belief import Belief
    from fcplan.taskgraph import TaskGraphBuilder

    world = World().reset(load_scenario(1), seed=0)
    builder = TaskGraphBuilder(world.scenario)
    belief = Belief(world.scenario)
    a = builder.build(world.team, belief)
    b = builder.build(world.team, belief)
    assert a.in_round_trip is b.in_round_trip and not a.in_round_trip.flags.writeable
    c = dataclasses.replace(a)
    assert c.shared_memo is None and c.in_round_trip is not a.in_round_trip
    assert np.array_equal(c.in_round_trip, a.in_round_trip)
    assert np.array_equal(c.reachable, a.reachable)


def test_shared_memo_keeps_values_of_read_only_inputs_only():
    """The memo returns the kept value for the very same read-only inputs, makes it again for
    other arrays, and keeps nothing made from a writable array."""
    a = np.arange(4.0)
    a.flags.writeable = False
    memo = SharedMemo()
    first = memo.get("double", (a,), lambda: a * 2)
    assert not first.flags.writeable
    assert memo.get("double", (a,), lambda: a * 3) is first
    b = a.copy()  # equal values, another array
    assert np.array_equal(memo.get("double", (b,), lambda: b * 3), a * 3)
    assert np.array_equal(memo.get("double", (b,), lambda: b * 4), a * 4)  # writable: not kept


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 7), n_tasks=st.integers(1, 30))
def test_pair_views_equal_the_tables(seed, n_agents, n_tasks):
    """in_round_trip_at and reachable_at at any (agent, task) pairs are the tables' entries,
    whether the table was computed before or not."""
    g = graph_with_modes(seed, n_agents, n_tasks)
    rng = np.random.default_rng(seed)
    ai = rng.integers(0, n_agents, 20)
    ti = rng.integers(0, n_tasks, 20)
    fresh = dataclasses.replace(g)
    assert np.array_equal(fresh.reachable_at(ai, ti), g.reachable[ai, ti])
    assert np.array_equal(fresh.in_round_trip_at(ai, ti), g.in_round_trip[ai, ti])
    assert np.array_equal(g.reachable_at(ai, ti), g.reachable[ai, ti])  # from the table
