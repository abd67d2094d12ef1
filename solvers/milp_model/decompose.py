"""Independent parts of a route model, restricted models, and a bound without a solver.

**Parts.** Two routes interact only through a row they share (one agent, one fire task, one
connected fire, one search block). The connected components of the graph joining every column
to its rows are independent problems: the optimum of the model is the sum of their optima, each
solved on its own (:func:`components`). Agents far apart, or a team split between separate
fires, give small parts that a solver proves optimal at once.

**Restricted models.** :func:`restrict` fixes every route outside a set of *free* routes at its
value in a solution ``x`` and keeps the free routes and the auxiliaries (covers, freezes) of
their rows as variables; the rows that hold a free column keep the fixed routes' share on their
right-hand side, and every row of a free auxiliary is kept. Each row holds at most one
auxiliary, so an auxiliary outside the free set appears in no kept row. Any solution of the restricted model, put back into ``x``, satisfies every
row of the full model, and its objective differs from the full one by a constant; this is the
move of the large-neighbourhood search (:mod:`solvers.milp_model.lns`).

**Bound.** Covers are concave (``min(L, .)``) and each freeze needs a route in it, so
``c @ x <= sum_r y_r g_r + sum_z c_z`` with ``g_r`` the gain of route ``r`` alone; each agent
flies one route, hence :func:`gain_bound` ``= sum_a max_r g_r + sum_z c_z`` bounds every solution.
It is loose (overlapping sweeps counted twice) but needs no solver. :func:`loose_bound` is
coarser still and costs one pass over the objective: each agent's best route value of its own
plus every auxiliary at its upper bound (``c @ x <= sum_a max_r c_r+ + sum_z c_z+ ub_z``); the
search uses it for the parts a deadline left unsolved.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp_model import brute_force_optimum, build_milp_model
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> m = build_milp_model(g)
>>> parts = components(m)
>>> sum(p.size for p in parts) == m.n_routes
True
>>> x, best = brute_force_optimum(m)
>>> sub = restrict(m, parts[0], x)
>>> bool(sub.model.is_feasible(x[sub.cols])), gain_bound(m) >= best
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from solvers.milp_model.start import Gains
from solvers.milp_model.types import ROUTE, MilpModel

__all__ = ["Restricted", "components", "gain_bound", "loose_bound", "restrict"]


@dataclass(frozen=True, eq=False)
class Restricted:
    """A restricted model and where its columns and rows come from."""

    model: MilpModel  # routes first, then auxiliaries, as in the full model
    cols: np.ndarray  # (n',) its columns in the full model (ascending)
    rows: np.ndarray  # (m',) its rows in the full model (ascending)
    offset: float  # objective of the fixed columns: full objective = offset + sub objective


def components(model: MilpModel) -> list[np.ndarray]:
    """The route columns of each independent part of ``model`` (ascending, parts ordered by
    their first route)."""
    n, m = model.n_vars, model.n_rows
    if model.n_routes == 0:
        return []
    coo = model.A_ub.tocoo()
    adj = sp.coo_array((np.ones(coo.nnz), (coo.col, n + coo.row)), shape=(n + m, n + m)).tocsr()
    _, label = connected_components(adj, directed=False)
    route_label = label[: model.n_routes]
    order = np.argsort(route_label, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(route_label[order]) != 0])
    parts = np.split(order, starts[1:])
    parts.sort(key=lambda p: int(p[0]))
    return parts


def restrict(model: MilpModel, free: np.ndarray, x: np.ndarray) -> Restricted:
    """The model over the route columns ``free`` (ascending) and the auxiliaries of their rows,
    every other column fixed at its value in ``x`` (module docstring); the rows kept are those of
    the free columns."""
    free = np.asarray(free, dtype=np.int64)
    a = model.A_ub.tocsc()
    rows = np.unique(a[:, free].indices) if free.size else np.zeros(0, np.int64)
    csr = model.A_ub.tocsr()
    touched = csr[rows].indices
    aux = np.unique(touched[model.var_kind[touched] != ROUTE])
    rows = np.union1d(rows, a[:, aux].indices).astype(np.int64)  # every row of a free auxiliary
    sub_rows = csr[rows]
    cols = np.r_[free, aux].astype(np.int64)
    fixed = np.ones(model.n_vars, dtype=bool)
    fixed[cols] = False
    x = np.asarray(x, dtype=np.float64)
    xf = np.where(fixed, x, 0.0)
    b = model.b_ub[rows] - sub_rows @ xf
    r = free
    sub = replace(
        model,
        c=model.c[cols],
        A_ub=sp.csr_array(sub_rows[:, cols]),
        b_ub=b,
        ub=model.ub[cols],
        var_kind=model.var_kind[cols],
        var_ref=model.var_ref[cols],
        route_agent=model.route_agent[r],
        route_kind=model.route_kind[r],
        route_tasks=model.route_tasks[r],
        route_arrival=model.route_arrival[r],
        route_length=model.route_length[r],
        route_value=model.route_value[r],
        altitude=model.altitude[r],
        row_kind=tuple(model.row_kind[i] for i in rows.tolist()),
        size=dict(
            model.size,
            variables=int(cols.size),
            routes=int(r.size),
            constraints=int(rows.size),
            part_of=int(model.n_vars),
        ),  # fmt: skip
    )
    return Restricted(model=sub, cols=cols, rows=rows, offset=float(model.c @ xf))


def gain_bound(model: MilpModel) -> float:
    """An upper bound on the objective of every solution (module docstring)."""
    if model.n_routes == 0:
        return 0.0
    g = Gains(model).gain
    best = np.full(int(model.route_agent.max()) + 1, 0.0)
    np.maximum.at(best, model.route_agent, np.where(np.isfinite(g), g, 0.0))
    freeze = model.c[model.var_kind != ROUTE]
    rows_per_aux = np.bincount(
        model.A_ub[:, model.var_kind != ROUTE].tocoo().col, minlength=freeze.size
    )
    return float(best.sum() + freeze[rows_per_aux == 2].sum())


def loose_bound(model: MilpModel) -> float:
    """An upper bound on every solution's objective without gains (module docstring)."""
    route = model.var_kind == ROUTE
    aux = ~route
    total = float(np.sum(np.maximum(model.c[aux], 0.0) * model.ub[aux]))
    if model.n_routes:
        best = np.zeros(int(model.route_agent.max()) + 1)
        np.maximum.at(best, model.route_agent, np.maximum(model.c[route], 0.0))
        total += float(best.sum())
    return total
