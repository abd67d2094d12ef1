"""Candidate tasks, action masks and feature tables of the task-level environment.

At every step each agent is offered its ``k`` most relevant tasks of the current
:class:`fcplan.taskgraph.TaskGraph`. Everything here is a vectorised function of the graph (no
networkx, no Python loop over tasks), so it costs a few tens of microseconds per step.

Feasibility (the action mask)
    A task is legal for agent ``i`` exactly when :func:`fcplan.plan.validate_plan` would accept
    the one-task route ``(task,)``: the agent's role can serve it (search blocks need a camera),
    it lies within a round trip of the agent's depot slot on a full battery, and, unless the agent
    is on a forced return (it recharges first), it can fly there and home on what it has left.

Relevance (the deterministic ranking)
    ``priority = value * freshness / (1 + eta)``, with ``value`` the task's value in the graph
    (fire: known cells weighted by facility threat; search: age of the block's coverage),
    ``freshness = 1`` for a fire sensed within ``fresh_s`` seconds and ``exp(-(s - fresh_s) /
    fresh_s)`` after that (1 for search blocks), and ``eta`` the flight time in seconds from
    where the agent's next route starts (its depot slot if it is on a forced return). Agents
    with a camera get at least ``ceil(k / 2)`` fire tasks and at least ``k // 2`` search blocks
    when that many are legal (the rest of the slots go to the other kind); action-only agents
    get fires only. The chosen tasks are listed by decreasing priority; ties go to the lower task
    row (a stable sort). Missing slots are padding (task row ``-1``, mask 0).

Task features (one row of the ``k x F`` table, see :data:`TASK_FEATURES`)
    all finite, clipped to ``[-FEATURE_BOUND, FEATURE_BOUND]``; padding rows are all zero.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 10, np.random.default_rng(0))
>>> c = rank_candidates(g, 4)
>>> c.rows.shape, bool((c.rows[c.valid] >= 0).all())
((3, 4), True)
>>> task_features(g, c, np.full((3, 2), np.nan)).shape
(3, 4, 17)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import DRAIN_PER_PX, Mode

__all__ = [
    "Candidates",
    "TASK_FEATURES",
    "AGENT_FEATURES",
    "FEATURE_BOUND",
    "legal_tasks",
    "rank_candidates",
    "task_features",
    "agent_features",
]

#: Names of the columns of the task-feature table (``F = len(TASK_FEATURES)``).
TASK_FEATURES = (
    "valid",  # 1 for a real candidate, 0 for padding
    # properties of the task (the same for every agent)
    "is_fire",
    "is_search",
    "log_value",  # log1p(task value) / 5
    "log_cells",  # log1p(known burning cells) / 5
    "staleness_min",  # seconds since sensed (fire) or covered (search) / 60
    "log_threat",  # log1p(penalty-weighted facility closeness)
    "freshness",  # the ranking's freshness factor
    # the task seen from this agent
    "dx",  # (task x - agent x) / W
    "dy",  # (task y - agent y) / W
    "distance",  # px from where the next route starts / W
    "eta_10s",  # flight time / 10 s
    "home_distance",  # px from the task to the agent's depot slot / W
    "closer_share",  # share of the other capable agents that are closer to the task
    "nearest_other",  # px from the nearest other capable agent / W (1 if none)
    "relative_priority",  # priority / the agent's best candidate priority
    "current_goal",  # exp(-px from the goal the env last gave this agent / 50)
)

#: Names of the entries of an agent's own-state vector.
AGENT_FEATURES = (
    "x",  # / W
    "y",  # / W
    "z_100m",  # altitude / 100 m
    "battery",  # fraction of capacity
    "tank",  # fraction of capacity (0 without a tank)
    "can_sense",
    "can_act",
    "idle",
    "active",
    "returning",
    "homing",
    "time",  # elapsed fraction of the episode
    "range",  # px it can still fly out and back / full-battery range
    "home_x",  # / W
    "home_y",  # / W
    "log_known_cells",  # log1p(known burning cells) / 10
    "fire_candidates",  # share of its candidate slots holding fire tasks
)

#: Every feature is clipped to ``[-FEATURE_BOUND, FEATURE_BOUND]``.
FEATURE_BOUND = 10.0

# plain ints: comparing arrays with IntEnum members goes through slow enum attribute lookups
_FIRE, _SEARCH = int(TaskKind.FIRE), int(TaskKind.SEARCH)
_RETURNING = int(Mode.RETURNING)
_POS1 = np.arange(1, 1 << 16)  # 1-based positions (task graphs hold far fewer tasks)


@dataclass(frozen=True, eq=False)
class Candidates:
    """Per-agent candidate tasks of one step.

    Attributes
    ----------
    rows : ndarray, (A, k) int64
        Task rows of the graph per slot, ``-1`` for padding.
    valid : ndarray, (A, k) bool
        Slot holds a legal task.
    start_distance : ndarray, (A, T) float64
        Px from where each agent's next route starts to each task.
    priority : ndarray, (A, T) float64
        Ranking score (``-inf`` where illegal).
    freshness : ndarray, (T,) float64
    legal : ndarray, (A, T) bool
        Every legal task (also those outside the top ``k``).
    """

    rows: np.ndarray
    valid: np.ndarray
    start_distance: np.ndarray
    priority: np.ndarray
    freshness: np.ndarray
    legal: np.ndarray

    @property
    def k(self) -> int:
        """Slots per agent."""
        return self.rows.shape[1]

    def action_mask(self) -> np.ndarray:
        """(A, k + 1) int8: legal candidate slots, then the always-legal no-op."""
        a = self.rows.shape[0]
        return np.concatenate([self.valid, np.ones((a, 1), dtype=bool)], axis=1).astype(np.int8)


def legal_tasks(graph: TaskGraph) -> np.ndarray:
    """(A, T) bool: one-task routes :func:`fcplan.plan.validate_plan` accepts (same arithmetic)."""
    d = graph.agent_task_distance
    dh = graph.task_home_distance
    ok = graph.can_do & (2.0 * dh <= graph.agent_full_range[:, None] + 1e-6)
    forced = graph.agent_mode == _RETURNING
    have = graph.agent_battery / DRAIN_PER_PX
    return ok & (forced[:, None] | (d + dh <= have[:, None] + 1e-6))


def rank_candidates(graph: TaskGraph, k: int, *, fresh_s: float = 5.0) -> Candidates:
    """The ``k`` most relevant legal tasks of every agent (see the module docstring)."""
    n_a, n_t = graph.n_agents, graph.n_tasks
    legal = legal_tasks(graph)
    forced = graph.agent_mode == _RETURNING
    d_start = graph.agent_task_distance
    if forced.any():
        d_start = np.where(forced[:, None], graph.task_home_distance, d_start)
    is_fire = graph.task_kind == _FIRE
    n_f = int(np.count_nonzero(is_fire))  # fire tasks come first in a task graph
    fresh = np.ones(n_t)
    if n_f:
        stale = graph.task_staleness[:n_f]
        fresh[:n_f] = np.minimum(np.exp(-(stale - fresh_s) / max(fresh_s, 1e-9)), 1.0)
    prio = (graph.task_value * fresh) / (1.0 + d_start / graph.agent_speed[:, None])
    prio[~legal] = -np.inf
    rows = np.full((n_a, k), -1, dtype=np.int64)
    if n_t == 0 or n_a == 0:
        return Candidates(rows, rows >= 0, d_start, prio, fresh, legal)
    ai = np.arange(n_a)[:, None]
    order = np.argsort(-prio, axis=1, kind="stable")  # illegal (-inf) last
    n_fire = legal[:, :n_f].sum(axis=1)
    n_search = legal[:, n_f:].sum(axis=1)
    take_fire = np.minimum(n_fire, np.maximum(k - k // 2, k - n_search))[:, None]
    take_search = np.minimum(n_search[:, None], k - take_fire)
    # rank of each sorted task within its kind (1-based); illegal tasks rank beyond every take
    s_fire = order < n_f
    fire_rank = np.cumsum(s_fire, axis=1)
    pos1 = _POS1[:n_t] if n_t <= _POS1.size else np.arange(1, n_t + 1)
    chosen = np.where(s_fire, fire_rank <= take_fire, pos1 - fire_rank <= take_search)
    m = min(k, n_t)
    first = np.argsort(~chosen, axis=1, kind="stable")[:, :m]  # chosen slots, priority order
    valid = chosen[ai, first]
    rows[:, :m] = np.where(valid, order[ai, first], -1)
    return Candidates(rows, rows >= 0, d_start, prio, fresh, legal)


def task_features(graph: TaskGraph, cand: Candidates, goal: np.ndarray) -> np.ndarray:
    """(A, k, F) float32 feature table (:data:`TASK_FEATURES`; padding rows are zero).

    ``goal`` is (A, 2): the position the environment last sent each agent to (NaN: none).
    """
    n_a, k = cand.rows.shape
    if graph.n_tasks == 0:
        return np.zeros((n_a, k, len(TASK_FEATURES)), dtype=np.float32)
    w = float(graph.world_size)
    r = np.maximum(cand.rows, 0)
    ai = np.arange(n_a)[:, None]
    pos = graph.task_pos[r]  # (A, k, 2)
    dist = cand.start_distance[ai, r]
    # other capable agents: how many are closer, and how close is the nearest
    d_all = cand.start_distance[:, r]  # (A_other, A, k)
    capable = graph.can_do[:, r] & _not_self(n_a)
    n_cap = capable.sum(axis=0)
    closer = (capable & (d_all < dist)).sum(axis=0)
    d_all[~capable] = np.inf
    nearest = d_all.min(axis=0)
    prio = np.where(cand.valid, cand.priority[ai, r], 0.0)
    best = prio.max(axis=1)
    # per-task columns, computed once over all tasks and gathered
    per_task = np.empty((graph.n_tasks, 7))
    per_task[:, 0] = graph.task_kind == _FIRE
    per_task[:, 1] = 1.0 - per_task[:, 0]
    per_task[:, 2] = graph.task_value
    per_task[:, 3] = graph.task_cells
    per_task[:, 4] = graph.task_threat
    np.log1p(per_task[:, 2:5], out=per_task[:, 2:5])
    per_task[:, 2:4] *= 0.2
    per_task[:, 5] = per_task[:, 4]
    per_task[:, 4] = graph.task_staleness / 60.0
    per_task[:, 6] = cand.freshness
    out = np.empty((n_a, k, len(TASK_FEATURES)), dtype=np.float32)
    out[..., 0] = 1.0
    out[..., 1:8] = per_task[r]
    out[..., 8:10] = (pos - graph.agent_pos[:, None, :]) / w
    out[..., 10] = dist / w
    out[..., 11] = dist / (10.0 * graph.agent_speed[:, None])
    out[..., 12] = graph.task_home_distance[ai, r] / w
    out[..., 13] = closer / np.maximum(n_cap, 1)
    out[..., 14] = np.minimum(nearest / w, 1.0)
    out[..., 15] = prio / np.where(best > 0, best, np.inf)[:, None]
    gd = np.hypot(pos[..., 0] - goal[:, None, 0], pos[..., 1] - goal[:, None, 1])
    out[..., 16] = np.where(np.isnan(gd), 0.0, np.exp(-gd / 50.0))  # NaN: no goal yet
    out[~cand.valid] = 0.0
    np.clip(out, -FEATURE_BOUND, FEATURE_BOUND, out=out)
    return out


@lru_cache(maxsize=64)
def _not_self(n: int) -> np.ndarray:
    """(n, n, 1) bool: True off the diagonal (read-only)."""
    m = ~np.eye(n, dtype=bool)[:, :, None]
    m.flags.writeable = False
    return m


def agent_features(graph: TaskGraph, cand: Candidates, time_fraction: float) -> np.ndarray:
    """(A, S) float32 own-state vectors (:data:`AGENT_FEATURES`)."""
    w = float(graph.world_size)
    out = np.empty((graph.n_agents, len(AGENT_FEATURES)), dtype=np.float64)
    out[:, 0:2] = graph.agent_pos / w
    out[:, 2] = graph.agent_z / 100.0
    out[:, 3] = graph.agent_battery / np.maximum(graph.agent_full_range * DRAIN_PER_PX, 1e-9)
    tank_cap = graph.agent_tank_capacity
    out[:, 4] = np.where(tank_cap > 0, graph.agent_tank / np.maximum(tank_cap, 1), 0.0)
    out[:, 5] = graph.agent_can_sense
    out[:, 6] = graph.agent_can_act
    out[:, 7:11] = _MODE_ONE_HOT[graph.agent_mode]
    out[:, 11] = time_fraction
    out[:, 12] = graph.agent_range / np.maximum(graph.agent_full_range, 1e-9)
    out[:, 13:15] = graph.agent_home / w
    out[:, 15] = np.log1p(graph.known_cells) / 10.0
    if graph.n_tasks:
        fire = graph.task_kind[np.maximum(cand.rows, 0)] == _FIRE
        out[:, 16] = (fire & cand.valid).sum(axis=1) / max(cand.k, 1)
    else:
        out[:, 16] = 0.0
    np.clip(out, -FEATURE_BOUND, FEATURE_BOUND, out=out)
    return out.astype(np.float32)


_MODE_ONE_HOT = np.eye(4)[[int(Mode.IDLE), int(Mode.ACTIVE), int(Mode.RETURNING), int(Mode.HOMING)]]
