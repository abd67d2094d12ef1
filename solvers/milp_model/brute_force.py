"""Exact optimum of tiny models by enumeration: the tests' ground truth.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> from solvers.milp_model import build_milp_model
>>> from solvers.milp import solve_cpsat
>>> m = build_milp_model(g)
>>> x, best = brute_force_optimum(m)
>>> bool(np.isclose(solve_cpsat(m)[1].objective, best))
True
"""

from __future__ import annotations

import itertools

import numpy as np

from solvers.milp_model.types import ROUTE, MilpModel

__all__ = ["brute_force_optimum"]


def brute_force_optimum(
    model: MilpModel, max_combinations: int = 2_000_000, chunk: int = 16_384
) -> tuple[np.ndarray, float]:
    """Exact optimum of a tiny model by enumeration (ground truth for tests).

    Every agent picks one of its routes or none; all such combinations are enumerated (in
    chunks) and checked against every row. The cover and freeze variables have non-negative
    objective coefficients and each row holds at most one of them, so for fixed routes their
    best values are the largest their rows allow (:meth:`MilpModel.best_auxiliaries`, computed
    here for a whole chunk at once).

    Parameters
    ----------
    model : MilpModel
    max_combinations : int
        Refuse (``ValueError``) models with more combinations than this.
    chunk : int
        Combinations checked per numpy batch.

    Returns
    -------
    x : ndarray, (n,) float64
        An optimal solution (the first in enumeration order among ties).
    objective : float
    """
    n, n_r = model.n_vars, model.n_routes
    aux = np.flatnonzero(model.var_kind != ROUTE)
    if np.any(model.c[aux] < 0):
        raise ValueError("cover and freeze variables must have non-negative coefficients")
    a_r = model.A_ub[:, :n_r].toarray()
    a_z = model.A_ub[:, aux].toarray()
    if np.any(a_z < 0) or np.any((a_z != 0).sum(axis=1) > 1):
        raise ValueError(
            "cover and freeze variables must appear with a positive coefficient, one per row"
        )
    if n_r == 0:  # nothing to choose: every variable is 0
        return np.zeros(n), 0.0
    agents = np.unique(model.route_agent)
    groups = [np.flatnonzero(model.route_agent == a) for a in agents]
    total = int(np.prod([g.size + 1 for g in groups], dtype=np.float64)) if groups else 1
    if total > max_combinations:
        raise ValueError(f"{total} combinations exceed max_combinations={max_combinations}")
    # per row: the aux column it bounds (or -1) and that coefficient
    row_aux = np.full(model.n_rows, -1)
    row_coef = np.ones(model.n_rows)
    if aux.size:
        row_aux = np.where((a_z != 0).any(axis=1), np.argmax(a_z != 0, axis=1), -1)
        row_coef = np.where(row_aux >= 0, a_z[np.arange(model.n_rows), np.maximum(row_aux, 0)], 1.0)
    c_r, c_z = model.c[:n_r], model.c[aux]
    best_val, best_x = -np.inf, np.zeros(n)
    combos = itertools.product(*[np.r_[-1, g] for g in groups])
    while True:
        block = np.array(list(itertools.islice(combos, chunk)), dtype=np.int64)
        if block.size == 0:
            break
        block = block.reshape(-1, len(groups))
        ys = np.zeros((block.shape[0], n_r))
        r, col = np.nonzero(block >= 0)
        ys[r, block[r, col]] = 1.0
        slack = model.b_ub[None, :] - ys @ a_r.T  # (N, m), aux at 0
        # routes alone must fit the rows without an aux variable (aux rows: aux >= 0 fits)
        free_rows = row_aux < 0
        feas = np.all(slack[:, free_rows] >= -1e-9, axis=1)
        zs = np.tile(model.ub[aux], (block.shape[0], 1))
        lim = np.floor(slack / row_coef[None, :] + 1e-9)
        for j in range(aux.size):
            rows_j = np.flatnonzero(row_aux == j)
            if rows_j.size:
                zs[:, j] = np.minimum(zs[:, j], lim[:, rows_j].min(axis=1))
        feas &= np.all(zs >= 0, axis=1)
        zs = np.maximum(zs, 0.0)
        val = np.where(feas, ys @ c_r + zs @ c_z, -np.inf)
        i = int(np.argmax(val))
        if val[i] > best_val + 1e-12:
            best_val = float(val[i])
            best_x = np.zeros(n)
            best_x[:n_r] = ys[i]
            best_x[aux] = zs[i]
    return best_x, best_val
