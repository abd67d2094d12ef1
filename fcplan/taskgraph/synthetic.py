"""Synthetic task graphs: random agents and tasks with no simulation behind them.

For solver tests, scaling studies and teaching: a :class:`~fcplan.taskgraph.types.TaskGraph`
of any size, drawn from a :class:`numpy.random.Generator` (the same generator state gives the
same graph).
"""

from __future__ import annotations

import numpy as np

from fcplan.taskgraph.types import TaskGraph, TaskKind
from fcplan.team import DRAIN_PER_PX, Mode

__all__ = ["synthetic_task_graph"]


def synthetic_task_graph(
    n_agents: int,
    n_tasks: int,
    rng: np.random.Generator,
    *,
    world_size: int = 1200,
    perception_share: float = 0.5,
    fire_share: float = 0.5,
    tank: int = 10,
    battery: float = 500.0,
    speed_px_s: float = 200.0,
    comm_range: float | None = None,
) -> TaskGraph:
    """A random task graph for solver tests and scaling studies (no simulation behind it).

    Agents are split into perception (the first ``round(perception_share * n_agents)``, at least
    one) and action agents (at least one), spread over the map with their depot slots on the
    left edge. Tasks are fire tiles (``fire_share``) and search blocks at uniform random positions;
    fire values are 1..60 known cells weighted by a random facility threat, search values are
    ages of 0..60 s; fires belong to random clusters.

    Examples
    --------
    >>> import numpy as np
    >>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
    >>> g.n_agents, g.n_tasks, int(g.agent_can_act.sum()) >= 1
    (3, 6, True)
    """
    if n_agents < 2:
        raise ValueError("a synthetic team needs at least 2 agents (one to sense, one to act)")
    w = float(world_size)
    n_p = min(max(int(round(perception_share * n_agents)), 1), n_agents - 1)
    role = np.r_[np.zeros(n_p), np.ones(n_agents - n_p)].astype(np.int8)
    n_fire = int(round(fire_share * n_tasks))
    kind = np.r_[np.full(n_fire, TaskKind.FIRE), np.full(n_tasks - n_fire, TaskKind.SEARCH)]
    home = np.stack([np.full(n_agents, 60.0), np.linspace(0.1 * w, 0.9 * w, n_agents)], axis=1)
    pos = rng.uniform(0.05 * w, 0.95 * w, size=(n_agents, 2))
    full = battery / DRAIN_PER_PX
    used = rng.uniform(0.0, 0.5, n_agents) * full
    task_pos = rng.uniform(0.0, w, size=(n_tasks, 2))
    cells = np.where(kind == TaskKind.FIRE, rng.integers(1, 61, n_tasks), 0)
    threat = np.where(kind == TaskKind.FIRE, rng.choice([0.0, 0.0, 1.0, 2.0, 5.0], n_tasks), 0.0)
    age = rng.uniform(0.0, 60.0, n_tasks)
    value = np.where(kind == TaskKind.FIRE, cells * (1.0 + threat), age)
    stale = np.where(kind == TaskKind.FIRE, rng.uniform(0.0, 10.0, n_tasks), age)
    n_clusters = max(n_fire // 4, 1)
    cluster = np.where(kind == TaskKind.FIRE, rng.integers(0, n_clusters, n_tasks), -1)
    battery_left = battery - used * DRAIN_PER_PX
    way_home = np.hypot(*(home - pos).T)
    fac_pos = np.array([[0.5 * w, 0.5 * w]])
    return TaskGraph(
        tick=0,
        time_s=0.0,
        world_size=int(world_size),
        depot_pos=np.array([60.0, 0.5 * w]),
        agent_ids=tuple(f"{'P' if r == 0 else 'A'}{i + 1}" for i, r in enumerate(role)),
        agent_role=role,
        agent_pos=pos,
        agent_z=np.where(role == 0, 50.0, 30.0),
        agent_alt_range=np.where(role[:, None] == 0, [[10.0, 100.0]], [[30.0, 30.0]]),
        agent_speed=np.full(n_agents, float(speed_px_s)),
        agent_range=np.maximum(battery_left / DRAIN_PER_PX - way_home, 0.0),
        agent_full_range=np.full(n_agents, full),
        agent_battery=battery_left,
        agent_tank=np.where(role == 1, tank, 0).astype(np.int64),
        agent_tank_capacity=np.where(role == 1, tank, 0).astype(np.int64),
        agent_mode=np.full(n_agents, int(Mode.ACTIVE), dtype=np.int8),
        agent_home=home,
        agent_can_sense=role == 0,
        agent_can_act=role == 1,
        task_ids=tuple(
            f"{'fire' if k == TaskKind.FIRE else 'search'}:{i}" for i, k in enumerate(kind)
        ),
        task_kind=kind.astype(np.int8),
        task_pos=task_pos,
        task_value=value.astype(np.float64),
        task_cells=cells.astype(np.int64),
        task_staleness=stale,
        task_threat=threat,
        task_cluster=cluster.astype(np.int64),
        task_block=np.full(n_tasks, -1, dtype=np.int64),
        facility_kinds=("house",),
        facility_pos=fac_pos,
        facility_rect=np.array([[0.5 * w - 60, 0.5 * w + 60, 0.5 * w - 75, 0.5 * w + 75]]),
        facility_penalty=np.array([1.0]),
        threat_time_s=np.full((n_tasks, 1), np.inf),
        tile_px=(54.0, 31.0),
        known_cells=int(cells.sum()),
        comm_range=comm_range,
    )
