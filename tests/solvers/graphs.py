"""Task graphs taken from greedy episodes, shared by the solver tests."""

from __future__ import annotations

from functools import cache

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.plan import plan_commands
from fcplan.scheduling import make_scheduler, solve
from fcplan.taskgraph import TaskGraph, build_task_graph

#: every shipped scenario plus an open-world design with hybrid agents and a 1000 px map
SCENARIOS = ["practice", *range(1, 25), "open_world_example"]


@cache
def episode_graphs(name, ticks: tuple[int, ...]) -> tuple[TaskGraph, ...]:
    """Task graphs at replan ``ticks`` of a greedy episode (replanning every simulated second)."""
    sc = load_scenario(name)
    world = World().reset(sc, seed=0)
    belief = Belief(sc)
    greedy = make_scheduler("greedy")
    rng = world.controller_rng
    out = []
    while world.tick <= max(ticks):
        commands = None
        if world.tick % sc.ticks_per_second == 0:
            g = build_task_graph(sc, world.team, belief)
            if world.tick in ticks:
                out.append(g)
            commands = plan_commands(solve(greedy, g, time_limit=None, rng=rng), g)
        belief.update(world.step(commands))
    return tuple(out)
