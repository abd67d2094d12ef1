"""The batched move rule (:class:`fcplan.env.vector_moves.BatchRoutes`) against the readable one
(:meth:`fcplan.env.motion_expert.TeamRoutes.choose`): the same action for every agent of every
world, tick after tick, from random plans (patrols, homes, altitudes, routes of fire and search
goals), positions on and off the goals, action masks and modes, with replans and resets between.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import load_scenario
from fcplan.env.motion_expert import TeamRoutes
from fcplan.env.vector_moves import BatchRoutes
from fcplan.plan import Plan
from fcplan.team import Mode
from tests.solvers.graphs import episode_graphs

SCENARIOS = ("open_world_example", 24, "practice")


def random_plan(graph, rng: np.random.Generator) -> Plan:
    """Routes of 0-4 goals for most agents (some patrolling), home for some, altitudes for some."""
    routes, alts, patrol, home = {}, {}, set(), set()
    for a in graph.agent_ids:
        u = rng.random()
        if u < 0.7:
            k = rng.choice(graph.n_tasks, size=min(int(rng.integers(0, 5)), graph.n_tasks),
                           replace=False)  # fmt: skip
            routes[a] = tuple(graph.task_ids[i] for i in k)
            if rng.random() < 0.25 and len(k) >= 2:
                patrol.add(a)
        elif u < 0.8:
            home.add(a)
        if rng.random() < 0.6:
            alts[a] = float(rng.uniform(10.0, 100.0))
    return Plan(routes=routes, altitudes=alts, patrol=frozenset(patrol), home=frozenset(home))


def positions(rule: TeamRoutes, graph, speed, rng):
    """Each agent on its next goal (give or take a fraction of half a step), or anywhere."""
    n = graph.n_agents
    pos = rng.uniform(0.0, graph.world_size, size=(n, 2))
    for i in range(n):
        route = rule._routes[i]
        if route and rng.random() < 0.6:
            pos[i] = route[0][:2] + rng.uniform(-0.6, 0.6, 2) * 0.5 * speed[i]
        if (
            rule._patrol[i]
            and route
            and all(
                abs(gx - pos[i, 0]) <= 0.5 * speed[i] and abs(gy - pos[i, 1]) <= 0.5 * speed[i]
                for gx, gy, _ in route
            )
        ):  # (the rule loops forever there: module docstring of vector_moves)
            pos[i] += 10 * speed[i]
    return pos


@pytest.mark.parametrize("scenario", SCENARIOS)
@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), num=st.integers(1, 5))
def test_batched_moves_equal_the_rule(scenario, seed, num):
    """Worlds with their own plans: every tick, every agent's action is the rule's; replans
    (new plans over old routes) and resets of some worlds keep them equal."""
    sc = load_scenario(scenario)
    graphs = episode_graphs(scenario, (0, 100, 300))
    ids = list(graphs[0].agent_ids)
    rng = np.random.default_rng(seed)
    n = len(ids)
    speed = np.array([a.speed for a in sc.agents], dtype=np.float64) * 0.25 * (1 + rng.random())
    climb = 5.0 * float(rng.uniform(0.1, 1.0))
    rules = [TeamRoutes(ids, sc) for _ in range(num)]
    batch = BatchRoutes(ids, sc, num)
    for tick in range(24):
        for b in range(num):
            if tick % 8 == 0 or rng.random() < 0.05:
                g = graphs[int(rng.integers(len(graphs)))]
                plan = random_plan(g, rng)
                rules[b].follow(plan, g)
                batch.follow(b, plan, g)
        if rng.random() < 0.1:
            b = int(rng.integers(num))
            rules[b] = TeamRoutes(ids, sc)
            batch.reset(np.array([b]))
        masks = (rng.random((num, n, 8)) < 0.75).astype(np.int8)
        masks[:, :, 0] = 1
        pos = np.stack([positions(rules[b], graphs[0], speed, rng) for b in range(num)])
        z_target = rng.uniform(0.0, 110.0, (num, n))
        mode = np.where(rng.random((num, n)) < 0.85, int(Mode.ACTIVE), int(Mode.RETURNING))
        rows = np.flatnonzero(rng.random(num) < 0.8)
        if not rows.size:
            continue
        got = batch.choose(rows, masks, pos, z_target, mode.astype(np.int8), speed, climb)
        for r, b in enumerate(rows.tolist()):
            want = rules[b].choose(dict(zip(ids, masks[b], strict=True)), pos[b].tolist(),
                                   z_target[b].tolist(), mode[b].tolist(), speed.tolist(),
                                   climb)  # fmt: skip
            assert got[r].tolist() == [want[a] for a in ids], (tick, b)


def test_a_patrol_on_top_of_its_goals_stops_after_one_round():
    """Where the rule would loop forever (every patrol goal within half a step), the batched rule
    drops one round of goals and answers."""
    sc = load_scenario("practice")
    g = episode_graphs("practice", (0,))[0]
    ids = list(g.agent_ids)
    batch = BatchRoutes(ids, sc, 1)
    t = g.task_ids[0]
    batch.follow(0, Plan(routes={ids[0]: (t, t)}, patrol=frozenset({ids[0]})), g)
    pos = np.zeros((1, len(ids), 2))
    pos[0, 0] = g.task_pos[0]
    speed = np.full(len(ids), 10.0)
    masks = np.ones((1, len(ids), 8), dtype=np.int8)
    mode = np.zeros((1, len(ids)), dtype=np.int8)
    out = batch.choose(np.array([0]), masks, pos, np.zeros((1, len(ids))), mode, speed, 1.0)
    assert out.shape == (1, len(ids)) and batch.count[0, 0] == 2
