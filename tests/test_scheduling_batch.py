"""``solve_batch``: one call for many worlds' graphs, each world's plan settled as ``solve``
settles it (validation, the greedy fallback per world, stats)."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.plan import Plan
from fcplan.scheduling import make_scheduler, solve
from fcplan.scheduling_batch import BatchScheduler, batch_capable, solve_batch
from fcplan.taskgraph import synthetic_task_graph
from solvers.greedy import GreedyScheduler


def graphs_and_rngs(n: int = 5):
    graphs = [
        synthetic_task_graph(3 + s % 4, 20 + 7 * s, np.random.default_rng(s)) for s in range(n)
    ]
    return graphs, [np.random.default_rng(100 + s) for s in range(n)]


def test_batched_greedy_equals_solve_per_world():
    """A batch-capable instance: one ``plan_batch`` call, plans and statuses those of ``solve``
    on each graph, stats with sizes and a non-negative share of the solver time."""
    graphs, rngs = graphs_and_rngs()
    greedy = make_scheduler("greedy")
    assert batch_capable(greedy) and isinstance(greedy, BatchScheduler)
    got = solve_batch(greedy, graphs, time_limit=None, rngs=rngs)
    for g, p, r in zip(graphs, got, rngs, strict=True):
        want = solve(greedy, g, time_limit=None, rng=r)
        assert p.routes == want.routes and p.altitudes == want.altitudes
        assert p.stats.status == "heuristic" and p.stats.solver_s >= 0.0
        assert p.stats.wall_time_s >= p.stats.solver_s
        assert p.stats.size["tasks"] == g.n_tasks


class _Broken(GreedyScheduler):
    """Greedy whose batched call misbehaves as told."""

    def __init__(self, how: str) -> None:
        super().__init__()
        self.how, self.batch_calls = how, 0

    def plan_batch(self, graphs, *, time_limit=None, rngs=None):
        self.batch_calls += 1
        if self.how == "raise":
            raise RuntimeError("boom")
        plans = super().plan_batch(graphs, time_limit=time_limit, rngs=rngs)
        if self.how == "short":
            return plans[:-1]
        plans[1] = Plan(routes={"nobody": ("nothing",)})  # invalid for world 1 only
        return plans


@pytest.mark.parametrize("how", ["raise", "short"])
def test_a_failed_batch_call_solves_every_world_on_its_own(how):
    """``plan_batch`` raising or returning the wrong number of plans: each world goes through
    ``solve`` (here the scheduler's own ``plan`` works, so no fallback)."""
    graphs, rngs = graphs_and_rngs()
    s = _Broken(how)
    got = solve_batch(s, graphs, time_limit=None, rngs=rngs)
    assert s.batch_calls == 1
    assert [p.stats.status for p in got] == ["heuristic"] * len(graphs)
    assert [p.routes for p in got] == [GreedyScheduler().plan(g).routes for g in graphs]


def test_an_invalid_plan_falls_back_for_its_world_only():
    """One world's invalid plan is replaced by greedy's (``fallback``, the reason named); the
    other worlds keep the batch's plans."""
    graphs, rngs = graphs_and_rngs()
    got = solve_batch(_Broken("invalid"), graphs, time_limit=None, rngs=rngs)
    assert [p.stats.status for p in got] == ["heuristic", "fallback"] + ["heuristic"] * 3
    assert "nobody" in got[1].stats.message
    assert got[1].routes == GreedyScheduler().plan(graphs[1]).routes


def test_one_instance_per_world_and_instances_without_plan_batch():
    """A sequence is one scheduler per world; a single instance without ``plan_batch`` is called
    on each graph in turn; both equal ``solve``."""
    graphs, _ = graphs_and_rngs(3)
    per_world = [make_scheduler("random") for _ in graphs]
    one = make_scheduler("random")
    assert not batch_capable(one)

    def rngs():
        return [np.random.default_rng(s) for s in range(3)]

    a = solve_batch(per_world, graphs, time_limit=None, rngs=rngs())
    b = solve_batch(one, graphs, time_limit=None, rngs=rngs())
    c = [solve(one, g, time_limit=None, rng=r) for g, r in zip(graphs, rngs(), strict=True)]
    assert [p.routes for p in a] == [p.routes for p in b] == [p.routes for p in c]


def test_lengths_must_match():
    """As many generators (and per-world schedulers) as graphs, else a ValueError naming both."""
    graphs, rngs = graphs_and_rngs(3)
    with pytest.raises(ValueError, match="3 graphs but 2 generators"):
        solve_batch(make_scheduler("greedy"), graphs, time_limit=None, rngs=rngs[:2])
    with pytest.raises(ValueError, match="3 graphs but 1 schedulers"):
        solve_batch([make_scheduler("greedy")], graphs, time_limit=None, rngs=rngs)


def test_the_batched_expert_shares_one_greedy_and_not_one_routing():
    """BatchPlanFollower plans every world with one greedy instance (batched), named or given,
    but makes one routing instance per world (no ``plan_batch``)."""
    env = VectorMotionEnv("practice", 3)
    shared = BatchPlanFollower(env, "greedy")
    assert shared.shared is not None and all(s is shared.shared for s in shared.schedulers)
    apart = BatchPlanFollower(env, "routing")
    assert apart.shared is None and len({id(s) for s in apart.schedulers}) == 3
    given = make_scheduler("greedy")
    assert BatchPlanFollower(env, given).shared is given
