"""Tests for solvers.cbba: conflict-free, convergent, consistent, valid, deterministic plans."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fcplan
from fcplan.plan import Plan, validate_plan
from fcplan.taskgraph import TaskGraph, TaskKind, synthetic_task_graph
from fcplan.team import Mode
from solvers.cbba import CBBAResult, CBBAScheduler, communication_graph
from tests.solvers.graphs import SCENARIOS, episode_graphs

#: replan ticks of the greedy episodes the real graphs come from (shared with test_greedy)
TICKS = (0, 100, 300, 600)
#: comm ranges for synthetic graphs: unlimited, larger than the map, small enough to split teams
COMM_RANGES = [None, 5000.0, 150.0]


def check_result(g: TaskGraph, res: CBBAResult, plan: Plan, cbba: CBBAScheduler) -> None:
    """Everything a CBBA plan must satisfy, whatever the communication graph."""
    validate_plan(plan, g)
    holders: dict[tuple[int, str], int] = {}
    for i, route in res.routes.items():
        service = res.service[i]
        assert route, "empty routes are not reported"
        assert len(set(route)) == len(route), f"agent {i} visits a task twice"
        assert len(route) <= cbba.bundle_length
        kinds = g.task_kind[route]
        if service == "dump":
            assert g.agent_can_act[i] and (kinds == TaskKind.FIRE).all()
            tank = (
                g.agent_tank_capacity[i] if g.agent_mode[i] == Mode.RETURNING else g.agent_tank[i]
            )
            assert len(route) <= tank
        else:
            assert g.agent_can_sense[i]
            # a watch (a fire task for a camera) is a whole route on its own
            assert (kinds == TaskKind.SEARCH).all() or len(route) == 1
        assert g.agent_mode[i] != Mode.HOMING
        assert g.route_ok(i, route), (g.route_length_px(i, route), g.agent_budget_px[i])
        for k in route:
            key = (int(k), service)
            assert key not in holders, f"task {k} ({service}) given to {holders[key]} and {i}"
            holders[key] = i
    # the plan is exactly the result's routes
    assert {g.agent_index[a]: [g.task_index[t] for t in r] for a, r in plan.routes.items()} == {
        i: list(r) for i, r in res.routes.items()
    }


def plan_and_result(g: TaskGraph, cbba: CBBAScheduler | None = None):
    cbba = cbba or CBBAScheduler()
    return cbba.run(g), cbba.plan(g, time_limit=None, rng=np.random.default_rng(0)), cbba


# ---------------------------------------------------------------------- synthetic graphs
@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_agents=st.integers(2, 8),
    n_tasks=st.integers(1, 40),
    comm=st.sampled_from(COMM_RANGES),
    perception=st.sampled_from([0.25, 0.5, 0.75]),
    fires=st.sampled_from([0.0, 0.5, 1.0]),
)
def test_conflict_free_convergent_and_consistent(seed, n_agents, n_tasks, comm, perception, fires):
    """On random graphs (up to 8 agents x 40 tasks, unlimited / large / team-splitting comm
    ranges): no (task, service) pair is held by two agents anywhere in the plan (a fire task can
    have one dumper and one watcher, a search task one camera); routes respect roles, bundle
    length, tank, the watch-is-a-route-on-its-own rule and the battery; both auctions converge before
    the round cap; within every connected component all agents hold the same winner and bid
    vectors at convergence (with full communication: every agent); a connected team needs no
    conflict resolution at assembly; and the messages counted are exactly each agent
    broadcasting to its neighbours in every round."""
    g = synthetic_task_graph(
        n_agents,
        n_tasks,
        np.random.default_rng(seed),
        comm_range=comm,
        perception_share=perception,
        fire_share=fires,
    )
    res, plan, cbba = plan_and_result(g)
    check_result(g, res, plan, cbba)
    cg = communication_graph(g.agent_pos, g.comm_range)
    assert res.comm.n_components == cg.n_components
    for stage in res.stages:
        assert stage.converged and stage.rounds < cbba.max_rounds
        assert stage.messages == stage.rounds * int(cg.adjacency.sum())
        for label in np.unique(cg.labels):
            rows = np.flatnonzero(cg.labels == label)
            assert (stage.winners[rows] == stage.winners[rows[0]]).all()
            assert (stage.bids[rows] == stage.bids[rows[0]]).all()
    if cg.n_components == 1:
        assert res.conflicts_resolved == 0
    size = plan.stats.size
    assert size["rounds"] == res.rounds and size["messages"] == res.messages
    assert size["converged"] and plan.stats.status == "heuristic"


def test_full_communication_agents_agree_on_every_winner():
    """With unlimited range on a 8 x 40 graph, every agent ends both auctions with the same
    winner vector, and each task's winner is the one agent whose route holds it."""
    g = synthetic_task_graph(8, 40, np.random.default_rng(3), fire_share=0.5)
    res, plan, cbba = plan_and_result(g)
    check_result(g, res, plan, cbba)
    assert res.comm.n_components == 1 and res.comm.diameter == 1
    for stage in res.stages:
        assert (stage.winners == stage.winners[0]).all()
        owner = {int(stage.items[j]): i for i, path in enumerate(stage.paths) for j in path}
        won = {int(stage.items[j]): int(w) for j, w in enumerate(stage.winners[0]) if w >= 0}
        assert owner == won
    assert res.conflicts_resolved == 0


# ---------------------------------------------------------------------- consensus table
def table_action(i, k, zk, yk, zi, yi, s_k, s_i) -> str:
    """Table I of Choi, Brunet & How (2009) for one task, written case by case: the receiver
    ``i``'s action on a message from ``k`` (``-1``: no winner). Bids compare with ties to the
    lower agent index. Row (m, n) uses the reference implementation's tie rule."""

    def newer(a):
        return s_k[a] > s_i[a]

    def outbid():
        return yk > yi or (yk == yi and zk < zi)

    if zk == k:
        if zi == i:
            return "update" if outbid() else "leave"
        if zi == k or zi == -1:
            return "update"
        return "update" if newer(zi) or outbid() else "leave"
    if zk == i:
        if zi == k:
            return "reset"
        if zi not in (i, -1) and newer(zi):
            return "reset"
        return "leave"
    if zk == -1:
        if zi == k:
            return "update"
        if zi not in (i, -1) and newer(zi):
            return "update"
        return "leave"
    m = zk
    if zi == i:
        return "update" if newer(m) and outbid() else "leave"
    if zi == k:
        return "update" if newer(m) else "reset"
    if zi == m or zi == -1:
        return "update" if newer(m) else "leave"
    n = zi
    if newer(n):
        return "update" if s_k[m] >= s_i[m] else "reset"
    return "update" if newer(m) and outbid() else "leave"


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n_agents=st.integers(2, 6), n_items=st.integers(1, 8))
def test_vectorised_consensus_applies_the_table(seed, n_agents, n_items):
    """One round of the vectorised consensus gives, on random states (random winners, bids and
    timestamps with many ties, random communication graphs), exactly what the case-by-case table
    gives when each receiver reads its neighbours' messages in index order, task by task."""
    from solvers.cbba.auction import Auction, _Agents
    from solvers.cbba.comms import CommGraph

    rng = np.random.default_rng(seed)
    a, m = n_agents, n_items
    upper = np.triu(rng.random((a, a)) < 0.6, 1)
    adj = upper | upper.T
    comm = CommGraph(adj, np.zeros(a, dtype=np.int64), 1, 1)
    z = rng.integers(-1, a, size=(a, m))
    y = np.where(z >= 0, rng.choice([1.0, 2.0, 3.0], size=(a, m)), 0.0)
    s = rng.integers(0, 4, size=(a, a)).astype(float)
    zeros = np.zeros((a, m))
    auc = Auction(
        zeros,
        zeros > 0,
        np.zeros(m, bool),
        np.ones(a, int),
        np.zeros((m, 2)),
        zeros,
        zeros,
        np.zeros((a, 2)),
        np.zeros((a, 2)),
        np.ones(a),
        np.ones(a),
        1.0,
    )
    agents = _Agents(auc)
    agents.y, agents.z, agents.s = y.copy(), z.copy(), s.copy()
    agents.consensus(comm.slots(), 5)
    # the reference: task by task, neighbour by neighbour
    ry, rz, rs = y.copy(), z.copy(), s.copy()
    for i in range(a):
        for k in np.flatnonzero(adj[i]):
            for j in range(m):
                act = table_action(i, k, z[k, j], y[k, j], rz[i, j], ry[i, j], s[k], rs[i])
                if act == "update":
                    rz[i, j], ry[i, j] = z[k, j], y[k, j]
                elif act == "reset":
                    rz[i, j], ry[i, j] = -1, 0.0
            rs[i] = np.maximum(rs[i], s[k])
            rs[i, k] = 5
    assert (agents.z == rz).all() and (agents.y == ry).all() and (agents.s == rs).all()


# ---------------------------------------------------------------------- stopping rule
@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_agents=st.integers(1, 8),
    n_tasks=st.integers(0, 25),
    edge_p=st.sampled_from([0.0, 0.3, 0.6, 1.0]),
    insertion=st.sampled_from(["anywhere", "append"]),
)
def test_the_round_the_auction_stops_at_is_a_fixed_point(
    seed, n_agents, n_tasks, edge_p, insertion
):
    """Simulating on, every agent building every round: the first round after the first
    ``diameter`` that changes nothing is where ``run_auction`` stops, and ``3 * diameter + 3``
    more rounds change no agent's winners, bids or bundle (random instances and random, possibly
    disconnected, communication graphs)."""
    from solvers.cbba.auction import _Agents
    from solvers.cbba.static import StaticInstance, solve_static, static_auction, static_comm

    rng = np.random.default_rng(seed)
    inst = StaticInstance.random(rng, n_agents, n_tasks, bundle_length=3)
    adj = np.triu(rng.random((n_agents, n_agents)) < edge_p, 1)
    inst = dataclasses.replace(inst, adjacency=adj | adj.T)
    res = solve_static(inst, insertion=insertion)
    auc, comm = static_auction(inst, insertion), static_comm(inst)
    agents = _Agents(auc)
    bidders = np.flatnonzero(auc.eligible.any(axis=1)).tolist()
    slots = comm.slots()

    def state():
        return agents.y.copy(), agents.z.copy(), [list(b) for b in agents.bundles]

    stop = None
    for t in range(1, res.rounds + 3 * comm.diameter + 4):
        before = state()
        for i in bidders:
            agents.build(i)
        if comm.messages_per_round:
            agents.consensus(slots, t)
            agents.release()
        after = state()
        same = all((a == b).all() for a, b in zip(before[:2], after[:2], strict=True))
        same &= before[2] == after[2]
        if stop is None and same and t > comm.diameter:
            stop = t
        elif stop is not None:
            assert same, f"changed in round {t} after a quiet round {stop}"
    assert stop == res.rounds and res.stopped_by == "converged"


# ---------------------------------------------------------------------- one agent = greedy
def one_agent(g: TaskGraph, i: int) -> TaskGraph:
    """The graph with agent row ``i`` only."""
    sel = [i]
    fields = {
        f.name: getattr(g, f.name)[sel]
        for f in dataclasses.fields(g)
        if f.name.startswith("agent_") and f.name != "agent_ids"
    }
    return dataclasses.replace(g, agent_ids=(g.agent_ids[i],), **fields)


def reference_bundle(g: TaskGraph, cbba: CBBAScheduler) -> list[int]:
    """The sequential greedy bundle of the only agent, the slow obvious way: repeatedly try every
    task at every position, score each whole path from scratch, keep the best gain."""
    rate = math.log(2.0) / cbba.half_life_s
    stale = g.task_staleness
    fresh = np.where(stale <= cbba.fresh_s, 1.0, np.exp(-(stale - cbba.fresh_s) / cbba.fresh_s))
    fire = g.task_kind == TaskKind.FIRE
    if g.agent_can_act[0]:
        value = np.where(fire, g.task_value * fresh, 0.0)
        limit = min(cbba.bundle_length, int(g.agent_tank[0]))
    else:  # alone, nobody dumps: watching is only worth it for stale fires
        value = np.where(fire, cbba.watch_weight * g.task_value * (1 - fresh), g.task_value)
        limit = cbba.bundle_length
    speed = g.agent_speed[0]

    def score(path):
        pts = np.vstack([g.agent_pos[0]] + [g.task_pos[k] for k in path])
        t = np.cumsum(np.hypot(*np.diff(pts, axis=0).T)) / speed
        return float(sum(value[k] * math.exp(-rate * tk) for k, tk in zip(path, t, strict=True)))

    def ok(path):
        if not g.agent_can_act[0] and len(path) > 1 and fire[path].any():
            return False  # a watch is a route on its own
        need, have = g.route_length_px(0, path), g.agent_budget_px[0]
        return need <= have + 1e-9 and bool(g.in_round_trip[0, path].all())

    path: list[int] = []
    while len(path) < limit:
        best = (0.0, None)
        base = score(path)
        for k in range(g.n_tasks):
            if k in path or value[k] <= 0:
                continue
            for q in range(len(path) + 1):
                new = path[:q] + [k] + path[q:]
                if ok(new) and score(new) - base > best[0] + 1e-9:
                    best = (score(new) - base, new)
        if best[1] is None:
            break
        path = best[1]
    return path


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_tasks=st.integers(1, 25),
    role=st.sampled_from(["perception", "action"]),
)
def test_single_agent_equals_sequential_greedy_bundle(seed, n_tasks, role):
    """With one agent (and so full communication), CBBA's route is the sequential greedy bundle:
    the task with the best marginal time-discounted score inserted at its best position, until
    the bundle is full or nothing gains."""
    g = synthetic_task_graph(2, n_tasks, np.random.default_rng(seed), fire_share=0.5)
    g1 = one_agent(g, 0 if role == "perception" else 1)
    cbba = CBBAScheduler()
    res = cbba.run(g1)
    assert res.comm.n_components == 1 and res.messages == 0
    assert res.routes.get(0, []) == reference_bundle(g1, cbba)


# ---------------------------------------------------------------------- partitions
def two_agents_one_fire(distance: float, comm_range: float | None) -> TaskGraph:
    """Two action agents ``distance`` px apart, one fire between them (closer to the first)."""
    g = synthetic_task_graph(3, 1, np.random.default_rng(0), perception_share=0.3, fire_share=1.0)
    pos = np.array([[100.0, 100.0], [300.0, 500.0], [300.0 + distance, 500.0]])
    return dataclasses.replace(
        g,
        agent_pos=pos,
        agent_battery=np.full(3, 500.0),
        task_pos=np.array([[300.0 + 0.4 * distance, 500.0]]),
        task_staleness=np.zeros(1),
        comm_range=comm_range,
    )


def test_disconnected_components_conflict_is_resolved_by_the_higher_bid():
    """Two action agents that cannot talk both win the same fire in their own components; the
    plan keeps the closer agent's (higher) bid, drops it from the other route, and counts one
    conflict. In range of each other, they agree without any conflict."""
    g = two_agents_one_fire(400.0, comm_range=100.0)
    res, plan, cbba = plan_and_result(g)
    assert res.comm.n_components == 3
    assert res.stages[0].winners[1, 0] == 1 and res.stages[0].winners[2, 0] == 2
    assert res.conflicts_resolved == 1
    check_result(g, res, plan, cbba)
    assert plan.routes == {"A2": ("fire:0",)}
    assert plan.stats.size["conflicts_resolved"] == 1

    g = two_agents_one_fire(400.0, comm_range=420.0)
    res, plan, cbba = plan_and_result(g)
    assert res.conflicts_resolved == 0 and plan.routes == {"A2": ("fire:0",)}


def test_line_graph_information_travels_hop_by_hop():
    """On a line of agents (each only hears its neighbours), the auction still converges to one
    winner per task, and takes more than ``diameter`` rounds to be sure of it."""
    g = synthetic_task_graph(6, 30, np.random.default_rng(5), perception_share=0.5)
    pos = np.stack([np.linspace(100, 1100, 6), np.full(6, 600.0)], axis=1)
    g = dataclasses.replace(g, agent_pos=pos, comm_range=210.0)
    res, plan, cbba = plan_and_result(g)
    assert res.comm.n_components == 1 and res.comm.diameter == 5
    check_result(g, res, plan, cbba)
    for stage in res.stages:
        assert stage.converged and stage.rounds >= 5 + 1
        assert (stage.winners == stage.winners[0]).all()


# ---------------------------------------------------------------------- real graphs
@pytest.mark.parametrize("name", SCENARIOS)
def test_plans_on_real_graphs_are_valid_and_conflict_free(name):
    """On graphs from greedy episodes of every shipped scenario, with the scenario's own range
    and with a 150-px range, CBBA's plan validates, is conflict-free per (task, service), fits
    every battery and converges."""
    for g in episode_graphs(name, TICKS):
        for comm in (g.comm_range, 150.0):
            gc = dataclasses.replace(g, comm_range=comm)
            res, plan, cbba = plan_and_result(gc)
            check_result(gc, res, plan, cbba)
            assert res.converged


@pytest.mark.parametrize("name", [1, 12, "open_world_example"])
def test_cbba_is_deterministic(name):
    """The same graph gives the same plan whatever the generator (CBBA draws no random numbers)."""
    for g in episode_graphs(name, TICKS):
        a = CBBAScheduler().plan(g, time_limit=None, rng=np.random.default_rng(1))
        b = CBBAScheduler().plan(g, time_limit=None, rng=np.random.default_rng(2))
        assert dict(a.routes) == dict(b.routes) and dict(a.altitudes) == dict(b.altitudes)
        assert a.stats == b.stats


# ---------------------------------------------------------------------- episodes
def test_episode_completes_and_prunes_fire():
    """``run_episode(1, "cbba", seed=0)`` runs to the end without a greedy fallback, puts out
    fire, and every replan reports its rounds and messages."""
    res = fcplan.run_episode(1, "cbba", seed=0)
    assert res.ticks == 1800 and res.fallbacks == 0
    assert res.metrics["manual"].overall_firefighting > 0
    assert all(s.size["rounds"] >= 1 and "messages" in s.size for s in res.solves)


def test_episode_with_a_short_comm_range():
    """Scenario #12 with a 300-px radio range runs to the end without a fallback, the team is
    split into several components at some replans, and fire is still put out."""
    sc = fcplan.load_scenario(12).replace(comm_range=300.0)
    res = fcplan.run_episode(sc, "cbba", seed=0)
    assert res.fallbacks == 0
    assert max(s.size["components"] for s in res.solves) > 1
    assert res.metrics["manual"].overall_firefighting > 0


def test_known_fire_is_fought_and_watched():
    """With known fire and idle action agents (greedy's hand-lit test fire), CBBA sends action
    agents to fire tasks and a camera agent to watch, at the watch altitude, a fire task that an
    action agent is heading to."""
    from tests.solvers.test_greedy import known_fire_graph

    g = known_fire_graph()
    res, plan, cbba = plan_and_result(g)
    check_result(g, res, plan, cbba)
    fought = {
        t for i, a in enumerate(g.agent_ids) if g.agent_can_act[i] for t in plan.routes.get(a, ())
    }
    assert fought
    watchers = [
        a
        for i, a in enumerate(g.agent_ids)
        if g.agent_can_sense[i] and set(plan.routes.get(a, ())) & fought
    ]
    assert watchers
    assert all(plan.altitudes[a] == cbba.watch_altitude for a in watchers)
