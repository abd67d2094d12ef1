"""The model's constraint rows, all ``A_ub x <= b_ub`` with integral entries, by family (see
:mod:`solvers.milp_model` for each): ``slot``, ``order``, ``once``, ``spread``, ``tank``,
``battery``, ``couple_dump`` and ``couple_watch``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.types import DUMP, SEARCH, WATCH, MilpParams
from solvers.milp_model.variables import Variables

__all__ = ["model_rows"]


class _Rows:
    """Constraint rows collected family by family (in COO form)."""

    def __init__(self) -> None:
        self.rows_i: list[np.ndarray] = []
        self.cols_j: list[np.ndarray] = []
        self.vals: list[np.ndarray] = []
        self.rhs: list[np.ndarray] = []
        self.fam: list[str] = []
        self.n_rows = 0

    def add(
        self,
        group: np.ndarray,
        cols: np.ndarray,
        coef: np.ndarray,
        b_of_group: Callable[[np.ndarray], np.ndarray],
        name: str,
    ) -> None:
        """Rows from a group label per entry (entries with the same label share a row)."""
        if group.size == 0:
            return
        labels, inv = np.unique(group, return_inverse=True)
        self.rows_i.append(self.n_rows + inv)
        self.cols_j.append(cols)
        self.vals.append(np.asarray(coef, dtype=np.float64))
        self.rhs.append(np.asarray(b_of_group(labels), dtype=np.float64))
        self.fam.extend([name] * labels.size)
        self.n_rows += labels.size

    def matrix(self, n: int) -> tuple[sp.csr_array, np.ndarray]:
        """The (rows, n) matrix and the right-hand sides."""
        if not self.rows_i:
            return sp.csr_array((0, n)), np.zeros(0)
        mat = sp.csr_array(
            (
                np.concatenate(self.vals),
                (np.concatenate(self.rows_i), np.concatenate(self.cols_j)),
            ),
            shape=(self.n_rows, n),
        )
        mat.sum_duplicates()
        return mat, np.concatenate(self.rhs)


def _ones(lab: np.ndarray) -> np.ndarray:
    return np.ones(lab.size)


def _zeros(lab: np.ndarray) -> np.ndarray:
    return np.zeros(lab.size)


def model_rows(
    graph: TaskGraph, p: MilpParams, v: Variables
) -> tuple[sp.csr_array, np.ndarray, tuple[str, ...]]:
    """The constraint matrix, right-hand sides and row families of the model (module
    docstring), in the order slot, order, once, spread, tank, battery, couple_dump,
    couple_watch."""
    rows = _Rows()
    _assignment_rows(rows, p, v)
    _spread_rows(rows, graph, p, v)
    _resource_rows(rows, graph, p, v)
    if v.n_z:
        _coupling_rows(rows, graph, v)
    mat, b = rows.matrix(v.n_x + v.n_z)
    return mat, b, tuple(rows.fam)


def _assignment_rows(rows: _Rows, p: MilpParams, v: Variables) -> None:
    """``slot``, ``order`` and ``once`` rows."""
    va, vk, vs, vkind, n_slots = v.va, v.vk, v.vs, v.vkind, p.slots
    n_x = v.n_x
    xi = np.arange(n_x)
    ones = np.ones(n_x)
    # one task per (agent, slot)
    rows.add(va * n_slots + vs, xi, ones, _ones, "slot")
    # slots in order: slot-s vars (+1) and slot-(s-1) vars (-1) of the same agent, for s >= 1
    later = vs >= 1
    ord_group = np.r_[va[later] * n_slots + vs[later], va * n_slots + vs + 1]
    ord_cols = np.r_[xi[later], xi]
    ord_coef = np.r_[np.ones(later.sum()), -np.ones(n_x)]
    has_later = np.isin(ord_group, va[later] * n_slots + vs[later])
    rows.add(ord_group[has_later], ord_cols[has_later], ord_coef[has_later], _zeros, "order")
    # each task at most once per kind (dump, watch, search) over all agents and slots; with
    # spread_px > 0 the search rows are replaced by the spread rows below (which imply them)
    once = (vkind != SEARCH) | (p.spread_px <= 0)
    rows.add(vk[once] * 3 + vkind[once], xi[once], ones[once], _ones, "once")


def _spread_rows(rows: _Rows, graph: TaskGraph, p: MilpParams, v: Variables) -> None:
    """``spread`` rows: at most one search assignment among the blocks within ``spread_px`` of
    any candidate block (searchers do not crowd; an agent's two slots go to blocks apart)."""
    srch = np.flatnonzero(v.vkind == SEARCH)
    if not (p.spread_px > 0 and srch.size):
        return
    blocks, bidx = np.unique(v.vk[srch], return_inverse=True)
    near = graph.task_distance[np.ix_(blocks, blocks)] <= p.spread_px  # (U, U)
    # drop rows whose neighbourhood is contained in another's (they are implied)
    inter = near.astype(np.int64) @ near.T.astype(np.int64)
    cnt = near.sum(axis=1)
    sub = (inter == cnt[:, None]) & (
        (cnt[None, :] > cnt[:, None])
        | (
            (cnt[None, :] == cnt[:, None])
            & (np.arange(blocks.size)[None, :] < np.arange(blocks.size)[:, None])
        )
    )
    np.fill_diagonal(sub, False)
    rows_u = np.flatnonzero(~sub.any(axis=1))
    ru, rv = np.nonzero(near[np.ix_(rows_u, bidx)])
    rows.add(ru, srch[rv], np.ones(ru.size), _ones, "spread")


def _resource_rows(rows: _Rows, graph: TaskGraph, p: MilpParams, v: Variables) -> None:
    """``tank`` and ``battery`` rows, only where they can bind."""
    va, vk, vs, vkind, n_slots = v.va, v.vk, v.vs, v.vkind, p.slots
    xi = np.arange(v.n_x)
    ones = np.ones(v.n_x)
    tank, rng_px = v.tank, v.rng_px
    # tank (only where it binds: fewer dumps left than slots)
    tank_rows = (vkind == DUMP) & (tank[va] < n_slots)
    rows.add(va[tank_rows], xi[tank_rows], ones[tank_rows], lambda lab: tank[lab], "tank")
    # battery (only where the worst case exceeds the range)
    coef = np.where(vs == 0, v.first_leg[va, vk], v.later_leg[va, vk])
    worst = np.zeros((graph.n_agents, n_slots))
    np.maximum.at(worst, (va, vs), coef)
    bat_rows = worst.sum(axis=1)[va] > rng_px[va]
    rows.add(va[bat_rows], xi[bat_rows], coef[bat_rows], lambda lab: rng_px[lab], "battery")


def _coupling_rows(rows: _Rows, graph: TaskGraph, v: Variables) -> None:
    """``couple_dump`` and ``couple_watch`` rows of the auxiliary ``z``."""
    va, vk, vs, vkind, zk, zs = v.va, v.vk, v.vs, v.vkind, v.zk, v.zs
    # z[k,s] <= sum_a dump[a,k,s]
    dump = np.flatnonzero(vkind == DUMP)
    match = (vk[dump][None, :] == zk[:, None]) & (vs[dump][None, :] == zs[:, None])
    _couple(rows, v, dump, match, "couple_dump")
    # z[k,s] <= sum of sensors on the same cluster in slots <= s
    sensor = np.flatnonzero((vkind == WATCH) | ((vkind == DUMP) & graph.agent_can_sense[va]))
    cl = graph.task_cluster
    match = (cl[vk[sensor]][None, :] == cl[zk][:, None]) & (vs[sensor][None, :] <= zs[:, None])
    _couple(rows, v, sensor, match, "couple_watch")


def _couple(rows: _Rows, v: Variables, cols: np.ndarray, match: np.ndarray, name: str) -> None:
    """One row per ``z[k, s]``: ``z[k, s] - sum of the x in cols matching it <= 0`` (``match``:
    (n_z, len(cols)) bool)."""
    n_z = v.n_z
    zr, j = np.nonzero(match)
    rows.add(
        np.r_[np.arange(n_z), zr],
        np.r_[v.n_x + np.arange(n_z), cols[j]],
        np.r_[np.ones(n_z), -np.ones(zr.size)],
        _zeros,
        name,
    )
