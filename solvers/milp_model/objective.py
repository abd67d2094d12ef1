"""The objective's terms: negative reward avoided over the horizon (see :mod:`solvers.milp_model`).

Every value is in the manual's penalty units (``0.1`` per active cell per second plus ``PC_f``
per active cell inside facility ``f`` per second), counted over the horizon ``H``:

* a dump on fire task ``k`` at ``t``: ``q n_k w_k (H - t)+`` with ``w_k = 0.1 + theta sum_f
  PC_f (1 - tau_kf / H)+`` (``tau_kf``: the graph's ``threat_time_s``);
* a search block ``b`` of value ``g_b`` (the graph's ``task_value``: capped coverage age, more
  near known fire) hides ``kappa g_b`` undiscovered burning cells, worth ``V_b = 0.1 kappa g_b H``
  when found now; a route that sweeps it ``t`` seconds from now finds them with probability
  ``p`` (:mod:`solvers.milp_model.sensing`) and earns ``V_b p (H - t)+ / H``;
* a connected fire ``c`` dumped on *and* watched stops growing: ``0.1 q gamma (H - t_c)+^2 / 2``
  with ``t_c`` the earliest arrival of an agent with water at one of its tasks.
"""

from __future__ import annotations

import numpy as np

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.sensing import segment_coverage
from solvers.milp_model.types import MilpParams

__all__ = ["block_values", "dump_value", "fire_weight", "route_cover", "straight_cover"]

#: Penalty per active cell per second (the manual's propagation weight).
CELL_RATE = 0.1


def fire_weight(graph: TaskGraph, p: MilpParams) -> np.ndarray:
    """(K,) ``w_k``: the penalty rate of one of task ``k``'s cells, facility threats included
    (0 for search tasks)."""
    fires = graph.task_cells > 0
    h = p.horizon_s
    tau = graph.threat_time_s
    w = np.full(graph.n_tasks, CELL_RATE)
    if tau.size and graph.facility_penalty.size:
        share = np.clip(1.0 - tau / h, 0.0, 1.0)  # inf -> 0
        w[: tau.shape[0]] += p.threat_weight * share @ graph.facility_penalty
    out: np.ndarray = np.where(fires, w, 0.0)
    return out


def dump_value(
    graph: TaskGraph, p: MilpParams, weight: np.ndarray, tasks: np.ndarray, arrival: np.ndarray
) -> np.ndarray:
    """Value of dumping on task rows ``tasks`` (any shape, -1: nothing) at ``arrival`` s."""
    valid = tasks >= 0
    k = np.where(valid, tasks, 0)
    t = np.where(valid, arrival, p.horizon_s)
    gain = p.prune_confidence * graph.task_cells[k] * weight[k] * np.maximum(p.horizon_s - t, 0.0)
    out: np.ndarray = np.where(valid, gain, 0.0)
    return out


def block_values(graph: TaskGraph, p: MilpParams, blocks: np.ndarray) -> np.ndarray:
    """(B,) ``V_b`` of the search task rows ``blocks``."""
    out: np.ndarray = CELL_RATE * p.search_weight * p.horizon_s * graph.task_value[blocks]
    return out


def straight_cover(
    graph: TaskGraph,
    agent: int,
    ends: np.ndarray,
    blocks: np.ndarray,
    z: float,
    t0: float,
    p: MilpParams,
) -> np.ndarray:
    """(E, B) discounted detection ``p (H - t)+ / H`` of ``blocks`` by straight flights from
    the agent's start (at ``t0``) to each of the points ``ends`` (E, 2) at altitude ``z``."""
    start = np.broadcast_to(graph.agent_start_pos[agent], ends.shape)
    return _discounted(graph, agent, start, ends, blocks, z, np.full(len(ends), t0), p)


def _discounted(
    graph: TaskGraph,
    agent: int,
    a: np.ndarray,
    b: np.ndarray,
    blocks: np.ndarray,
    z: float,
    t_start: np.ndarray,
    p: MilpParams,
) -> np.ndarray:
    lo, hi = graph.agent_alt_range[agent]
    speed = float(graph.agent_speed[agent])
    share, when = segment_coverage(
        a, b, graph.task_pos[blocks], p.search_block_px, z, float(lo), float(hi), speed
    )
    late = t_start[:, None] + when
    hs = p.search_horizon_s
    out: np.ndarray = share * np.maximum(hs - late, 0.0) / hs
    return out


def route_cover(
    graph: TaskGraph,
    agent: int,
    tasks: np.ndarray,
    arrival: np.ndarray,
    blocks: np.ndarray,
    z: float,
    t0: float,
    p: MilpParams,
) -> np.ndarray:
    """(P, B) discounted detection of ``blocks`` by each route (rows of ``tasks`` / ``arrival``,
    padded with -1 / NaN) flown at altitude ``z``: per block the best of the route's legs."""
    n_routes, length = tasks.shape
    cover = np.zeros((n_routes, blocks.size))
    if n_routes == 0 or blocks.size == 0:
        return cover
    start = graph.agent_start_pos[agent]
    for j in range(length):
        on = tasks[:, j] >= 0
        if not on.any():
            break
        rows = np.flatnonzero(on)
        to = graph.task_pos[tasks[rows, j]]
        if j == 0:
            frm = np.broadcast_to(start, to.shape)
            t_start = np.full(rows.size, t0)
        else:
            frm = graph.task_pos[tasks[rows, j - 1]]
            t_start = arrival[rows, j - 1]
        # legs repeat across routes: compute each distinct (from, to, start time) once
        key = np.c_[frm, to, t_start]
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        leg = _discounted(graph, agent, uniq[:, :2], uniq[:, 2:4], blocks, z, uniq[:, 4], p)
        cover[rows] = np.maximum(cover[rows], leg[inv.ravel()])
    return cover
