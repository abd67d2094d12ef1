"""Tests for the spatial decomposition of big routing models (solvers.routing.decompose) and
the routing scheduler's use of it."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.plan import validate_plan
from fcplan.taskgraph import synthetic_task_graph
from solvers.routing import RoutingScheduler
from solvers.routing.decompose import bisection_sizes, spatial_groups


@given(
    seed=st.integers(0, 2**32 - 1),
    n_v=st.integers(1, 60),
    n_k=st.integers(0, 120),
    size=st.integers(1, 20),
    density=st.floats(0.0, 1.0),
)
@settings(max_examples=80, deadline=None)
def test_groups_partition_vehicles_and_tasks(seed, n_v, n_k, size, density):
    """Every vehicle is in exactly one group of at most ``size`` (group sizes as
    bisection_sizes says); every task some vehicle may serve is in exactly one group, the group
    of its nearest allowed vehicle; a task nobody may serve is in none."""
    rng = np.random.default_rng(seed)
    starts = rng.uniform(0, 1000, (n_v, 2))
    tasks = rng.uniform(0, 1000, (n_k, 2))
    allowed = rng.random((n_v, n_k)) < density
    groups = spatial_groups(starts, tasks, allowed, size)
    vehicles = np.concatenate([v for v, _ in groups])
    assert sorted(vehicles.tolist()) == list(range(n_v))
    assert sorted(v.size for v, _ in groups) == sorted(bisection_sizes(n_v, size))
    assert all(v.size <= size for v, _ in groups)
    owned = np.concatenate([t for _, t in groups]) if groups else np.zeros(0, int)
    assert sorted(owned.tolist()) == np.flatnonzero(allowed.any(axis=0)).tolist()
    if len(groups) > 1:
        d = np.hypot(*(starts[:, None] - tasks[None]).transpose(2, 0, 1))
        d = np.where(allowed, d, np.inf)
        for vs, ts in groups:
            for k in ts.tolist():
                assert d[vs, k].min() == d[:, k].min()


def test_groups_are_spatially_compact():
    """Two well-separated teams of 10 are cut into their own groups at size 10."""
    rng = np.random.default_rng(0)
    starts = np.r_[rng.uniform(0, 100, (10, 2)), rng.uniform(900, 1000, (10, 2))]
    groups = spatial_groups(starts, np.zeros((0, 2)), np.zeros((20, 0), bool), 10)
    assert [sorted(v.tolist()) for v, _ in groups] == [list(range(10)), list(range(10, 20))]


def test_a_big_team_is_routed_by_group_models_without_a_shared_task():
    """On 60 agents the scheduler solves several group models per role (stats ``models``), the
    plan is valid, no task is in two routes of one role (a fire may be dumped on and watched),
    and the deterministic plan is the same twice."""
    g = synthetic_task_graph(60, 400, np.random.default_rng(3))
    sched = RoutingScheduler(deterministic=True, group_vehicles=8, solution_limit=5)
    plan = sched.plan(g, time_limit=None, rng=None)
    validate_plan(plan, g)
    assert plan.stats.size["models"] >= 6 and "action 1/" in plan.stats.message
    for role in (0, 1):
        tasks = [t for a, r in plan.routes.items() if g.agent_role[g.agent_ids.index(a)] == role
                 for t in r]  # fmt: skip
        assert len(tasks) == len(set(tasks))
    assert len(plan.routes) > 30
    again = RoutingScheduler(deterministic=True, group_vehicles=8, solution_limit=5)
    assert again.plan(g, time_limit=None, rng=None).routes == plan.routes


def test_group_vehicles_zero_keeps_one_model_per_role():
    """``group_vehicles=0`` never splits: one model per role whatever the team size."""
    g = synthetic_task_graph(40, 200, np.random.default_rng(1))
    plan = RoutingScheduler(deterministic=True, group_vehicles=0, solution_limit=5).plan(
        g, time_limit=None, rng=None
    )
    assert plan.stats.size["models"] == 2
