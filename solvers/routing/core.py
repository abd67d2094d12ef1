"""The routing core: one prize-collecting vehicle routing problem on a plain distance matrix.

:func:`solve_routes` is the model both routing schedulers solve for each role, and a solver in its
own right (posed as a TSP it is checked against TSPLIB's known optima, see
``bench/bench_tsplib.py``). Notation: ``L`` locations with travel ``d[a, b] >= 0`` between them
(``dist``, any unit, asymmetric allowed); ``V`` vehicles, vehicle ``v`` leaves location
``s_v = starts[v]`` and ends at ``e_v = ends[v]``; every other location is a **task** ``k`` with
a prize ``p_k`` (``inf``: the visit is required).

Model
-----
Choose for each vehicle an ordered route ``r_v = (k_1, ..., k_n)`` of distinct tasks (each task
on at most one route) to

.. math::

    \\min \\; \\sum_v c(r_v) + \\sum_{k \\notin \\cup_v r_v} p_k

    \\text{s.t.} \\quad \\ell(r_v) \\le B_v, \\quad |r_v| \\le Q_v, \\quad
    k \\in r_v \\Rightarrow \\text{allowed}[v, k], \\quad p_k = \\infty \\Rightarrow k \\in \\cup_v r_v

with the route length ``l(r) = d[s, k_1] + ... + d[k_n, e]`` (the way to the end always counts
against the budget ``B_v``, ``budgets``), the route cost ``c(r) = l(r)``, or ``l(r) - d[k_n, e]``
with ``charge_return=False`` (the closing leg is free: a vehicle replans long before it flies
home), ``c(()) = 0`` for an empty route (the vehicle is not used), and ``Q_v`` the most visits
(``capacities``). The objective is the travel plus the prizes
left uncollected (a prize-collecting VRP / team orienteering problem with a budget per vehicle);
with every prize infinite and one vehicle it is the TSP (``starts = ends``) or the shortest
Hamiltonian path (``starts != ends``). A vehicle may always fly straight from its start to its
end, even beyond its budget (it then serves nothing).

Tasks that no vehicle can serve (not allowed, or ``d[s_v, k] + d[k, e_v] > B_v`` for every ``v``)
are left out of the search and their prizes counted; a required one raises.

Backends
--------
``backend="ortools"`` (:mod:`solvers.routing.ortools_backend`, OR-Tools' routing library: a
first-solution heuristic then guided local search) or ``backend="pyvrp"``
(:mod:`solvers.routing.pyvrp_backend`, PyVRP's iterated local search). Both need integers:
distances are multiplied by ``scale`` and rounded **up** (so a route the solver accepts fits its
budget in the real distances too), budgets rounded down, prizes rounded to the nearest integer
(at least 1, so an optional visit stays optional). Reported travel and objective are recomputed
from the real ``dist``. Neither backend proves a bound (``bound`` is NaN).

Limits and the time-limit rule
------------------------------
``deterministic=True``: the search stops on a work limit (OR-Tools: solutions and branches;
PyVRP: iterations, fixed seed), never on the clock, so the same input gives the same routes in
any process and under any load. Otherwise it stops at ``time_limit`` seconds for the whole call:
each backend gets the time left after building its model. A search cut by the clock is never
handed back as if it were a decision:

* if it found nothing, the ``warm_start`` routes (made feasible) are returned
  (``kept_warm_start``), else :class:`RoutingFailedError` is raised (a scheduler's caller falls
  back to greedy, :func:`fcplan.scheduling.solve`);
* if it found routes that a single feasible insertion would improve (OR-Tools completes an
  interrupted first solution by leaving the rest out), the routes are completed by cheapest
  insertion (``repaired``), and the warm start is returned instead if it is better.

Examples
--------
A 4-city tour from city 0 (every city required; the closing leg is charged by default):

>>> import numpy as np
>>> from solvers.routing import solve_routes
>>> xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], dtype=float)
>>> dist = np.linalg.norm(xy[:, None] - xy[None], axis=2)
>>> res = solve_routes(dist, starts=[0], deterministic=True)
>>> res.objective, sorted(res.routes[0])
(40.0, [1, 2, 3])

An open path from city 0 to city 3:

>>> solve_routes(dist, starts=[0], ends=[3], deterministic=True).routes
((1, 2),)

Prize collecting with a budget: city 2 is worth less than its detour and is left out.

>>> res = solve_routes(dist, starts=[0], prizes=[0, 50, 5, 50], budgets=[40],
...                    deterministic=True)
>>> sorted(res.routes[0]), round(res.travel, 2), res.dropped
([1, 3], 34.14, 5.0)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["BACKENDS", "RoutesResult", "RoutingFailedError", "RoutingInstance"]

#: The backends of :func:`solve_routes`.
BACKENDS = ("ortools", "pyvrp")

#: Slack of the budget comparisons in real distance units (the same route summed in another
#: order may differ in its last bits).
TOL = 1e-6


class RoutingFailedError(RuntimeError):
    """The search found no routes within its limit and there was no warm start to keep."""


@dataclass(frozen=True, slots=True)
class RoutesResult:
    """Result of :func:`solve_routes`.

    Attributes
    ----------
    routes : tuple of tuple of int
        Per vehicle, the task locations it visits in order (start and end excluded).
    objective : float
        ``travel + dropped`` (see the model in :mod:`solvers.routing.core`).
    travel : float
        Cost of the routes in ``dist`` units (without the closing legs when
        ``charge_return=False``; an empty route costs nothing).
    dropped : float
        Prizes of the tasks left out (``inf`` never: required tasks are always served).
    bound : float
        A proven lower bound on the objective (NaN: neither backend proves one).
    status : str
        ``feasible`` (the work limit or a local optimum ended the search) or ``time_limit``
        (the clock did).
    backend : str
        Which backend searched.
    warm_started : bool
        The search started from the (feasible part of the) warm start.
    kept_warm_start : bool
        The routes are the warm start's: the clock ended the search before it found anything
        better.
    repaired : bool
        The clock cut the search and the routes were completed by cheapest insertion.
    size : dict
        ``vehicles``, ``tasks`` (searched), ``locations``.
    work : dict
        What the search spent (backend-specific: ``solutions``, ``branches``, ``iterations``).
    """

    routes: tuple[tuple[int, ...], ...]
    objective: float
    travel: float
    dropped: float
    status: str
    backend: str
    bound: float = float("nan")
    warm_started: bool = False
    kept_warm_start: bool = False
    repaired: bool = False
    size: dict = field(default_factory=dict)
    work: dict = field(default_factory=dict)

    @property
    def n_visits(self) -> int:
        """Visits over all routes."""
        return sum(len(r) for r in self.routes)


@dataclass(frozen=True, eq=False)
class RoutingInstance:
    """The normalised input of :func:`solve_routes` (what the backends read).

    ``m`` searched tasks are the tasks some vehicle can serve, in location order.
    """

    dist: np.ndarray  # (L, L) float64 travel between locations
    starts: np.ndarray  # (V,) int64 start location of each vehicle
    ends: np.ndarray  # (V,) int64 end location of each vehicle
    tasks: np.ndarray  # (m,) int64 location of each searched task
    prize: np.ndarray  # (m,) float64 prize of each searched task (inf: required)
    budget: np.ndarray  # (V,) float64 most route length (inf: none)
    visits: np.ndarray  # (V,) int64 most visits per route (m: none)
    ok: np.ndarray  # (V, m) bool the vehicle may serve the task and fly to its end
    charge_return: bool
    out_dropped: float  # prizes of the tasks nobody can serve

    @property
    def n_vehicles(self) -> int:
        return len(self.starts)

    @property
    def n_tasks(self) -> int:
        return len(self.tasks)

    @property
    def required(self) -> np.ndarray:
        """(m,) bool: the task must be visited."""
        out: np.ndarray = ~np.isfinite(self.prize)
        return out

    @classmethod
    def of(
        cls,
        dist: Any,
        starts: Any,
        ends: Any = None,
        prizes: Any = None,
        budgets: Any = None,
        capacities: Any = None,
        allowed: Any = None,
        charge_return: bool = True,
    ) -> RoutingInstance:
        """Check and normalise :func:`solve_routes`'s arguments (raises ``ValueError`` on bad
        shapes or values, :class:`RoutingFailedError` if a required task cannot be served)."""
        d = np.asarray(dist, dtype=np.float64)
        n_loc = d.shape[0] if d.ndim == 2 else -1
        if d.ndim != 2 or d.shape[1] != n_loc:
            raise ValueError(f"dist must be a square (L, L) matrix, got shape {d.shape}")
        if not np.isfinite(d).all() or (d < 0).any():
            raise ValueError("dist must be finite and >= 0")
        s = _index_vector("starts", starts, n_loc)
        e = s if ends is None else _index_vector("ends", ends, n_loc)
        if len(e) != len(s):
            raise ValueError(f"starts and ends must have one entry per vehicle ({len(s)})")
        n_v = len(s)
        is_task = np.ones(n_loc, dtype=bool)
        is_task[s] = is_task[e] = False
        tasks = np.flatnonzero(is_task)
        p_all = np.full(n_loc, np.inf) if prizes is None else np.asarray(prizes, np.float64)
        b = np.full(n_v, np.inf) if budgets is None else np.asarray(budgets, np.float64)
        q = np.full(n_v, len(tasks)) if capacities is None else np.asarray(capacities)
        for name, arr, shape in (("prizes", p_all, (n_loc,)), ("budgets", b, (n_v,)),
                                 ("capacities", q, (n_v,))):  # fmt: skip
            if arr.shape != shape:
                raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
        if np.isnan(p_all[tasks]).any() or (p_all[tasks] < 0).any():
            raise ValueError("prizes of task locations must be >= 0 (inf: required)")
        if np.isnan(b).any() or (q < 0).any():
            raise ValueError("budgets must not be NaN and capacities must be >= 0")
        ok = np.ones((n_v, len(tasks)), dtype=bool)
        if allowed is not None:
            a = np.asarray(allowed, dtype=bool)
            if a.shape != (n_v, n_loc):
                raise ValueError(f"allowed must have shape {(n_v, n_loc)}, got {a.shape}")
            ok &= a[:, tasks]
        ok &= d[s[:, None], tasks[None, :]] + d[tasks[None, :], e[:, None]] <= b[:, None] + TOL
        ok &= (q > 0)[:, None]
        served = ok.any(axis=0)
        prize = p_all[tasks]
        if (~np.isfinite(prize) & ~served).any():
            bad = tasks[~np.isfinite(prize) & ~served]
            raise RoutingFailedError(f"required tasks at locations {bad.tolist()} are unreachable")
        out_dropped = float(prize[~served].sum())
        return cls(
            d, s, e, tasks[served], prize[served], b,
            np.minimum(q.astype(np.int64), served.sum()), ok[:, served], bool(charge_return),
            out_dropped,
        )  # fmt: skip

    # ------------------------------------------------------------------ routes
    def route_legs(self, v: int, route: Sequence[int]) -> np.ndarray:
        """The legs' lengths of vehicle ``v`` flying its task positions ``route`` (into
        :attr:`tasks`), start and end included."""
        path = np.r_[self.starts[v], self.tasks[np.asarray(route, dtype=np.int64)], self.ends[v]]
        legs: np.ndarray = self.dist[path[:-1], path[1:]]
        return legs

    def evaluate(self, routes: Sequence[Sequence[int]]) -> tuple[float, float]:
        """``(travel, dropped)`` of routes given as task positions (into :attr:`tasks`)."""
        travel = 0.0
        seen = np.zeros(self.n_tasks, dtype=bool)
        for v, r in enumerate(routes):
            if not r:
                continue  # an unused vehicle costs nothing
            legs = self.route_legs(v, r)
            travel += float(legs.sum() if self.charge_return else legs[:-1].sum())
            seen[list(r)] = True
        return travel, float(self.prize[~seen].sum()) + self.out_dropped

    def fit(self, routes: Sequence[Sequence[int]]) -> list[list[int]]:
        """Routes (task positions) made feasible: per vehicle, the tasks it may serve that no
        earlier route took, cut to the longest prefix within its visits and budget."""
        taken = np.zeros(self.n_tasks, dtype=bool)
        out: list[list[int]] = []
        for v in range(self.n_vehicles):
            r = [k for k in (routes[v] if v < len(routes) else ()) if self.ok[v, k]]
            r = [k for i, k in enumerate(r) if not taken[k] and k not in r[:i]]
            r = r[: int(self.visits[v])]
            while r and self.route_legs(v, r).sum() > self.budget[v] + TOL:
                r.pop()
            taken[r] = True
            out.append(r)
        return out

    def result(
        self, routes: Sequence[Sequence[int]], status: str, backend: str, **flags: Any
    ) -> RoutesResult:
        """The :class:`RoutesResult` of routes given as task positions."""
        travel, dropped = self.evaluate(routes)
        return RoutesResult(
            routes=tuple(tuple(int(self.tasks[k]) for k in r) for r in routes),
            objective=travel + dropped, travel=travel, dropped=dropped, status=status,
            backend=backend,
            size={"vehicles": self.n_vehicles, "tasks": self.n_tasks,
                  "locations": int(self.dist.shape[0])},
            **flags,
        )  # fmt: skip

    def warm_routes(self, warm_start: Sequence[Sequence[int]] | None) -> list[list[int]] | None:
        """A warm start given as task *locations* per vehicle, as feasible task positions
        (None: no warm start, or nothing of it survives)."""
        if warm_start is None:
            return None
        pos = {int(loc): k for k, loc in enumerate(self.tasks.tolist())}
        routes = [[pos[int(t)] for t in r if int(t) in pos] for r in warm_start]
        fitted = self.fit(routes)
        return fitted if any(fitted) else None


def _index_vector(name: str, x: Any, n_loc: int) -> np.ndarray:
    arr = np.asarray(x, dtype=np.int64).reshape(-1)
    if arr.size and (arr.min() < 0 or arr.max() >= n_loc):
        raise ValueError(f"{name} must be location indices in [0, {n_loc}), got {arr.tolist()}")
    return arr
