"""Task graphs taken from greedy episodes, shared by the solver tests."""

from __future__ import annotations

from functools import cache

from fcplan import load_scenario
from fcplan.mission import Mission
from fcplan.scheduling import make_scheduler
from fcplan.taskgraph import TaskGraph

#: every shipped scenario plus an open-world design with hybrid agents and a 1000 px map
SCENARIOS = ["practice", *range(1, 25), "open_world_example"]


@cache
def episode_graphs(name, ticks: tuple[int, ...]) -> tuple[TaskGraph, ...]:
    """Task graphs at replan ``ticks`` of a greedy episode (replanning every simulated second)."""
    mission = Mission(load_scenario(name), seed=0, replan_period=1.0, event_replans=False)
    greedy = make_scheduler("greedy")
    out = []
    while mission.tick <= max(ticks):
        commands = None
        if mission.replan_due():
            graph, plan = mission.replan(greedy)
            if mission.tick in ticks:
                out.append(graph)
            commands = mission.commands_for(plan, graph)
        mission.step(commands)
    return tuple(out)
