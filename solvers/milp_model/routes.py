"""Route enumeration: who may do what, candidate tasks, and every short route with its exact
arrival times and length.

For agent ``a`` (start :attr:`~fcplan.taskgraph.TaskGraph.agent_start_pos` ``s_a``, speed ``v_a``,
budget :attr:`~fcplan.taskgraph.TaskGraph.agent_budget_px` ``b_a``, depot slot ``h_a``) a route
``k_1 .. k_n`` is flown from ``s_a``; an agent on a forced return first flies home (it
recharges there), which delays every arrival by ``t0_a = |p_a - s_a| / v_a``. Arrival times are
exact for straight flights at the agent's own speed::

    t_1 = t0_a + |s_a k_1| / v_a,     t_j = t_{j-1} + |k_{j-1} k_j| / v_a

and a route is kept only if the whole flight fits the budget,
``|s_a k_1| + sum_j |k_j k_{j+1}| + |k_n h_a| <= b_a``, which is
:meth:`~fcplan.taskgraph.TaskGraph.route_ok` (so every kept route is also
:attr:`~fcplan.taskgraph.TaskGraph.reachable` at its first task by the triangle inequality).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> cands = np.flatnonzero(agent_roles(g).ok1[2])[:3]
>>> tasks, arrival, px = enumerate_routes(g, 2, cands, 2, 0.0)
>>> len(tasks) <= 3 + 3 * 2, all(g.route_ok(2, t[t >= 0].tolist()) for t in tasks)
(True, True)
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.taskgraph.types import pairwise_distance
from fcplan.team import Mode

__all__ = ["AgentRoles", "agent_roles", "enumerate_routes", "top_candidates"]


@dataclass(frozen=True, eq=False)
class AgentRoles:
    """What each agent may do this replan, and where and when its next route starts."""

    dumper: np.ndarray  # (A,) bool can act with water left (a full tank on a forced return)
    sensor: np.ndarray  # (A,) bool has a camera
    tank: np.ndarray  # (A,) int64 dumps available for the next route
    t0: np.ndarray  # (A,) s before the next route starts (the flight home on a forced return)
    ok1: np.ndarray  # (A, K) bool the one-task route (k,) is flyable and suits the role


def agent_roles(graph: TaskGraph) -> AgentRoles:
    """The :class:`AgentRoles` of ``graph``'s agents (every mode: an agent sent home can be
    given a route again)."""
    forced = graph.agent_mode == Mode.RETURNING
    tank = np.where(forced, graph.agent_tank_capacity, graph.agent_tank).astype(np.int64)
    dumper = graph.agent_can_act & (tank > 0)
    sensor = graph.agent_can_sense.copy()
    speed = np.maximum(graph.agent_speed, 1e-9)
    away = np.hypot(*(graph.agent_pos - graph.agent_start_pos).T)
    t0 = np.where(forced, away / speed, 0.0)
    fire = graph.task_kind == TaskKind.FIRE
    role_ok = (fire[None, :] & (dumper | sensor)[:, None]) | (~fire[None, :] & sensor[:, None])
    d1 = graph.start_task_distance + graph.task_home_distance
    ok1 = role_ok & graph.in_round_trip & (d1 <= graph.agent_budget_px[:, None])
    return AgentRoles(dumper=dumper, sensor=sensor, tank=tank, t0=t0, ok1=ok1)


def top_candidates(score: np.ndarray, allowed: np.ndarray, n: int) -> np.ndarray:
    """Rows of the ``n`` best ``allowed`` entries of ``score`` (ties: lower row first), best
    first, only those with a positive score."""
    rows = np.flatnonzero(allowed & (score > 0))
    if rows.size == 0:
        return rows
    order = np.lexsort((rows, -score[rows]))
    out: np.ndarray = rows[order[:n]]
    return out


@lru_cache(maxsize=64)
def _orders(m: int, length: int) -> np.ndarray:
    """(P, length) every ordered selection of 1..length of ``m`` items, padded with -1, shorter
    first (read-only)."""
    parts = []
    for n in range(1, min(length, m) + 1):
        perm = np.array(list(itertools.permutations(range(m), n)), dtype=np.int64)
        parts.append(np.pad(perm.reshape(-1, n), ((0, 0), (0, length - n)), constant_values=-1))
    out = np.concatenate(parts) if parts else np.zeros((0, length), dtype=np.int64)
    out.flags.writeable = False
    return out


def enumerate_routes(
    graph: TaskGraph,
    agent: int,
    cands: np.ndarray,
    length: int,
    t0: float,
    first: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every route of ``agent`` over the candidate task rows ``cands`` with at most ``length``
    tasks that fits its budget (module docstring); with ``first`` (bool, one per candidate),
    only routes that start at a candidate marked True.

    Returns
    -------
    tasks : ndarray, (P, length) int64
        Task rows in visiting order, padded with -1.
    arrival : ndarray, (P, length) float64
        Arrival time at each task (s from now), NaN on padding.
    px : ndarray, (P,) float64
        Length of the whole flight, the way home included.
    """
    m = int(cands.size)
    if m == 0 or length < 1:
        return np.zeros((0, length), np.int64), np.zeros((0, length)), np.zeros(0)
    order = _orders(m, length)  # (P, L) local indices
    if first is not None:
        order = order[np.asarray(first, dtype=bool)[order[:, 0]]]
    d_start = graph.start_task_distance[agent, cands]
    d_home = graph.task_home_distance[agent, cands]
    # only the candidates' distances: the graph's (K, K) table costs O(K^2) time and memory
    # (2,000 tasks: 32 MB and tens of ms), of which a model reads a few hundred entries
    pos = graph.task_pos[cands]
    d_between = pairwise_distance(pos, pos)
    valid = order >= 0
    idx = np.where(valid, order, 0)
    leg = np.zeros(order.shape)
    leg[:, 0] = d_start[idx[:, 0]]
    if length > 1:
        leg[:, 1:] = np.where(valid[:, 1:], d_between[idx[:, :-1], idx[:, 1:]], 0.0)
    flown = np.cumsum(leg, axis=1)
    n_tasks = valid.sum(axis=1)
    last = idx[np.arange(len(order)), n_tasks - 1]
    px = flown[:, -1] + d_home[last]
    keep = px <= graph.agent_budget_px[agent]
    speed = max(float(graph.agent_speed[agent]), 1e-9)
    arrival = np.where(valid, t0 + flown / speed, np.nan)
    tasks = np.where(valid, cands[idx], -1)
    return tasks[keep], arrival[keep], px[keep]
