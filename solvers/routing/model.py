"""The prize-collecting routing model on plain arrays, and its solution.

``V`` vehicles start at ``start`` and end at their depot slots ``end``; ``N`` task nodes may each
be visited at most once, and leaving node ``k`` out costs its drop penalty ``penalty[k]`` (in
px; ``inf``: the visit is mandatory). The objective (minimised) is the travel in px plus the
penalties of the nodes left out. Dimensions:

* ``distance``: travel px, capped per vehicle by its ``budget``, the legs into the end
  position included, so every route keeps its way home (a vehicle may always fly straight to
  its end, even beyond its budget; it then gets no task);
* ``visits``: task visits, capped per vehicle by ``max_visits`` and its ``capacity`` (only when
  one of them binds).

A vehicle may only serve the nodes ``allowed`` to it that it can reach and still fly home from
(``d(start, k) + d(k, end) <= budget``); nodes nobody can serve are left out of the model (their
penalties are added to the objective). OR-Tools needs integers: distances are scaled by
``scale`` and rounded *up* (a route the solver accepts is within the budget in real px too),
capacities rounded down, penalties rounded (at least 1, so a visit stays optional). Distances and
visit counts are registered as a matrix / vector (``RegisterTransitMatrix``,
``RegisterUnaryTransitVector``), never as Python callbacks, so the search never calls back into
Python. How the model is searched: :mod:`solvers.routing.search`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from ortools.constraint_solver import pywrapcp

from solvers.routing.search import SEARCH_STATUS, model_parameters, search

__all__ = ["RouteSolution", "RoutingFailedError", "solve_routes"]

#: largest penalty / capacity fed to OR-Tools (int64 costs are summed: stay far from overflow)
_BIG = 10**12


class RoutingFailedError(RuntimeError):
    """The routing model found no solution within its limit (the caller falls back)."""


@dataclass(frozen=True, slots=True)
class RouteSolution:
    """Result of :func:`solve_routes`.

    Attributes
    ----------
    routes : tuple of tuple of int
        Per vehicle, the node indices it visits in order (start and end excluded).
    objective_px : float
        Travel plus drop penalties of the unvisited nodes, in px (OR-Tools objective / scale).
    travel_px : float
        Travel of the routes in px (including the legs home when ``charge_return``), from the
        unscaled distances.
    dropped_px : float
        Sum of the drop penalties of the unvisited nodes, in px.
    status : str
        ``feasible`` or ``time_limit`` (see the module docstring).
    size : dict
        ``vehicles``, ``nodes`` (task nodes in the model), ``dimensions``.
    rescued : bool
        The time limit ended the search before any solution, and the routes are the
        first-solution heuristic's, found after the limit (``rescue=True``).
    """

    routes: tuple[tuple[int, ...], ...]
    objective_px: float
    travel_px: float
    dropped_px: float
    status: str
    size: dict
    rescued: bool = False


def solve_routes(
    start: np.ndarray,
    end: np.ndarray,
    nodes: np.ndarray,
    penalty: np.ndarray,
    budget: np.ndarray,
    *,
    capacity: np.ndarray | None = None,
    allowed: np.ndarray | None = None,
    max_visits: int | None = None,
    charge_return: bool = False,
    time_limit: float | None = 0.1,
    deterministic: bool = False,
    solution_limit: int = 40,
    branch_limit: int | None = 2000,
    first_solution: str = "PARALLEL_CHEAPEST_INSERTION",
    metaheuristic: str = "GUIDED_LOCAL_SEARCH",
    scale: float = 10.0,
    rescue: bool = True,
) -> RouteSolution:
    """Solve one prize-collecting routing model on plain arrays (the scheduler's building block).

    Parameters
    ----------
    start, end : ndarray, (V, 2)
        Start and end (depot slot) positions of the ``V`` vehicles.
    nodes : ndarray, (N, 2)
        Task positions.
    penalty : ndarray, (N,)
        Drop penalty of each node in px (``inf``: the visit is mandatory).
    budget : ndarray, (V,)
        Distance each vehicle may fly in px, including its way to ``end``. A vehicle that cannot
        even fly straight to its end gets no task (and is allowed that direct leg).
    capacity : ndarray, (V,) of int, optional
        Most visits of each vehicle (e.g. dumps left in the tank), on top of ``max_visits``.
    allowed : ndarray, (V, N) of bool, optional
        Which vehicle may serve which node (default: all).
    max_visits : int, optional
        Most nodes per route.
    charge_return : bool
        Count the legs into the end positions in the objective (they always count for the
        budget).
    time_limit : float, optional
        Seconds for the whole call, building the model included (ignored when
        ``deterministic``; None: no wall-time limit, only ``branch_limit``).
    deterministic, solution_limit, branch_limit, first_solution, metaheuristic, rescue
        How the model is searched (:func:`solvers.routing.search.search`): stop after
        ``solution_limit`` solutions instead of a wall time when ``deterministic``, and after
        ``branch_limit`` search branches in both modes (None: no such limit); the names of the
        OR-Tools ``FirstSolutionStrategy`` and ``LocalSearchMetaheuristic``; with ``rescue``, a
        time-out before any solution runs the first-solution heuristic alone past the limit
        (the result has ``status="time_limit"`` and ``rescued=True``) instead of raising.
    scale : float
        Integer units per px (10: decimetres).

    Returns
    -------
    RouteSolution

    Raises
    ------
    RoutingFailedError
        If no solution is found (within the limit, when ``rescue`` is off), or a mandatory
        node cannot be served.

    Examples
    --------
    >>> import numpy as np
    >>> sol = solve_routes(np.zeros((1, 2)), np.zeros((1, 2)), np.array([[30.0, 40.0]]),
    ...                    np.array([1000.0]), np.array([1000.0]), deterministic=True)
    >>> sol.routes, sol.travel_px
    (((0,),), 50.0)
    """
    t_enter = time.perf_counter()
    prob = _Problem.of(start, end, nodes, penalty, budget, allowed)
    if prob.n_vehicles == 0 or prob.keep.size == 0:
        return RouteSolution(
            ((),) * prob.n_vehicles, prob.out_dropped, 0.0, prob.out_dropped, "feasible",
            {"vehicles": prob.n_vehicles, "nodes": 0, "dimensions": 0},
        )  # fmt: skip
    rm = _build_model(prob, capacity, max_visits, charge_return, scale)
    t0 = time.perf_counter()
    time_left = None if time_limit is None else time_limit - (t0 - t_enter)
    found = search(
        rm.model, t0, time_left, deterministic=deterministic, solution_limit=solution_limit,
        branch_limit=branch_limit, first_solution=first_solution, metaheuristic=metaheuristic,
        rescue=rescue,
    )  # fmt: skip
    if found[0] is None:
        raise RoutingFailedError(
            f"no routing solution ({_status_name(found[1])}) for {prob.n_vehicles} vehicles x "
            f"{rm.n_nodes} nodes within "
            + (f"{solution_limit} solutions" if deterministic else f"{time_limit} s")
            + (f" and {branch_limit} branches" if branch_limit is not None else "")
        )
    return _solution(prob, rm, found, charge_return, deterministic, scale)


@dataclass(frozen=True, eq=False)
class _Problem:
    """The arrays of a routing problem, and which nodes some vehicle can serve."""

    start: np.ndarray  # (V, 2)
    end: np.ndarray  # (V, 2)
    nodes: np.ndarray  # (N, 2)
    penalty: np.ndarray  # (N,) px, inf: mandatory
    budget: np.ndarray  # (V,) px
    ok: np.ndarray  # (V, N) bool: the vehicle may serve the node and still fly home
    keep: np.ndarray  # (m,) the nodes some vehicle can serve (the model's nodes)
    out_dropped: float  # the penalties of the others

    @property
    def n_vehicles(self) -> int:
        return len(self.start)

    @classmethod
    def of(
        cls,
        start: np.ndarray,
        end: np.ndarray,
        nodes: np.ndarray,
        penalty: np.ndarray,
        budget: np.ndarray,
        allowed: np.ndarray | None,
    ) -> _Problem:
        """The problem of :func:`solve_routes`'s arguments (raises if a mandatory node cannot
        be served)."""
        start = np.asarray(start, dtype=np.float64).reshape(-1, 2)
        end = np.asarray(end, dtype=np.float64).reshape(-1, 2)
        nodes = np.asarray(nodes, dtype=np.float64).reshape(-1, 2)
        penalty = np.asarray(penalty, dtype=np.float64)
        budget = np.asarray(budget, dtype=np.float64)
        n_v, n_n = len(start), len(nodes)
        ok = np.ones((n_v, n_n), dtype=bool) if allowed is None else np.asarray(allowed, bool)
        # a vehicle may only take nodes it can reach and still fly home from
        ok = ok & (_pairwise(start, nodes) + _pairwise(end, nodes) <= budget[:, None])
        served = ok.any(axis=0)
        mandatory = ~np.isfinite(penalty)
        if (mandatory & ~served).any():
            raise RoutingFailedError(
                f"mandatory nodes {np.flatnonzero(mandatory & ~served)} are unreachable"
            )
        keep = np.flatnonzero(served)  # model nodes -> input nodes
        out_dropped = float(penalty[~served].sum())
        return cls(start, end, nodes, penalty, budget, ok, keep, out_dropped)


@dataclass(frozen=True, eq=False)
class _Model:
    """An OR-Tools routing model of ``V`` vehicles (nodes: ``V`` starts, ``V`` ends, then the
    task nodes) with what reading its solutions needs."""

    manager: Any  # pywrapcp.RoutingIndexManager
    model: Any  # pywrapcp.RoutingModel
    dist_px: np.ndarray  # (2 V + m, 2 V + m) px between the model's nodes
    penalty_px: np.ndarray  # (m,) drop penalties (0 for mandatory nodes)
    n_vehicles: int
    n_nodes: int
    dimensions: int


def _build_model(
    prob: _Problem,
    capacity: np.ndarray | None,
    max_visits: int | None,
    charge_return: bool,
    scale: float,
) -> _Model:
    """The routing model of the nodes some vehicle can serve, with its dimensions,
    disjunctions and vehicle restrictions (see the module docstring)."""
    keep = prob.keep
    start, end, nodes, budget, ok = prob.start, prob.end, prob.nodes[keep], prob.budget, prob.ok
    ok = ok[:, keep]
    penalty = prob.penalty[keep]
    n_v, m = len(start), len(nodes)
    mandatory: np.ndarray = ~np.isfinite(penalty)
    # node order in the model: V starts, V ends, m tasks
    pts = np.concatenate([start, end, nodes])
    dist_px = _pairwise(pts, pts)
    dist = np.ceil(dist_px * scale - 1e-9).astype(np.int64)
    direct = dist[np.arange(n_v), n_v + np.arange(n_v)]
    cap = np.maximum(np.floor(budget * scale + 1e-9), direct).astype(np.int64)
    cap = np.minimum(cap, _BIG)

    manager = pywrapcp.RoutingIndexManager(
        len(pts), n_v, list(range(n_v)), list(range(n_v, 2 * n_v))
    )
    model = pywrapcp.RoutingModel(manager, model_parameters())
    dist_cb = model.RegisterTransitMatrix(dist.tolist())
    if charge_return:
        cost_cb = dist_cb
    else:
        cost = dist.copy()
        cost[:, n_v : 2 * n_v] = 0
        cost_cb = model.RegisterTransitMatrix(cost.tolist())
    model.SetArcCostEvaluatorOfAllVehicles(cost_cb)
    model.AddDimensionWithVehicleCapacity(dist_cb, 0, cap.tolist(), True, "distance")
    dims = 1
    visits = np.full(n_v, m, dtype=np.int64)
    if max_visits is not None:
        visits = np.minimum(visits, int(max_visits))
    if capacity is not None:
        visits = np.minimum(visits, np.maximum(np.asarray(capacity, dtype=np.int64), 0))
    if (visits < m).any():
        unit = model.RegisterUnaryTransitVector([0] * (2 * n_v) + [1] * m)
        model.AddDimensionWithVehicleCapacity(unit, 0, visits.tolist(), True, "visits")
        dims += 1
    pen = np.where(np.isfinite(penalty), penalty, 0.0)
    pen_int = np.clip(np.rint(pen * scale), 1, _BIG).astype(np.int64)
    restricted = cast(np.ndarray, ~ok.all(axis=0))
    vehicles = np.arange(n_v)
    for j in range(m):  # the Python API adds disjunctions one node at a time
        index = manager.NodeToIndex(2 * n_v + j)
        if not mandatory[j]:
            model.AddDisjunction([index], int(pen_int[j]))
        if restricted[j]:
            # (SetAllowedVehiclesForIndex's absl::Span argument is not wrapped for Python in 9.15)
            model.VehicleVar(index).RemoveValues(vehicles[~ok[:, j]].tolist())
    return _Model(manager, model, dist_px, pen, n_v, m, dims)


def _solution(
    prob: _Problem,
    rm: _Model,
    found: tuple[Any, int, bool, bool],
    charge_return: bool,
    deterministic: bool,
    scale: float,
) -> RouteSolution:
    """The :class:`RouteSolution` of a search's ``(solution, status, rescued, hit_time)``."""
    sol, status, rescued, hit_time = found
    model, manager, n_v = rm.model, rm.manager, rm.n_vehicles
    routes = []
    travel = 0.0
    visited = np.zeros(rm.n_nodes, dtype=bool)
    for v in range(n_v):
        idx = model.Start(v)
        path = [v]
        route = []
        while not model.IsEnd(idx):
            idx = sol.Value(model.NextVar(idx))
            node = manager.IndexToNode(idx)
            path.append(node)
            if node >= 2 * n_v:
                route.append(int(prob.keep[node - 2 * n_v]))
                visited[node - 2 * n_v] = True
        legs = rm.dist_px[path[:-1], path[1:]]
        travel += float(legs.sum() if charge_return else legs[:-1].sum())
        routes.append(tuple(route))
    dropped = float(rm.penalty_px[~visited].sum()) + prob.out_dropped
    return RouteSolution(
        routes=tuple(routes),
        objective_px=sol.ObjectiveValue() / scale + prob.out_dropped,
        travel_px=travel,
        dropped_px=dropped,
        status="time_limit"
        if rescued or (
            status == SEARCH_STATUS.ROUTING_PARTIAL_SUCCESS_LOCAL_OPTIMUM_NOT_REACHED
            and not deterministic and hit_time
        )
        else "feasible",
        rescued=rescued,
        size={"vehicles": n_v, "nodes": rm.n_nodes, "dimensions": rm.dimensions},
    )  # fmt: skip


def _status_name(status: int) -> str:
    """The name of an OR-Tools routing search status."""
    return SEARCH_STATUS.Name(status) if status in SEARCH_STATUS.values() else str(status)


def _pairwise(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = a[:, None, :] - b[None, :, :]
    out: np.ndarray = np.sqrt(np.einsum("ijk,ijk->ij", d, d))
    return out
