"""Candidates and feature tables of many task graphs at once: the batched kernel of
:mod:`fcplan.env.task_candidates`.

:func:`batch_observe` takes the graphs of ``B`` worlds of one scenario (the same agents; ragged
task sets) and returns, for every graph, exactly what :func:`~fcplan.env.task_candidates.
rank_candidates`, :func:`~fcplan.env.task_candidates.task_features` and
:func:`~fcplan.env.task_candidates.agent_features` return for it alone (bit for bit:
``tests/env/test_task_batch.py``). Those functions stay the specification; here the same
element-wise operations run on padded arrays with a batch axis in front:

==================  ======================  ==================================================
array               shape                   notes
==================  ======================  ==================================================
task fields         (B, T)                  ``T`` the largest task count; world ``b``'s
                                            tasks in rows ``0 .. T_b - 1`` (fires first),
                                            padding after them (never legal)
distance tables     (B, A, T)               agent-task and task-home px
                                            (:func:`fcplan.taskgraph.pairwise_distance`'s
                                            operations), the feasibility rule of
                                            :attr:`fcplan.taskgraph.TaskGraph.reachable`
agent fields        (B, A)                  stacked from the graphs
==================  ======================  ==================================================

The ranking sorts each agent's padded row (padding, illegal, sorts last: after every real task,
so the rows, ranks and ties of the real tasks are the single graph's), and the per-agent split
between fire and search slots is computed for all agents at once. The per-world
:class:`~fcplan.env.task_candidates.Candidates` are views of the batch's arrays (their task
axis cut to the world's ``T_b``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from fcplan.env.task_candidates import (
    _MODE_ROWS,
    AGENT_FEATURES,
    FEATURE_BOUND,
    TASK_FEATURES,
    Candidates,
)
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.taskgraph.types import FEASIBILITY_TOL_PX
from fcplan.team import DRAIN_PER_PX, Mode

__all__ = ["GraphBatch", "BatchObservation", "stack_graphs", "batch_observe"]

_FIRE, _SEARCH, _RETURNING = int(TaskKind.FIRE), int(TaskKind.SEARCH), int(Mode.RETURNING)
_MODE_TABLE = np.array([_MODE_ROWS.get(m, (np.nan,) * 4) for m in range(max(_MODE_ROWS) + 1)])


@dataclass(eq=False)
class GraphBatch:
    """``B`` task graphs of one team as padded arrays (module docstring; ``T`` >= 1)."""

    n_tasks: np.ndarray  # (B,) int64
    n_fire: np.ndarray  # (B,) int64 fire tasks (rows 0 .. n_fire - 1)
    kind: np.ndarray  # (B, T) int8 (padding: search)
    pos: np.ndarray  # (B, T, 2)
    value: np.ndarray  # (B, T)
    stale: np.ndarray  # (B, T)
    cells: np.ndarray  # (B, T) int64
    threat: np.ndarray  # (B, T)
    agent_pos: np.ndarray  # (B, A, 2)
    home: np.ndarray  # (B, A, 2)
    speed: np.ndarray  # (B, A)
    can_sense: np.ndarray  # (B, A) bool
    mode: np.ndarray  # (B, A) int8
    full_range: np.ndarray  # (B, A)
    battery: np.ndarray  # (B, A)
    dist: np.ndarray  # (B, A, T) agent-task px
    home_dist: np.ndarray  # (B, A, T) task-home px
    start_dist: np.ndarray  # (B, A, T) px from where the next route starts
    can_do: np.ndarray  # (B, A, T) bool
    legal: np.ndarray  # (B, A, T) bool: TaskGraph.reachable (False on padding)


class BatchObservation(NamedTuple):
    """What :func:`batch_observe` returns (``B`` graphs, ``A`` agents, ``k`` slots)."""

    #: ``rank_candidates(graphs[b], k)`` of each graph
    candidates: list[Candidates]
    #: (B, A, k, F) float32 ``task_features`` of each graph, stacked
    tasks: np.ndarray
    #: (B, A, S) float32 ``agent_features`` of each graph, stacked
    agents: np.ndarray
    #: (B, A, k) int64 task row of each slot (``-1``: padding) and (B, A, k) bool legal slots
    rows: np.ndarray
    valid: np.ndarray
    #: (B, A, k, 2) position of each slot's task, (B, A, k) bool: it is a fire, and (B, A, k)
    #: seconds of flight to it from where the agent's next route starts (``start_distance /
    #: agent_speed``, the conflict rule's arrival time; padding slots: those of task row 0)
    slot_pos: np.ndarray
    slot_fire: np.ndarray
    slot_eta: np.ndarray


def _pad(parts: list[np.ndarray], flat: np.ndarray, shape: tuple[int, ...], fill: float,
         dtype: type) -> np.ndarray:  # fmt: skip
    """Per-graph arrays of ragged length scattered into a padded ``shape`` array (``flat``:
    the flat index ``b * T + t`` of each task of the concatenated arrays)."""
    out: np.ndarray = np.full(shape, fill, dtype=dtype)
    if flat.size:
        out.reshape(shape[0] * shape[1], *shape[2:])[flat] = np.concatenate(parts)
    return out


def _stack(graphs: Sequence[TaskGraph], name: str) -> np.ndarray:
    """``np.stack`` of the graphs' arrays ``name`` (one concatenation: cheaper)."""
    parts = [getattr(g, name) for g in graphs]
    return np.concatenate(parts).reshape(len(parts), *parts[0].shape)


def _distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(B, P, Q) :func:`fcplan.taskgraph.types.pairwise_distance` of (B, P, 2) and (B, Q, 2)."""
    dx = a[:, :, 0, None] - b[:, None, :, 0]
    dy = a[:, :, 1, None] - b[:, None, :, 1]
    dx *= dx
    dy *= dy
    dx += dy
    return np.sqrt(dx, out=dx)


def stack_graphs(graphs: Sequence[TaskGraph]) -> GraphBatch:
    """The padded arrays of ``graphs`` (the same agents in each) and their distance tables and
    feasibility rule (:attr:`fcplan.taskgraph.TaskGraph.reachable`), computed together."""
    n = len(graphs)
    nt = np.array([g.n_tasks for g in graphs], dtype=np.int64)
    t = max(int(nt.max(initial=0)), 1)
    where = np.arange(int(nt.sum())) + np.repeat(np.arange(n) * t - (np.cumsum(nt) - nt), nt)
    kind = _pad([g.task_kind for g in graphs], where, (n, t), _SEARCH, np.int8)
    first_fire = (nt > 0) & (kind[:, 0] == _FIRE)
    n_fire = np.where(first_fire, t - np.count_nonzero(kind, axis=1), 0)
    pos = _pad([g.task_pos for g in graphs], where, (n, t, 2), 0.0, np.float64)
    agent_pos = _stack(graphs, "agent_pos")
    home = _stack(graphs, "agent_home")
    dist, home_dist = _distance(agent_pos, pos), _distance(home, pos)
    mode = _stack(graphs, "agent_mode")
    forced = mode == _RETURNING
    can_sense = _stack(graphs, "agent_can_sense")
    full = _stack(graphs, "agent_full_range")
    battery = _stack(graphs, "agent_battery")
    can_do = (kind == _FIRE)[:, None, :] | can_sense[:, :, None]
    legal = 2.0 * home_dist <= (full + FEASIBILITY_TOL_PX)[:, :, None]
    legal &= can_do
    ok = dist + home_dist <= (battery / DRAIN_PER_PX)[:, :, None] + FEASIBILITY_TOL_PX
    ok |= forced[:, :, None]
    legal &= ok
    legal &= np.arange(t) < nt[:, None, None]
    return GraphBatch(
        n_tasks=nt,
        n_fire=n_fire,
        kind=kind,
        pos=pos,
        value=_pad([g.task_value for g in graphs], where, (n, t), 0.0, np.float64),
        stale=_pad([g.task_staleness for g in graphs], where, (n, t), 0.0, np.float64),
        cells=_pad([g.task_cells for g in graphs], where, (n, t), 0, np.int64),
        threat=_pad([g.task_threat for g in graphs], where, (n, t), 0.0, np.float64),
        agent_pos=agent_pos,
        home=home,
        speed=_stack(graphs, "agent_speed"),
        can_sense=can_sense,
        mode=mode,
        full_range=full,
        battery=battery,
        dist=dist,
        home_dist=home_dist,
        start_dist=np.where(forced[:, :, None], home_dist, dist),
        can_do=can_do,
        legal=legal,
    )


def _rank(gb: GraphBatch, k: int, fresh_s: float) -> tuple[np.ndarray, ...]:
    """(rows, valid, priority, freshness) of every graph: ``rank_candidates`` with a batch axis."""
    n, a, t = gb.legal.shape
    nf = gb.n_fire[:, None]
    fresh = np.minimum(np.exp(-(gb.stale - fresh_s) / max(fresh_s, 1e-9)), 1.0)
    fresh = np.where(np.arange(t) < nf, fresh, 1.0)
    value = gb.value * fresh
    prio = value[:, None, :] / (1.0 + gb.start_dist / gb.speed[:, :, None])
    prio = np.where(gb.legal, prio, -np.inf)
    order = np.argsort(np.negative(prio), axis=2, kind="stable")  # illegal, padding last
    n_legal = np.add.reduce(gb.legal, axis=2)
    legal_fire = np.add.reduce(gb.legal & (np.arange(t) < nf[:, :, None]), axis=2)
    take_fire = np.minimum(legal_fire, np.maximum(k - k // 2, k - (n_legal - legal_fire)))
    take_search = np.minimum(n_legal - legal_fire, k - take_fire)
    s_fire = order < nf[:, :, None]
    fire_rank = np.cumsum(s_fire, axis=2)
    pos1 = np.arange(1, t + 1)
    chosen = np.where(
        s_fire, fire_rank <= take_fire[:, :, None], pos1 - fire_rank <= take_search[:, :, None]
    )
    # the chosen tasks in priority order fill the first slots (at most k are chosen); the
    # others are padding
    slot = np.cumsum(chosen, axis=2)
    slot -= 1
    bi, ai, ti = np.nonzero(chosen)
    rows = np.full((n, a, k), -1, dtype=np.int64)
    rows[bi, ai, slot[bi, ai, ti]] = order[bi, ai, ti]
    return rows, rows >= 0, prio, fresh


def _task_table(gb: GraphBatch, rows: np.ndarray, valid: np.ndarray, prio: np.ndarray,
                fresh: np.ndarray, goal: np.ndarray, w: np.ndarray) -> np.ndarray:  # fmt: skip
    """(B, A, k, F) float32 ``task_features`` of every graph."""
    n, a, k = rows.shape
    out = np.empty((len(TASK_FEATURES), n, a, k))
    r = np.maximum(rows, 0)
    bi = np.arange(n)[:, None, None]
    pt = np.empty((9, n, gb.kind.shape[1]))
    pt[1] = gb.kind
    np.subtract(1.0, pt[1], out=pt[0])
    np.log1p(gb.value, out=pt[2])
    pt[2] *= 0.2
    np.log1p(gb.cells, out=pt[3])
    pt[3] *= 0.2
    np.divide(gb.stale, 60.0, out=pt[4])
    np.log1p(gb.threat, out=pt[5])
    pt[6] = fresh
    pt[7:9] = gb.pos.transpose(2, 0, 1)
    out[1:10] = pt[:, bi, r]
    out[0] = 1.0
    gd = out[8:10] - goal.transpose(2, 0, 1)[:, :, :, None]
    gd = np.hypot(gd[0], gd[1])
    gd /= -50.0
    np.exp(gd, out=out[16])
    out[16][np.isnan(out[16])] = 0.0
    out[8:10] -= gb.agent_pos.transpose(2, 0, 1)[:, :, :, None]
    dist = np.take_along_axis(gb.start_dist, r, axis=2)
    out[10] = dist
    out[12] = np.take_along_axis(gb.home_dist, r, axis=2)
    oth = np.arange(a)[None, :, None, None]
    rr = r[:, None, :, :]  # (B, 1, A, k): agent i's slots, seen by every other agent j
    capable = gb.can_do[bi[:, :, :, None], oth, rr]  # (B, A_other, A, k)
    capable &= ~np.eye(a, dtype=bool)[None, :, :, None]
    d_cap = np.where(capable, gb.start_dist[bi[:, :, :, None], oth, rr], np.inf)
    n_cap = np.add.reduce(capable, axis=1)
    np.maximum(n_cap, 1, out=n_cap)
    np.minimum(np.minimum.reduce(d_cap, axis=1), w, out=out[14])
    out[11:14:2] = 0.0
    out[8:15] /= w
    np.divide(dist, (10.0 * gb.speed)[:, :, None], out=out[11])
    np.divide(np.add.reduce(d_cap < dist[:, None], axis=1), n_cap, out=out[13])
    p = np.where(valid, np.take_along_axis(prio, r, axis=2), 0.0)
    best = np.maximum.reduce(p, axis=2)
    best = np.where(best > 0, best, np.inf)
    np.divide(p, best[:, :, None], out=out[15])
    out[:, ~valid] = 0.0
    np.minimum(out, FEATURE_BOUND, out=out)
    np.maximum(out, -FEATURE_BOUND, out=out)
    return out.transpose(1, 2, 3, 0).astype(np.float32, order="C")


def _agent_table(graphs: Sequence[TaskGraph], gb: GraphBatch, rows: np.ndarray,
                 valid: np.ndarray, time_fraction: np.ndarray) -> np.ndarray:  # fmt: skip
    """(B, A, S) float32 ``agent_features`` of every graph."""
    n, a, k = rows.shape
    w = np.array([float(g.world_size) for g in graphs])[:, None]
    known = np.array([g.known_cells for g in graphs], dtype=np.int64)
    log_known = np.where(known > 0, np.log1p(known) / 10.0, 0.0)
    full = gb.full_range
    cap = _stack(graphs, "agent_tank_capacity")
    out = np.empty((n, a, len(AGENT_FEATURES)))
    out[:, :, 0] = gb.agent_pos[:, :, 0] / w
    out[:, :, 1] = gb.agent_pos[:, :, 1] / w
    out[:, :, 2] = _stack(graphs, "agent_z") / 100.0
    out[:, :, 3] = gb.battery / np.maximum(full * DRAIN_PER_PX, 1e-9)
    tank = _stack(graphs, "agent_tank")
    out[:, :, 4] = np.where(cap > 0, tank / np.maximum(cap, 1), 0.0)
    out[:, :, 5] = gb.can_sense
    out[:, :, 6] = _stack(graphs, "agent_can_act")
    out[:, :, 7:11] = _MODE_TABLE[gb.mode]
    out[:, :, 11] = time_fraction[:, None]
    out[:, :, 12] = _stack(graphs, "agent_range") / np.maximum(full, 1e-9)
    out[:, :, 13] = gb.home[:, :, 0] / w
    out[:, :, 14] = gb.home[:, :, 1] / w
    out[:, :, 15] = log_known[:, None]
    fire_slots = np.add.reduce(valid & (rows < gb.n_fire[:, None, None]), axis=2)
    out[:, :, 16] = fire_slots / max(k, 1)
    np.minimum(out, FEATURE_BOUND, out=out)
    np.maximum(out, -FEATURE_BOUND, out=out)
    return out.astype(np.float32)


def batch_observe(
    graphs: Sequence[TaskGraph],
    k: int,
    goal: np.ndarray,
    time_fraction: np.ndarray,
    *,
    fresh_s: float = 5.0,
) -> BatchObservation:
    """Candidates, task features and agent features of ``B`` graphs of one team at once.

    Parameters
    ----------
    graphs : sequence of TaskGraph
        ``B`` graphs with the same agents (any task sets).
    k : int
        Candidate slots per agent.
    goal : ndarray, (B, A, 2)
        Per graph the ``goal`` of :func:`~fcplan.env.task_candidates.task_features`.
    time_fraction : ndarray, (B,)
        Per graph the ``time_fraction`` of :func:`~fcplan.env.task_candidates.agent_features`.

    Returns
    -------
    BatchObservation
        Per graph ``rank_candidates(graphs[b], k, fresh_s=fresh_s)``, ``task_features(graphs[b],
        candidates[b], goal[b])`` and ``agent_features(graphs[b], candidates[b],
        time_fraction[b])``, and the slots' task rows, positions and kinds.
    """
    gb = stack_graphs(graphs)
    rows, valid, prio, fresh = _rank(gb, k, fresh_s)
    w = np.array([float(g.world_size) for g in graphs])[:, None, None]
    tasks = _task_table(gb, rows, valid, prio, fresh, goal, w)
    agents = _agent_table(graphs, gb, rows, valid, time_fraction)
    cands = [
        Candidates(
            rows=rows[b],
            valid=valid[b],
            start_distance=gb.start_dist[b, :, :nt],
            priority=prio[b, :, :nt],
            freshness=fresh[b, :nt],
            legal=gb.legal[b, :, :nt],
        )
        for b, nt in enumerate(gb.n_tasks.tolist())
    ]
    bi = np.arange(len(graphs))[:, None, None]
    r = np.maximum(rows, 0)
    slot_pos = gb.pos[bi, r]
    slot_fire = gb.kind[bi, r] == _FIRE
    slot_eta = np.take_along_axis(gb.start_dist, r, axis=2) / gb.speed[:, :, None]
    return BatchObservation(cands, tasks, agents, rows, valid, slot_pos, slot_fire, slot_eta)
