"""Worlds with hand-lit fire that the team has sensed, shared by the task-graph tests."""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.taskgraph import TaskGraph, build_task_graph
from fcplan.team import Command


@lru_cache(maxsize=4)
def quiet_scenario(name: str | int = 1):
    """A shipped scenario whose own fire regions never ignite during the game."""
    sc = load_scenario(name)
    regions = tuple(dataclasses.replace(r, delay_s=10_000.0) for r in sc.regions)
    return sc.replace(regions=regions)


def hover_world(cells, at, *, z: float = 100.0, hover_ticks: int = 30, scenario=None):
    """Ignite ``cells`` by hand, fly P1 to ``at`` (or each agent of a dict ``{id: xy}`` to its
    point) at altitude ``z`` and hover there.

    Returns the world and the team's belief. At z = 100 the view is 200 x 115 px; each cell in it
    is sensed with probability 0.4 per tick, so after ~30 ticks almost every cell is known (the
    tests compare the graph with the belief, not with the ignited cells).
    """
    sc = scenario or quiet_scenario(1)
    world = World().reset(sc, seed=0)
    if len(cells):
        world.ignite(np.asarray(cells, dtype=np.int64).reshape(-1, 2))
    belief = Belief(sc)
    targets = at if isinstance(at, dict) else {"P1": at}
    team = world.team
    n = 0
    cmd = {}
    for agent, xy in targets.items():
        i = team.index(agent)
        travel = math.hypot(xy[0] - team.pos[i, 0], xy[1] - team.pos[i, 1])
        n = max(n, int(travel / team.speed[i]) + 2 + hover_ticks)
        cmd[agent] = Command(route=((float(xy[0]), float(xy[1])),), altitude=z)
    for _ in range(n):
        belief.update(world.step(cmd))
        cmd = None
    return world, belief


def graph_of(world, belief, params=None) -> TaskGraph:
    return build_task_graph(world.scenario, world.team, belief, params)


def block_cells(center, half=(40, 25), step=3):
    """A filled rectangle of cells (every ``step`` px) around ``center``."""
    cx, cy = center
    xs = np.arange(cx - half[0], cx + half[0] + 1, step)
    ys = np.arange(cy - half[1], cy + half[1] + 1, step)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.stack([gx.ravel(), gy.ravel()], axis=1)


def rect_distance(p, rect) -> float:
    x0, x1, y0, y1 = rect
    dx = max(x0 - p[0], 0.0, p[0] - x1)
    dy = max(y0 - p[1], 0.0, p[1] - y1)
    return math.hypot(dx, dy)


def fire_tile_of_cells(graph: TaskGraph, xy: np.ndarray) -> np.ndarray:
    """(k,) row of the fire task whose tile holds each cell (-1 when none)."""
    tw, th = graph.tile_px
    fires = graph.fire_tasks
    tiles = {
        (int(graph.task_pos[k, 0] // tw), int(graph.task_pos[k, 1] // th)): int(k) for k in fires
    }
    assert len(tiles) == fires.size, "two fire tasks share a tile"
    return np.array([tiles.get((int(x // tw), int(y // th)), -1) for x, y in xy], dtype=np.int64)


# strategies: a few clumps of cells inside one 200 x 115 px view centred on a random point
centres = st.tuples(st.integers(150, 1050), st.integers(150, 1050))
offsets = st.lists(
    st.tuples(st.integers(-95, 95), st.integers(-55, 55)), min_size=1, max_size=60, unique=True
)


@lru_cache(maxsize=1)
def fire_near_house():
    """Known fire just north of the house at I-02 (footprint x 840..960, y 125..275)."""
    cells = block_cells((900, 100), half=(20, 10), step=2)
    return hover_world(cells, (900, 100))


@lru_cache(maxsize=1)
def fire_far_away():
    """Known fire at (520, 500): more than 250 px from every facility footprint of #1."""
    cells = block_cells((520, 500), half=(30, 20), step=2)
    return hover_world(cells, (520, 500))
