"""Greedy's batched pick loop (:mod:`solvers.greedy_batch`) against the readable rule.

``GreedyScheduler.plan_batch(graphs)`` must give, graph for graph, the plan ``plan(graph)``
gives: the same routes in the same order, the same altitudes and the same objective bit for
bit, whatever the other graphs in the batch (their sizes, their teams, whether they have
anything to assign).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.plan import Plan
from fcplan.taskgraph import TaskGraph, synthetic_task_graph
from fcplan.team import Mode
from solvers.greedy import GreedyScheduler
from tests.solvers.graphs import SCENARIOS, episode_graphs

TICKS = (0, 100, 300, 600)

SETTINGS = [
    {},
    {"route_length": 1, "search_route_length": 4},
    {"spread_px": 0.0, "max_watch_fraction": 0.0},
    {"route_length": 6, "spread_px": 600.0, "fresh_s": 0.5},
]


def same_plan(a: Plan, b: Plan) -> bool:
    """Routes (with their order), altitudes, patrols, homes and the objective all equal."""
    return (
        a.routes == b.routes
        and list(a.routes) == list(b.routes)
        and a.altitudes == b.altitudes
        and a.patrol == b.patrol
        and a.home == b.home
        and a.stats.objective == b.stats.objective  # type: ignore[union-attr]
        and a.stats.size == b.stats.size  # type: ignore[union-attr]
    )


def check_batch(graphs: list[TaskGraph], **kw) -> None:
    g = GreedyScheduler(**kw)
    batch = g.plan_batch(graphs)
    assert len(batch) == len(graphs)
    for i, (graph, plan) in enumerate(zip(graphs, batch, strict=True)):
        assert same_plan(plan, g.plan(graph)), f"graph {i} differs"


@pytest.mark.parametrize("kw", SETTINGS)
def test_batch_equals_rule_on_every_scenarios_episode_graphs(kw):
    """One batch of the graphs of greedy episodes on every shipped scenario and the open world
    (hybrids, several team sizes, with and without known fire): each plan equals the rule's."""
    graphs = [g for name in SCENARIOS for g in episode_graphs(name, TICKS)]
    assert any(g.fire_tasks.size for g in graphs) and any(not g.fire_tasks.size for g in graphs)
    check_batch(graphs, **kw)


def test_a_world_plans_the_same_alone_and_among_others():
    """A graph's plan does not depend on the other graphs of its batch (alone, first, last,
    beside a larger team)."""
    graphs = list(episode_graphs(24, TICKS)) + list(episode_graphs("open_world_example", TICKS))
    g = GreedyScheduler()
    for graph in graphs:
        alone = g.plan_batch([graph])[0]
        assert same_plan(alone, g.plan_batch([graph, *graphs])[0])
        assert same_plan(alone, g.plan_batch([*graphs, graph])[-1])


def test_graphs_with_nothing_to_assign_mix_with_others():
    """Graphs whose agents are all homing, or that have no tasks of value, get the rule's plan
    (empty or watch-only) beside graphs that assign."""
    rng = np.random.default_rng(3)
    busy = synthetic_task_graph(5, 40, rng)
    homing = synthetic_task_graph(4, 30, rng)
    homing.agent_mode[:] = Mode.HOMING
    no_value = synthetic_task_graph(3, 10, rng)
    no_value.task_value[:] = 0.0
    check_batch([homing, busy, no_value, busy])


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    sizes=st.lists(st.tuples(st.integers(2, 14), st.integers(1, 160)), min_size=1, max_size=9),
    kw=st.sampled_from(SETTINGS),
)
def test_batch_equals_rule_on_random_graphs(seed, sizes, kw):
    """Random synthetic graphs of random sizes in one batch: each plan equals the rule's."""
    rng = np.random.default_rng(seed)
    check_batch([synthetic_task_graph(a, k, rng) for a, k in sizes], **kw)


def test_empty_batch():
    """No graphs, no plans."""
    assert GreedyScheduler().plan_batch([]) == []
