"""Candidate tasks, action masks and feature tables of the task-level environment.

At every step each agent is offered its ``k`` most relevant tasks of the current
:class:`fcplan.taskgraph.TaskGraph`. Everything here is a vectorised function of the graph (no
networkx, no Python loop over tasks), so it costs a few tens of microseconds per step.

Feasibility (the action mask)
    The legal tasks of agent ``i`` are :attr:`fcplan.taskgraph.TaskGraph.reachable`: exactly the
    one-task routes ``(task,)`` that :func:`fcplan.plan.validate_plan` accepts (the agent's role
    can serve the task, it lies within a round trip of the agent's depot slot on a full battery,
    and, unless the agent is on a forced return, it can fly there and home on what it has left).

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

Shared arrays
    What depends only on read-only arrays that the graphs of one
    :class:`fcplan.taskgraph.TaskGraphBuilder` share (the constant task-feature rows and who can
    serve a task of a fire-free graph, lists of per-agent constants) is computed once and kept
    in the graphs' :attr:`~fcplan.taskgraph.TaskGraph.shared_memo`: the same values as computing
    it every step.

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
from typing import Any

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
_POS1 = np.arange(1, 1 << 16)  # 1-based positions (task graphs hold far fewer tasks)
_ROWS = np.arange(256)[:, None]  # agent rows as a column, for fancy indexing


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
        a, k = self.rows.shape
        out = np.ones((a, k + 1), dtype=np.int8)
        out[:, :k] = self.valid
        return out


def legal_tasks(graph: TaskGraph) -> np.ndarray:
    """(A, T) bool: one-task routes :func:`fcplan.plan.validate_plan` accepts (a copy of
    :attr:`fcplan.taskgraph.TaskGraph.reachable`)."""
    return graph.reachable.copy()


def _candidates(
    rows: np.ndarray,
    start_distance: np.ndarray,
    priority: np.ndarray,
    freshness: np.ndarray,
    legal: np.ndarray,
    valid: np.ndarray | None = None,
) -> Candidates:
    """``Candidates(...)`` with ``valid`` defaulting to the slots holding a task."""
    return Candidates(
        rows=rows,
        valid=rows >= 0 if valid is None else valid,
        start_distance=start_distance,
        priority=priority,
        freshness=freshness,
        legal=legal,
    )


@lru_cache(maxsize=16)
def _ones(n: int) -> np.ndarray:
    """(n,) float64 ones (read-only): the freshness of search blocks."""
    out = np.ones(n)
    out.flags.writeable = False
    return out


def rank_candidates(graph: TaskGraph, k: int, *, fresh_s: float = 5.0) -> Candidates:
    """The ``k`` most relevant legal tasks of every agent (see the module docstring)."""
    n_a, n_t = graph.n_agents, graph.n_tasks
    legal = graph.reachable
    d_start = graph.start_task_distance
    kind = graph.task_kind
    # fires (kind 0) come first: none when the first task is a search block
    n_f = n_t - int(np.count_nonzero(kind)) if n_t and kind[0] == _FIRE else 0
    value = graph.task_value
    if n_f:
        fresh = np.ones(n_t)
        stale = graph.task_staleness[:n_f]
        fresh[:n_f] = np.minimum(np.exp(-(stale - fresh_s) / max(fresh_s, 1e-9)), 1.0)
        value = value * fresh  # (x * 1.0 == x: skipped when there is no fire)
    else:
        fresh = _ones(n_t)
    prio = value / (1.0 + d_start / graph.agent_speed[:, None])
    prio = np.where(legal, prio, -np.inf)
    if n_t == 0 or n_a == 0:
        return _candidates(np.full((n_a, k), -1, dtype=np.int64), d_start, prio, fresh, legal)
    m = min(k, n_t)
    order = np.argsort(np.negative(prio), axis=1, kind="stable")  # illegal (-inf) last
    n_legal = np.add.reduce(legal, axis=1)
    if n_f == 0:  # search blocks only: the best legal ones (the first n_legal), in order
        valid = _POS1[:m] <= n_legal[:, None]
        rows = np.where(valid, order[:, :m], -1)
        if m < k:
            rows = np.concatenate([rows, np.full((n_a, k - m), -1, dtype=np.int64)], axis=1)
            valid = None
        return _candidates(rows, d_start, prio, fresh, legal, valid)
    rows = np.full((n_a, k), -1, dtype=np.int64)
    ai = _ROWS[:n_a] if n_a <= _ROWS.shape[0] else np.arange(n_a)[:, None]
    # per agent, how many fires and search blocks to take (a handful of agents: Python ints)
    takes = [
        (tf := min(nf, max(k - k // 2, k - (nl - nf))), min(nl - nf, k - tf))
        for nl, nf in zip(
            n_legal.tolist(), np.add.reduce(legal[:, :n_f], axis=1).tolist(), strict=True
        )
    ]
    take_fire, take_search = np.array(takes, dtype=np.int64).T[:, :, None]
    # rank of each sorted task within its kind (1-based); illegal tasks rank beyond every take
    s_fire = order < n_f
    fire_rank = np.cumsum(s_fire, axis=1)
    pos1 = _POS1[:n_t] if n_t <= _POS1.size else np.arange(1, n_t + 1)
    chosen = np.where(s_fire, fire_rank <= take_fire, pos1 - fire_rank <= take_search)
    first = np.argsort(~chosen, axis=1, kind="stable")[:, :m]  # chosen slots, priority order
    valid = chosen[ai, first]
    rows[:, :m] = np.where(valid, order[ai, first], -1)
    return _candidates(rows, d_start, prio, fresh, legal)


def task_features(graph: TaskGraph, cand: Candidates, goal: np.ndarray) -> np.ndarray:
    """(A, k, F) float32 feature table (:data:`TASK_FEATURES`; padding rows are zero).

    ``goal`` is (A, 2): the position the environment last sent each agent to (NaN: none).
    """
    n_a, k = cand.rows.shape
    n_t = graph.n_tasks
    if n_t == 0:
        return np.zeros((n_a, k, len(TASK_FEATURES)), dtype=np.float32)
    w = float(graph.world_size)
    valid = cand.valid
    r = np.maximum(cand.rows, 0)
    ai = _ROWS[:n_a] if n_a <= _ROWS.shape[0] else np.arange(n_a)[:, None]
    sd = cand.start_distance
    # float64 work table, feature-major (F, A, k) so that every feature is a contiguous row;
    # transposed and cast once at the end (clipping before or after the cast gives the same
    # float32)
    out = np.empty((len(TASK_FEATURES), n_a, k))
    # per-task rows (features 1 .. 9), computed once over all tasks and gathered at once
    pt = _task_rows(graph, cand.freshness)
    np.log1p(graph.task_value, out=pt[2])
    pt[2] *= 0.2
    np.divide(graph.task_staleness, 60.0, out=pt[4])
    np.take(pt, r, axis=1, out=out[1:10])  # rows 8, 9: the task's position for now
    out[0] = 1.0
    # a goal is set (or not) as a whole position; NaN != NaN (Python floats: no numpy call)
    no_goal = [x != x for x in goal[:, 0].tolist()]
    if False in no_goal:
        gd = out[8:10] - goal.T[:, :, None]
        gd = np.hypot(gd[0], gd[1])
        gd /= -50.0
        np.exp(gd, out=out[16])
        if True in no_goal:  # NaN: no goal yet
            out[16][np.isnan(out[16])] = 0.0
    else:  # no agent has a goal yet
        out[16] = 0.0
    out[8:10] -= graph.agent_pos.T[:, :, None]
    dist = sd[ai, r]
    out[10] = dist
    out[12] = graph.task_home_distance[ai, r]
    # other capable agents: how many are closer, and how close is the nearest; incapable others
    # at +inf: never closer (distances are finite), never the nearest
    per_agent = _capable_per_agent(graph, n_a)
    if per_agent is None:
        capable = graph.can_do[:, r]  # (A_other, A, k)
        capable &= _not_self(n_a)
        d_cap = np.where(capable, sd[:, r], np.inf)
        n_cap = np.add.reduce(capable, axis=0)
        np.maximum(n_cap, 1, out=n_cap)
    else:  # who can serve does not depend on the task: (A_other, A, 1) and (A, 1)
        capable, n_cap = per_agent
        d_cap = np.where(capable, sd[:, r], np.inf)
    # min(d / w, 1) == min(d, w) / w
    np.minimum(np.minimum.reduce(d_cap, axis=0), w, out=out[14])
    out[11:14:2] = 0.0  # (rows 11 and 13, written below: no garbage through the division)
    out[8:15] /= w
    np.divide(dist, (10.0 * graph.agent_speed)[:, None], out=out[11])
    np.divide(np.add.reduce(d_cap < dist, axis=0), n_cap, out=out[13])
    prio = np.where(valid, cand.priority[ai, r], 0.0)
    best = [b if b > 0 else np.inf for b in np.maximum.reduce(prio, axis=1).tolist()]
    np.divide(prio, np.array(best)[:, None], out=out[15])
    out[:, ~valid] = 0.0
    _clip(out)
    return out.transpose(1, 2, 0).astype(np.float32, order="C")


def _capable_per_agent(graph: TaskGraph, n_a: int) -> tuple[np.ndarray, np.ndarray] | None:
    """For a shared read-only ``can_do`` whose every row is constant (graphs without fire: only
    the agent's camera matters), the (A_other, A, 1) bool "other agent j can serve agent i's
    tasks" and the (A, 1) int64 ``max(count, 1)`` of those agents; else None."""
    can_do, memo = graph.can_do, graph.shared_memo
    if memo is None or can_do.flags.writeable or can_do.shape[1] == 0:
        return None
    return memo.get("capable_per_agent", (can_do,), lambda: _capable_table(can_do, n_a))


def _capable_table(can_do: np.ndarray, n_a: int) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`_capable_per_agent` computed (read-only arrays)."""
    if not (can_do == can_do[:, :1]).all():
        return None
    capable = can_do[:, :1][:, None, :] & _not_self(n_a)  # (A_other, A, 1)
    n_cap = np.add.reduce(capable, axis=0)
    np.maximum(n_cap, 1, out=n_cap)
    capable.flags.writeable = n_cap.flags.writeable = False
    return capable, n_cap


def _task_rows(graph: TaskGraph, freshness: np.ndarray) -> np.ndarray:
    """(9, T) float64 rows of task features 1 .. 9 (kinds, log value and cells, staleness, log
    threat, freshness, position) with the rows that do not depend on the step filled in: all but
    rows 2 (log value) and 4 (staleness), which the caller fills.

    Graphs of one builder without fire share their kind, cell, threat and position arrays
    (read-only) and their freshness (all ones): those rows are computed once per set of arrays
    (kept in the graphs' memo) and copied.
    """
    src = (graph.task_kind, graph.task_cells, graph.task_threat, graph.task_pos, freshness)
    memo = graph.shared_memo
    if memo is None or any(a.flags.writeable for a in src):
        return _make_task_rows(graph, freshness)
    kept = memo.get("task_rows", src, lambda: _make_task_rows(graph, freshness))
    return kept.copy()


def _make_task_rows(graph: TaskGraph, freshness: np.ndarray) -> np.ndarray:
    """:func:`_task_rows` computed."""
    pt = np.empty((9, graph.n_tasks))
    pt[1] = graph.task_kind  # is_search: kinds are 0 (fire) and 1 (search)
    np.subtract(1.0, pt[1], out=pt[0])
    np.log1p(graph.task_cells, out=pt[3])
    pt[3] *= 0.2
    np.log1p(graph.task_threat, out=pt[5])
    pt[6] = freshness
    pt[7:9] = graph.task_pos.T
    return pt


def _clip(out: np.ndarray) -> None:
    """Clip to ``[-FEATURE_BOUND, FEATURE_BOUND]`` in place (two ufunc calls: cheaper than
    ``np.clip``'s wrapper; the same values, NaN kept)."""
    np.minimum(out, FEATURE_BOUND, out=out)
    np.maximum(out, -FEATURE_BOUND, out=out)


@lru_cache(maxsize=64)
def _not_self(n: int) -> np.ndarray:
    """(n, n, 1) bool: True off the diagonal (read-only)."""
    m = ~np.eye(n, dtype=bool)[:, :, None]
    m.flags.writeable = False
    return m


def agent_features(graph: TaskGraph, cand: Candidates, time_fraction: float) -> np.ndarray:
    """(A, S) float32 own-state vectors (:data:`AGENT_FEATURES`)."""
    # a handful of agents: plain Python floats (the same IEEE arithmetic as numpy's)
    w = float(graph.world_size)
    n_a = graph.n_agents
    known = float(np.log1p(graph.known_cells)) / 10.0 if graph.known_cells else 0.0
    kind = graph.task_kind
    if graph.n_tasks and kind[0] == _FIRE:  # (fires come first: else none)
        # valid slots holding one of the n_f fires (rows 0 .. n_f - 1), counted in Python
        n_f = graph.n_tasks - int(np.count_nonzero(kind))
        k = max(cand.k, 1)
        share = [
            sum(1 for r, v in zip(rw, vl, strict=True) if v and r < n_f) / k
            for rw, vl in zip(cand.rows.tolist(), cand.valid.tolist(), strict=True)
        ]
    else:
        share = [0.0] * n_a
    one_hot = _MODE_ROWS
    rows = [
        [
            x / w,
            y / w,
            z / 100.0,
            bat / max(full * DRAIN_PER_PX, 1e-9),
            tank / max(cap, 1) if cap > 0 else 0.0,
            sense,
            act,
            *one_hot[mode],
            time_fraction,
            rng / max(full, 1e-9),
            hx / w,
            hy / w,
            known,
            sh,
        ]
        for (x, y), z, bat, (full, cap, sense, act, (hx, hy)), tank, mode, rng, sh in zip(
            graph.agent_pos.tolist(),
            graph.agent_z.tolist(),
            graph.agent_battery.tolist(),
            _agent_constants(graph),
            graph.agent_tank.tolist(),
            graph.agent_mode.tolist(),
            graph.agent_range.tolist(),
            share,
            strict=True,
        )
    ]
    out = np.array(rows, dtype=np.float64).reshape(n_a, len(AGENT_FEATURES))
    _clip(out)
    return out.astype(np.float32)


def _agent_constants(graph: TaskGraph) -> list[tuple[Any, ...]]:
    """Per agent, its full range, tank capacity, camera and water flags and depot slot (Python
    numbers; kept in the memo of a builder's graphs, whose arrays of these never change)."""
    src = (
        graph.agent_full_range,
        graph.agent_tank_capacity,
        graph.agent_can_sense,
        graph.agent_can_act,
        graph.agent_home,
    )
    memo = graph.shared_memo
    if memo is None or any(a.flags.writeable for a in src):
        return _zip_lists(src)
    return memo.get("agent_constants", src, lambda: _zip_lists(src))


def _zip_lists(arrays: tuple[np.ndarray, ...]) -> list[tuple[Any, ...]]:
    """Per row, the rows of ``arrays`` as Python numbers (or lists)."""
    return list(zip(*(a.tolist() for a in arrays), strict=True))


def _as_list(graph: TaskGraph, name: str) -> list[Any]:
    """``getattr(graph, name).tolist()``, kept in the graph's memo for the read-only arrays the
    graphs of a builder share (the per-team constants); the caller must not change the list."""
    a: np.ndarray = getattr(graph, name)
    memo = graph.shared_memo
    if memo is None or a.flags.writeable:
        out: list[Any] = a.tolist()
        return out
    return memo.get("list:" + name, (a,), a.tolist)


_MODE_ONE_HOT = np.eye(4)[[int(Mode.IDLE), int(Mode.ACTIVE), int(Mode.RETURNING), int(Mode.HOMING)]]
_MODE_ROWS = {int(m): tuple(_MODE_ONE_HOT[int(m)].tolist()) for m in Mode}
