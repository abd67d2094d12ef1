"""Warm start and completeness: the gain of adding one route to a solution, a greedy first
solution seeded with the previous plan, and the agents a solution leaves idle with work to do.

The gain of a route is the objective with it minus without it, cover and freeze variables at
their best in both (:meth:`~solvers.milp_model.MilpModel.best_auxiliaries`); a route of an
agent that has one already, or one that breaks a row, gains ``-inf``.

:class:`Gains` keeps every route's gain up to date while routes are added, in time linear in
the nonzeros of the rows a new route touches: an auxiliary's best value is the smallest
``floor(slack_i / a_i)`` over its rows ``i`` (at most its bound), a route only loosens the rows it
appears in, and each auxiliary lies in one row (a cover) or two (a freeze: dump and watch).

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

__all__ = ["Gains", "complete", "idle_agents", "initial_solution", "route_gains"]

_TOL = 1e-9


class Gains:
    """The gain of every route for a route choice that grows one route at a time.

    Parameters
    ----------
    model : MilpModel
    y : ndarray, (R,), optional
        The routes chosen to start with (0/1; default none). It must satisfy the rows.

    Attributes
    ----------
    y : ndarray, (R,) float64
        The routes chosen so far.
    gain : ndarray, (R,) float64
        Each route's gain (``-inf``: its agent has a route, or it breaks a row).
    """

    def __init__(self, model: MilpModel, y: np.ndarray | None = None) -> None:
        self.model = m = model
        n_r = m.n_routes
        self.y = np.zeros(n_r) if y is None else np.asarray(y, dtype=np.float64).copy()
        aux = np.flatnonzero(m.var_kind != ROUTE)
        a = m.A_ub.tocsc()
        # each row's auxiliary (-1: none) and its coefficient
        sub = a[:, aux].tocoo()
        self.row_aux = np.full(m.n_rows, -1, dtype=np.int64)
        self.row_coef = np.ones(m.n_rows)
        self.row_aux[sub.row] = sub.col
        self.row_coef[sub.row] = sub.data
        self.aux_c = m.c[aux]
        self.aux_ub = m.ub[aux]
        # the rows of each auxiliary (one or two), -1 padded
        order = np.argsort(sub.col, kind="stable")
        counts = np.bincount(sub.col, minlength=aux.size)
        if counts.size and counts.max() > 2:
            raise ValueError("an auxiliary variable appears in more than two rows")
        self.aux_rows = np.full((aux.size, 2), -1, dtype=np.int64)
        first = np.r_[0, np.cumsum(counts)[:-1]]
        rows_sorted = sub.row[order]
        self.aux_rows[counts > 0, 0] = rows_sorted[first[counts > 0]]
        two = counts == 2
        self.aux_rows[two, 1] = rows_sorted[first[two] + 1]
        self.routes = a[:, :n_r].tocsc()  # route columns
        self.by_row = self.routes.tocsr()  # routes of each row
        self.slack = m.b_ub - self.routes @ self.y
        self.gain = np.full(n_r, -np.inf)
        self._stale = np.zeros(n_r, dtype=bool)
        self._freeze = (counts == 2) if aux.size else np.zeros(0, dtype=bool)
        self._busy = np.zeros(int(m.route_agent.max()) + 1 if n_r else 0, dtype=bool)
        self._busy[m.route_agent[self.y > 0.5]] = True
        self.update(np.arange(n_r))

    def _limits(self, rows: np.ndarray, slack: np.ndarray) -> np.ndarray:
        """``floor(slack / a_aux)`` of aux rows (inf elsewhere)."""
        out = np.floor(slack / self.row_coef[rows] + _TOL)
        return np.where(self.row_aux[rows] >= 0, out, np.inf)

    def aux_values(self) -> np.ndarray:
        """(Z,) each auxiliary's best value for the routes chosen."""
        rows = self.aux_rows
        lim = np.where(rows >= 0, self._limits(np.maximum(rows, 0), self.slack[rows]), np.inf)
        return np.maximum(np.minimum(self.aux_ub, lim.min(axis=1)), 0.0)

    def update(self, routes: np.ndarray) -> None:
        """Recompute the gains of ``routes`` (route rows) for the current choice."""
        routes = np.asarray(routes, dtype=np.int64)
        if routes.size == 0:
            return
        pos, which = _gather(self.routes.indptr, routes)
        r, i, a = routes[which], self.routes.indices[pos].astype(np.int64), self.routes.data[pos]
        new_slack = self.slack[i] - a
        aux = self.row_aux[i]
        plain = aux < 0
        # rows without an auxiliary must keep a non-negative slack
        bad = np.zeros(self.gain.size, dtype=bool)
        bad[r[plain & (new_slack < -_TOL)]] = True
        gain = np.zeros(self.gain.size)
        np.add.at(gain, routes, self.model.c[routes])
        mine = ~plain
        if mine.any():
            r_a, i_a, z_a = r[mine], i[mine], aux[mine]
            lim_new = self._limits(i_a, new_slack[mine])
            # the other row of a freeze variable, unless this route is in it as well
            rows = self.aux_rows[z_a]
            other = np.where(rows[:, 0] == i_a, rows[:, 1], rows[:, 0])
            key = r_a * (self.aux_c.size + 1) + z_a
            _, grp, n_in = np.unique(key, return_inverse=True, return_counts=True)
            grp = grp.ravel()
            lim_grp = np.full(n_in.size, np.inf)
            np.minimum.at(lim_grp, grp, lim_new)
            lim_other = np.where(other >= 0, self._limits(np.maximum(other, 0), self.slack[other]),
                                 np.inf)  # fmt: skip
            rest = np.full(n_in.size, np.inf)
            np.minimum.at(rest, grp, np.where(n_in[grp] > 1, np.inf, lim_other))
            first = np.unique(grp, return_index=True)[1]
            z_g, r_g = z_a[first], r_a[first]
            z_new = np.minimum(self.aux_ub[z_g], np.minimum(lim_grp, rest))
            bad[r_g[z_new < 0]] = True
            z_new = np.maximum(z_new, 0.0)
            z_now = self._aux_now(z_g)
            np.add.at(gain, r_g, self.aux_c[z_g] * (z_new - z_now))
        out = np.where(bad[routes], -np.inf, gain[routes])
        out[self._busy[self.model.route_agent[routes]] | (self.y[routes] > 0.5)] = -np.inf
        self.gain[routes] = out

    def _aux_now(self, z: np.ndarray) -> np.ndarray:
        rows = self.aux_rows[z]
        lim = np.where(rows >= 0, self._limits(np.maximum(rows, 0), self.slack[rows]), np.inf)
        out: np.ndarray = np.maximum(np.minimum(self.aux_ub[z], lim.min(axis=1)), 0.0)
        return out

    def add(self, route: int) -> None:
        """Choose ``route``. The gains of routes sharing a row without an auxiliary (its agent's,
        those dumping or heading where it does) or a freeze row with it are recomputed; those
        sharing only cover rows can only fall (a cover's value is concave in the routes that
        sweep it) and are marked stale, recomputed when they next look best (:meth:`best`)."""
        self.y[route] = 1.0
        self._busy[self.model.route_agent[route]] = True
        pos, _ = _gather(self.routes.indptr, np.array([route]))
        rows = self.routes.indices[pos].astype(np.int64)
        self.slack[rows] -= self.routes.data[pos]
        z = self.row_aux[rows]
        aux = z >= 0
        frozen = self._freeze[z[aux]]  # (indexed only where there is an auxiliary: a model
        # may have none, and then this array is empty)
        exact_rows = np.r_[rows[~aux], self.aux_rows[z[aux]][frozen].ravel()]
        exact_rows = np.unique(exact_rows[exact_rows >= 0])
        cover_rows = rows[aux][~frozen]
        exact = np.unique(np.r_[self._routes_in(exact_rows), route])
        self._stale[self._routes_in(cover_rows)] = True
        self._stale[exact] = False
        self.update(exact)

    def _routes_in(self, rows: np.ndarray) -> np.ndarray:
        """The routes with an entry in any of ``rows``."""
        pos, _ = _gather(self.by_row.indptr, rows)
        return self.by_row.indices[pos].astype(np.int64)

    def best(self) -> int:
        """The route of largest gain (ties: the lowest row), recomputing stale gains first (in
        batches: the stale gains are upper bounds)."""
        while True:
            r = int(np.argmax(self.gain))
            if not self._stale[r] or not np.isfinite(self.gain[r]):
                return r
            stale = np.flatnonzero(self._stale)
            top = stale[np.argsort(-self.gain[stale], kind="stable")[: max(64, stale.size // 8)]]
            batch = np.union1d(top, stale[self.gain[stale] >= self.gain[r] - _TOL])
            self._stale[batch] = False
            self.update(batch)

    def solution(self) -> np.ndarray:
        """The whole vector: the routes chosen, every auxiliary at its best."""
        return self.model.best_auxiliaries(
            np.r_[self.y, np.zeros(self.model.n_vars - self.model.n_routes)]
        )


def _gather(indptr: np.ndarray, major: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions in a compressed sparse array's ``indices`` / ``data`` of the entries of the
    ``major`` rows (CSR) or columns (CSC), and for each entry its index in ``major``."""
    starts = indptr[major]
    lens = indptr[major + 1] - starts
    which = np.repeat(np.arange(major.size), lens)
    offset = np.arange(which.size) - np.repeat(np.cumsum(lens) - lens, lens)
    return starts[which] + offset, which


def route_gains(model: MilpModel, y: np.ndarray) -> np.ndarray:
    """(R,) objective gain of adding each route to the route choice ``y`` (R,) (cover and freeze
    variables at their best before and after); ``-inf`` where the route's agent already has a
    route or adding it breaks a row."""
    if model.n_routes == 0:
        return np.zeros(0)
    return Gains(model, y).gain


def _previous_routes(
    model: MilpModel, graph: TaskGraph, previous: Mapping[str, tuple[str, ...]]
) -> list[int]:
    """Per agent of the previous plan, the model's route equal to its route or to what is left of
    it after its first task (the first that the model has), in agent order."""
    out = []
    tasks = model.route_tasks
    width = tasks.shape[1]
    for aid, route in previous.items():
        a = graph.agent_index.get(aid)
        if a is None or not route or len(route) > width:
            continue
        mine = np.flatnonzero(model.route_agent == a)
        for want in (route, route[1:]):
            rows = [graph.task_index.get(t, -2) for t in want]
            if not rows or -2 in rows:
                continue
            key = np.full(width, -1)
            key[: len(rows)] = rows
            hit = mine[np.all(tasks[mine] == key, axis=1)]
            if hit.size:
                out.append(int(hit[0]))
                break
    return sorted(out, key=lambda r: int(model.route_agent[r]))


def initial_solution(
    model: MilpModel,
    graph: TaskGraph,
    previous: Mapping[str, tuple[str, ...]],
    deadline: float | None = None,
) -> np.ndarray:
    """A complete first solution: each agent's route of the previous plan (or what is left of it
    after its first task) where the model still has it and it gains, then one route at a time
    the route of largest gain (ties: the lowest row) until none gains (or the
    :func:`time.perf_counter` ``deadline`` passes: the solver completes a partial start).
    Returns the whole vector (auxiliaries at their best)."""
    if model.n_routes == 0:
        return np.zeros(model.n_vars)
    gains = Gains(model)
    for r in _previous_routes(model, graph, previous):
        if gains.gain[r] > _TOL:
            gains.add(r)
    return _greedy(gains, deadline)


def complete(model: MilpModel, x: np.ndarray, deadline: float | None = None) -> np.ndarray:
    """``x`` (feasible) with routes of largest gain added one at a time until none gains (or the
    ``deadline`` passes): no agent is left idle that a route would make worth more."""
    if model.n_routes == 0:
        return np.asarray(x, dtype=np.float64)
    y = (np.asarray(x, dtype=np.float64)[: model.n_routes] > 0.5).astype(np.float64)
    return _greedy(Gains(model, y), deadline)


def _greedy(gains: Gains, deadline: float | None) -> np.ndarray:
    for _ in range(gains.y.size):
        if deadline is not None and time.perf_counter() > deadline:
            break
        r = gains.best()
        if not gains.gain[r] > _TOL:
            break
        gains.add(r)
    return gains.solution()


def idle_agents(model: MilpModel, x: np.ndarray) -> np.ndarray:
    """Agent rows without a route in ``x`` for which some route would raise the objective."""
    n_r = model.n_routes
    if n_r == 0:
        return np.zeros(0, dtype=np.int64)
    y = (np.asarray(x, dtype=np.float64)[:n_r] > 0.5).astype(np.float64)
    g = route_gains(model, y)
    return np.unique(model.route_agent[g > 1e-9])
