"""Warm start and completeness: the gain of adding one route to a solution, a greedy first
solution seeded with the previous plan, and the agents a solution leaves idle with work to do.

The gain of a route is the objective with it minus without it, cover and freeze variables at
their best in both (:meth:`~solvers.milp_model.MilpModel.best_auxiliaries`); a route of an
agent that has one already, or one that breaks a row, gains ``-inf``.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> from solvers.milp_model import build_milp_model
>>> m = build_milp_model(g)
>>> x = initial_solution(m, g, previous={})
>>> bool(m.is_feasible(x)), idle_agents(m, x).tolist()
(True, [])
>>> idle_agents(m, np.zeros(m.n_vars)).tolist()  # P2 may only watch: worth nothing alone
[0, 2]
"""

from __future__ import annotations

import time
from collections.abc import Mapping

import numpy as np

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.types import ROUTE, MilpModel

__all__ = ["idle_agents", "initial_solution", "route_gains"]


def _aux_layout(model: MilpModel) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rows holding an auxiliary variable: (row, aux position, coefficient) sorted by aux, and
    the aux columns."""
    aux = np.flatnonzero(model.var_kind != ROUTE)
    sub = model.A_ub[:, aux].tocoo()
    keep = sub.data > 0
    order = np.argsort(sub.col[keep], kind="stable")
    return sub.row[keep][order], sub.col[keep][order], sub.data[keep][order], aux


def route_gains(model: MilpModel, y: np.ndarray) -> np.ndarray:
    """(R,) objective gain of adding each route to the route choice ``y`` (R,) (cover and freeze
    variables at their best before and after); ``-inf`` where the route's agent already has a
    route or adding it breaks a row."""
    n_r = model.n_routes
    gains = np.full(n_r, -np.inf)
    if n_r == 0:
        return gains
    a_r = model.A_ub[:, :n_r].tocsc()
    slack = model.b_ub - a_r @ y  # (m,) auxiliaries at 0
    rows, pos, coef, aux = _aux_layout(model)
    busy = np.zeros(int(model.route_agent.max()) + 1, dtype=bool)
    busy[model.route_agent[y > 0.5]] = True
    cand = np.flatnonzero(~busy[model.route_agent] & (y < 0.5))
    if cand.size == 0:
        return gains
    after = slack[:, None] - a_r[:, cand].toarray()  # (m, C)
    plain = np.ones(model.n_rows, dtype=bool)
    plain[rows] = False
    ok = np.all(after[plain] >= -1e-9, axis=0)
    base = model.c[:n_r] @ y
    z_now = _best_aux(slack[:, None], rows, pos, coef, model.ub[aux])[:, 0]
    z_new = _best_aux(after, rows, pos, coef, model.ub[aux])
    ok &= np.all(z_new >= 0, axis=0)
    c_z = model.c[aux]
    value = base + model.c[cand] + c_z @ np.maximum(z_new, 0.0)
    gains[cand] = np.where(ok, value - (base + c_z @ z_now), -np.inf)
    return gains


def _best_aux(
    slack: np.ndarray, rows: np.ndarray, pos: np.ndarray, coef: np.ndarray, ub: np.ndarray
) -> np.ndarray:
    """(Z, C) the largest value each auxiliary's rows allow for each column of ``slack`` (m, C)."""
    out = np.repeat(ub[:, None], slack.shape[1], axis=1)
    if rows.size:
        lim = np.floor(slack[rows] / coef[:, None] + 1e-9)  # (entries, C)
        starts = np.flatnonzero(np.r_[True, pos[1:] != pos[:-1]])
        out[pos[starts]] = np.minimum(out[pos[starts]], np.minimum.reduceat(lim, starts, axis=0))
    return out


def initial_solution(
    model: MilpModel,
    graph: TaskGraph,
    previous: Mapping[str, tuple[str, ...]],
    deadline: float | None = None,
) -> np.ndarray:
    """A complete first solution: each agent's route of the previous plan (or what is left of it
    after its first task) where the model still has it and it gains, then one route at a time
    the route of largest gain until none gains (or the :func:`time.perf_counter` ``deadline``
    passes: the solver completes a partial start). Returns the whole vector (auxiliaries at
    their best)."""
    n_r = model.n_routes
    y = np.zeros(n_r)
    if n_r == 0:
        return np.zeros(model.n_vars)
    tasks = model.route_tasks
    for aid, route in previous.items():
        a = graph.agent_index.get(aid)
        if a is None or not route:
            continue
        for want in (route, route[1:]):
            rows = [graph.task_index.get(t, -2) for t in want]
            if not rows or -2 in rows:
                continue
            key = np.full(tasks.shape[1], -1)
            key[: len(rows)] = rows[: tasks.shape[1]]
            hit = np.flatnonzero((model.route_agent == a) & np.all(tasks == key, axis=1))
            if hit.size and route_gains(model, y)[hit[0]] > 0:
                y[hit[0]] = 1.0
                break
    for _ in range(graph.n_agents):
        if deadline is not None and time.perf_counter() > deadline:
            break
        g = route_gains(model, y)
        r = int(np.argmax(g))
        if not g[r] > 1e-12:
            break
        y[r] = 1.0
    return model.best_auxiliaries(np.r_[y, np.zeros(model.n_vars - n_r)])


def idle_agents(model: MilpModel, x: np.ndarray) -> np.ndarray:
    """Agent rows without a route in ``x`` for which some route would raise the objective."""
    n_r = model.n_routes
    if n_r == 0:
        return np.zeros(0, dtype=np.int64)
    y = (np.asarray(x, dtype=np.float64)[:n_r] > 0.5).astype(np.float64)
    g = route_gains(model, y)
    return np.unique(model.route_agent[g > 1e-9])
