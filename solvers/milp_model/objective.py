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

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp_model import MilpParams
>>> g = synthetic_task_graph(2, 2, np.random.default_rng(0), fire_share=1.0)
>>> p = MilpParams(horizon_s=30.0, threat_weight=0.0)
>>> k = np.array([0]); v = dump_value(g, p, fire_weight(g, p), k, np.array([10.0]))
>>> bool(np.isclose(v[0], 0.9 * g.task_cells[0] * 0.1 * (30.0 - 10.0)))
True
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.kernels import discounted_coverage, near_cells_each, whole_counts
from solvers.milp_model.types import MilpParams

__all__ = [
    "FireSnapshot",
    "block_values",
    "dump_value",
    "fire_weight",
    "hidden_cells",
    "near_known_cells",
    "route_cover",
    "straight_cover",
]

#: Penalty per active cell per second (the manual's propagation weight).
CELL_RATE = 0.1
#: Coverage age (s) at which a block's value is the same for every ``search_age_exponent``.
AGE_UNIT_S = 60.0


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


class FireSnapshot:
    """The fire tasks of one graph (positions (F, 2), cells (F,)) and, once asked for, the most
    known cells near each of a set of block centres (:meth:`near`), kept for the next models.

    The MILP schedulers keep the snapshots of the last ``recent_fire_s`` seconds (a few dozen in
    an episode that replans several times a second) and every model counts the known cells near
    each block in each of them: a snapshot kept by the scheduler counts them once for the blocks
    of every model after it (they change only when the graph's blocks do).

    Examples
    --------
    >>> s = FireSnapshot(np.array([[50.0, 50.0]]), np.array([3.0]))
    >>> s.near(np.array([[50.0, 50.0], [500.0, 50.0]]), 150.0).tolist()
    [3.0, 0.0]
    """

    __slots__ = ("pos", "cells", "_centres", "_reach", "_near")

    def __init__(self, pos: np.ndarray, cells: np.ndarray) -> None:
        self.pos = np.asarray(pos, np.float64).reshape(-1, 2)
        self.cells = np.asarray(cells, np.float64)
        self._centres: np.ndarray | None = None
        self._reach = np.nan
        self._near = np.zeros(0)

    def counted(self, centres: np.ndarray, reach: float) -> bool:
        """True when :meth:`near` of ``centres`` and ``reach`` is known already."""
        c = self._centres
        return c is not None and reach == self._reach and np.array_equal(c, centres)

    def keep(self, centres: np.ndarray, reach: float, near: np.ndarray) -> None:
        """Remember ``near`` as the counts for ``centres`` and ``reach``."""
        self._centres, self._reach, self._near = np.array(centres, np.float64), reach, near

    def near(self, centres: np.ndarray, reach: float) -> np.ndarray:
        """(B,) the known cells of this snapshot within ``reach`` of each of ``centres``."""
        if not self.counted(centres, reach):
            count_near([self], centres, reach)
        return self._near


def count_near(snapshots: Sequence[FireSnapshot], centres: np.ndarray, reach: float) -> None:
    """Count the known cells near ``centres`` in every snapshot not yet counted for them: the
    fast kernel (:func:`~solvers.milp_model.kernels.near_cells_each`) for whole cell counts, all
    such snapshots at once, and the readable rule for the others (their sums depend on order)."""
    todo = [s for s in snapshots if not s.counted(centres, reach)]
    whole = [s for s in todo if whole_counts([(s.pos, s.cells)])]
    if whole:
        each = near_cells_each(centres, [(s.pos, s.cells) for s in whole], reach)
        for s, row in zip(whole, each, strict=True):
            s.keep(centres, reach, row)
    for s in todo:
        if not s.counted(centres, reach):
            s.keep(centres, reach, near_known_cells(centres, [(s.pos, s.cells)], reach))


def hidden_cells(
    graph: TaskGraph,
    p: MilpParams,
    blocks: np.ndarray,
    recent_fire: Sequence[FireSnapshot | tuple[np.ndarray, np.ndarray]] = (),
) -> np.ndarray:
    """(B,) undiscovered burning cells expected in the search task rows ``blocks``:
    ``kappa A60 (A_b / A60) ** alpha (1 + min(n_b, 50) / 10)`` with ``A_b`` the block's
    coverage age (its ``task_staleness``, capped at ``search_age_cap_s``), ``A60 = 60`` s and
    ``n_b`` the most known burning cells in the 3 x 3 blocks around it, now or in any of the
    ``recent_fire`` snapshots (:class:`FireSnapshot` or ``(positions (F, 2), cells (F,))`` of
    the fire tasks of recent graphs): fire spreads from known fire, and fronts a dump did not
    freeze run on after the fire they belong to is put out. ``n_b`` is what
    :func:`near_known_cells` gives over all the snapshots (the snapshots count apart, each with
    the exact kernel where its counts are whole, so the result is the rule's bit for bit)."""
    age = np.minimum(graph.task_staleness[blocks], p.search_age_cap_s)
    fires = graph.fire_tasks
    snapshots = [FireSnapshot(graph.task_pos[fires], graph.task_cells[fires])]
    snapshots += [s if isinstance(s, FireSnapshot) else FireSnapshot(*s) for s in recent_fire]
    centres, reach = graph.task_pos[blocks], 1.5 * p.search_block_px
    count_near(snapshots, centres, reach)
    near = np.zeros(len(blocks))
    for s in snapshots:
        np.maximum(near, s.near(centres, reach), out=near)
    scale = AGE_UNIT_S * (np.maximum(age, 0.0) / AGE_UNIT_S) ** p.search_age_exponent
    out: np.ndarray = p.search_weight * scale * (1.0 + np.minimum(near, 50.0) / 10.0)
    return out


def near_known_cells(
    centres: np.ndarray, snapshots: Sequence[tuple[np.ndarray, np.ndarray]], reach: float
) -> np.ndarray:
    """(B,) the most known cells within ``reach`` (px, along each axis) of each of ``centres``
    (B, 2) in any snapshot of fire tasks (positions (F, 2), cells (F,)): the readable rule, one
    dense (blocks x fires) test per snapshot. :func:`hidden_cells` uses its fast twin,
    :func:`solvers.milp_model.kernels.near_cells_each`, equal to it, when the cells are whole
    numbers (they count cells), and this rule otherwise."""
    near = np.zeros(len(centres))
    for pos, cells in snapshots:
        if len(cells) and len(centres):
            gap = np.abs(centres[:, None, :] - np.asarray(pos)[None, :, :])
            close = np.all(gap <= reach, axis=2)
            np.maximum(near, close.astype(np.float64) @ np.asarray(cells, np.float64), out=near)
    return near


def block_values(
    graph: TaskGraph,
    p: MilpParams,
    blocks: np.ndarray,
    recent_fire: Sequence[FireSnapshot | tuple[np.ndarray, np.ndarray]] = (),
) -> np.ndarray:
    """(B,) ``V_b = 0.1 H E_b`` of the search task rows ``blocks``, with ``E_b`` their
    :func:`hidden_cells`."""
    out: np.ndarray = CELL_RATE * p.horizon_s * hidden_cells(graph, p, blocks, recent_fire)
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
    """(S, B) ``share (H_s - t)+ / H_s`` of ``blocks`` under the segments ``a -> b`` started at
    ``t_start``: :func:`~solvers.milp_model.sensing.discounted_share` (by its fast kernel,
    :func:`solvers.milp_model.kernels.discounted_coverage`, equal to it bit for bit)."""
    lo, hi = graph.agent_alt_range[agent]
    return discounted_coverage(
        a, b, graph.task_pos[blocks], p.search_block_px, z, float(lo), float(hi),
        float(graph.agent_speed[agent]), t_start, p.search_horizon_s,
    )  # fmt: skip


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
