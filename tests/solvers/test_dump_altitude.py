"""One dump-altitude rule for every built-in scheduler (:meth:`TaskGraph.dump_altitude`).

A dump puts out the sensed burning cells in the dumping agent's field of view, which grows with
its altitude, so where a hybrid (camera and water) flies its dumps is part of how well a team
fights fire. The built-in schedulers place it by one rule with one setting, ``dump_altitude``
(None: the top of the agent's bounds), so that a comparison between them is about what they
assign. Checked on task graphs of an open-world episode with hybrids.
"""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.scheduling import SettingError, make_scheduler
from fcplan.taskgraph import TaskGraph, TaskKind
from tests.solvers.graphs import episode_graphs

#: the schedulers that route hybrids to fires, in settings that keep the test quick
SCHEDULERS = {
    "greedy": {},
    "routing": {"deterministic": True, "solution_limit": 20, "branch_limit": 1000},
    "cbba": {"deterministic": True},
    "milp": {"deterministic": True},
    "oracle": {},
}


def _graphs() -> list[TaskGraph]:
    """Graphs of the open-world example with a fire known and a hybrid with water."""
    out = [
        g
        for g in episode_graphs("open_world_example", (0, 100, 300, 600))
        if g.fire_tasks.size and (g.agent_can_act & g.agent_can_sense & (g.agent_tank > 0)).any()
    ]
    assert out
    return out


def _hybrid_dumpers(g: TaskGraph, plan) -> list[int]:
    """Rows of the hybrids with water that the plan sends to fires."""
    rows = np.flatnonzero(g.agent_can_act & g.agent_can_sense & (g.agent_tank > 0))
    return [
        int(i)
        for i in rows
        if plan.routes.get(g.agent_ids[i])
        and g.task_kind[g.task_index[plan.routes[g.agent_ids[i]][0]]] == TaskKind.FIRE
    ]


def test_the_rule_is_the_top_of_the_bounds_or_the_setting_clipped():
    """``dump_altitude(row)`` is the top of the row's altitude bounds; with a value, the value
    clipped to the bounds."""
    g = _graphs()[0]
    for i in range(g.n_agents):
        lo, hi = (float(v) for v in g.agent_alt_range[i])
        assert g.dump_altitude(i) == hi
        assert g.dump_altitude(i, 0.001) == lo
        assert g.dump_altitude(i, (lo + hi) / 2) == (lo + hi) / 2


@pytest.mark.parametrize("name", sorted(SCHEDULERS))
@pytest.mark.parametrize("z", [None, 60.0])
def test_every_scheduler_flies_its_hybrids_dumps_at_the_dump_altitude(name, z):
    """Each built-in scheduler's plan puts every hybrid it sends to a fire with water at
    ``graph.dump_altitude(row, dump_altitude)``, by default and with the setting given; at
    least one such hybrid is planned on these graphs."""
    settings = dict(SCHEDULERS[name])
    if z is not None:
        settings["dump_altitude"] = z
    sched = make_scheduler(name, **settings)
    seen = 0
    for g in _graphs():
        plan = sched.plan(g, time_limit=None, rng=np.random.default_rng(0))
        for i in _hybrid_dumpers(g, plan):
            assert plan.altitudes[g.agent_ids[i]] == g.dump_altitude(i, z), (name, i)
            seen += 1
    assert seen


@pytest.mark.parametrize("name", ["greedy", "routing", "cbba", "milp"])
@pytest.mark.parametrize("bad", [0.0, -5.0, float("nan"), float("inf"), "high"])
def test_a_bad_dump_altitude_is_refused_in_one_line(name, bad):
    """A dump altitude that is not a positive finite number is refused at construction by every
    scheduler that has the setting, with the setting's name in the message."""
    with pytest.raises((SettingError, ValueError), match="dump_altitude"):
        make_scheduler(name, dump_altitude=bad)
