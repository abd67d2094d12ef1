"""The OR-Tools backend of :func:`solvers.routing.solve_routes`.

Model (``pywrapcp.RoutingModel``): one node per distinct start/end location, then one per task;
arc costs are the scaled distances rounded up (``ceil(scale * d)``), with the arcs into the end
nodes free when ``charge_return=False``. Dimensions only where they bind: ``distance`` (cumulated
scaled distance <= ``floor(scale * budget)``, the leg to the end included) and ``visits`` (one per
task <= the vehicle's capacity). An optional task is a disjunction with penalty
``rint(scale * prize)`` (at least 1); a task only some vehicles may serve has its vehicle variable
restricted. Distances are registered as matrices, never as Python callbacks, so the search never
calls back into Python.

Search: a first-solution heuristic (``first_solution``, an OR-Tools ``FirstSolutionStrategy``
name, or ``"auto"``: ``CHRISTOFIDES`` for a single vehicle through required tasks only, a TSP or
shortest Hamiltonian path, else ``PARALLEL_CHEAPEST_INSERTION``, which weighs insertions against
prizes) or
the warm start (``ReadAssignmentFromRoutes`` then ``SolveFromAssignmentWithParameters``), then a
local-search metaheuristic (``metaheuristic``, default guided local search with penalty factor
``gls_lambda``). It stops

* in wall-clock mode at ``wall_fraction`` of the time left before the deadline once the model
  is built, less ``reserve_s`` for reading and completing the routes (OR-Tools' own
  ``time_limit``). OR-Tools spaces its clock checks out by how fast its search steps ran so far,
  so on a loaded machine it overshoots its limit (measured: by 10-30 ms on 0.1 s under a load of
  12 on 2 cores); the fraction absorbs that;
* in deterministic mode after ``solution_limit`` solutions or ``branch_limit`` search branches,
  whichever comes first (guided local search on a tiny model may find no new solution for
  ever: the branches end it), never on the clock (the LNS sub-searches' own wall-time limit is
  made unreachable);

and in wall-clock mode also after ``wall_branch_limit`` branches when given (ends the search of
small models early).

Measured choices (``bench/README.md``, "routing core"): on TSPLIB tours ``CHRISTOFIDES`` was
the most robust start (``PARALLEL_CHEAPEST_INSERTION`` stayed 4-8 % above the optimum on
51-130 cities at 0.1 s); on the scheduler's prize-collecting models of the shipped scenarios
``PARALLEL_CHEAPEST_INSERTION`` was (``PATH_CHEAPEST_ARC`` and ``CHRISTOFIDES`` ended up to 32 %
and 52 % worse at the scheduler's deterministic budget).

Examples
--------
>>> import numpy as np
>>> from solvers.routing.core import RoutingInstance
>>> xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], dtype=float)
>>> inst = RoutingInstance.of(np.linalg.norm(xy[:, None] - xy[None], axis=2), [0], [3])
>>> solve_ortools(inst, OrToolsOptions(solution_limit=10), None, None).routes
((1, 2),)
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from solvers.routing.core import RoutesResult, RoutingFailedError, RoutingInstance
from solvers.routing.insertion import settle

__all__ = ["FIRST_SOLUTIONS", "METAHEURISTICS", "OrToolsOptions", "solve_ortools"]

#: OR-Tools enums by name: first-solution strategies, metaheuristics, search statuses
FIRST_SOLUTIONS = routing_enums_pb2.FirstSolutionStrategy.Value
METAHEURISTICS = routing_enums_pb2.LocalSearchMetaheuristic.Value
_STATUS = routing_enums_pb2.RoutingSearchStatus.Value

#: largest penalty / capacity fed to OR-Tools (int64 costs are summed: stay far from overflow)
_BIG = 10**12


@dataclass(frozen=True, slots=True)
class OrToolsOptions:
    """Search settings of the OR-Tools backend (see the module docstring).

    Parameters
    ----------
    first_solution : str
        ``FirstSolutionStrategy`` name, or ``"auto"`` (see the module docstring).
    metaheuristic : str
        ``LocalSearchMetaheuristic`` name.
    solution_limit, branch_limit : int
        Solutions and search branches before the search stops in deterministic mode (whichever
        comes first).
    wall_branch_limit : int, optional
        Search branches before the search stops in wall-clock mode (None: no such limit).
    gls_lambda : float
        Guided local search's penalty factor.
    scale : float
        Integer units per distance unit.
    reserve_s : float
        Seconds kept back from the deadline (wall-clock mode) for reading the routes.
    wall_fraction : float
        Share of the time left (after ``reserve_s``) given to OR-Tools' own time limit.
    """

    first_solution: str = "auto"
    metaheuristic: str = "GUIDED_LOCAL_SEARCH"
    solution_limit: int = 2000
    branch_limit: int = 20_000
    wall_branch_limit: int | None = None
    gls_lambda: float = 0.1
    scale: float = 10.0
    reserve_s: float = 0.001
    wall_fraction: float = 0.8

    def __post_init__(self) -> None:
        for what, value, enum in (
            ("first_solution", self.first_solution, FIRST_SOLUTIONS),
            ("metaheuristic", self.metaheuristic, METAHEURISTICS),
        ):
            names = list(enum.keys()) + (["auto"] if what == "first_solution" else [])
            if value not in names:
                raise ValueError(f"unknown {what} {value!r}; one of {', '.join(names)}")
        if self.solution_limit < 1 or self.branch_limit < 1:
            raise ValueError("solution_limit and branch_limit must be >= 1")
        if not 0 < self.wall_fraction <= 1:
            raise ValueError(f"wall_fraction must be in (0, 1], got {self.wall_fraction!r}")
        if not self.scale > 0:
            raise ValueError(f"scale must be > 0, got {self.scale!r}")


@dataclass(frozen=True, eq=False)
class _Model:
    """A routing model of an instance, and how its nodes map back."""

    manager: Any  # pywrapcp.RoutingIndexManager
    model: Any  # pywrapcp.RoutingModel
    n_depots: int  # nodes [0, n_depots) are start/end locations, then the tasks


def solve_ortools(
    inst: RoutingInstance,
    opts: OrToolsOptions,
    deadline: float | None,
    warm: list[list[int]] | None,
    from_warm: bool = True,
) -> RoutesResult:
    """Search ``inst`` with OR-Tools until ``deadline`` (``perf_counter`` time; None:
    deterministic, on ``opts``' work limits), starting from ``warm`` (task positions) if given
    and ``from_warm``."""
    rm = _build(inst, opts)
    params = _parameters(opts, deadline, _first_solution(inst, opts))
    time_left = None
    if deadline is not None:
        time_left = deadline - time.perf_counter() - opts.reserve_s
        if time_left <= 0:
            return settle(inst, None, warm, backend="ortools", timed_out=True,
                          warm_started=False, work={"branches": 0})  # fmt: skip
        params.time_limit.FromMicroseconds(max(int(opts.wall_fraction * time_left * 1e6), 1))
    model = rm.model
    branches = opts.branch_limit if deadline is None else opts.wall_branch_limit
    if branches is not None:
        model.AddSearchMonitor(model.solver().BranchesLimit(int(branches)))
    model.CloseModelWithParameters(params)
    start = None
    if warm is not None and from_warm:
        idx = [[rm.manager.NodeToIndex(rm.n_depots + k) for k in r] for r in warm]
        start = model.ReadAssignmentFromRoutes(idx, True)
    t0 = time.perf_counter()
    if start is not None:
        sol = model.SolveFromAssignmentWithParameters(start, params)
    else:
        sol = model.SolveWithParameters(params)
    status = model.status()
    timed_out = time_left is not None and (
        status in (_STATUS.ROUTING_FAIL_TIMEOUT, _STATUS.ROUTING_FAIL)
        or time.perf_counter() - t0 >= 0.95 * opts.wall_fraction * time_left
    )
    if sol is None and not timed_out:
        raise RoutingFailedError(f"ortools: no routes ({_STATUS.Name(status)})")
    routes = None if sol is None else _routes(rm, sol, inst.n_vehicles)
    work = {"branches": int(model.solver().Branches())}
    return settle(inst, routes, warm, backend="ortools", timed_out=timed_out,
                  warm_started=start is not None, work=work)  # fmt: skip


def _first_solution(inst: RoutingInstance, opts: OrToolsOptions) -> str:
    """The first-solution strategy for ``inst`` (resolves ``"auto"``)."""
    if opts.first_solution != "auto":
        return opts.first_solution
    tsp = inst.n_vehicles == 1 and bool(inst.required.all()) and inst.visits[0] >= inst.n_tasks
    return "CHRISTOFIDES" if tsp else "PARALLEL_CHEAPEST_INSERTION"


def _parameters(opts: OrToolsOptions, deadline: float | None, first_solution: str) -> Any:
    """``RoutingSearchParameters`` of one search (the wall-time limit is set by the caller)."""
    p = pywrapcp.DefaultRoutingSearchParameters()
    p.first_solution_strategy = FIRST_SOLUTIONS.Value(first_solution)
    p.local_search_metaheuristic = METAHEURISTICS.Value(opts.metaheuristic)
    p.guided_local_search_lambda_coefficient = float(opts.gls_lambda)
    if deadline is None:
        p.solution_limit = int(opts.solution_limit)
        # the completion searches of the LNS operators have a wall-time limit (0.1 s by
        # default): make it unreachable so that nothing depends on the machine's speed
        p.lns_time_limit.FromSeconds(3600)
    return p


def _build(inst: RoutingInstance, opts: OrToolsOptions) -> _Model:
    """The OR-Tools model of ``inst`` (see the module docstring)."""
    n_v, m, scale = inst.n_vehicles, inst.n_tasks, opts.scale
    depots, inv = np.unique(np.r_[inst.starts, inst.ends], return_inverse=True)
    n_d = len(depots)
    locs = np.r_[depots, inst.tasks]
    dist = np.ceil(inst.dist[np.ix_(locs, locs)] * scale - 1e-9).astype(np.int64)
    np.fill_diagonal(dist, 0)
    s_node, e_node = inv[:n_v], inv[n_v:]
    manager = pywrapcp.RoutingIndexManager(
        n_d + m, n_v, [int(x) for x in s_node], [int(x) for x in e_node]
    )
    mp = pywrapcp.DefaultRoutingModelParameters()
    # small models: an uncompressed search trail is faster than zlib's
    mp.solver_parameters.compress_trail = mp.solver_parameters.NO_COMPRESSION
    model = pywrapcp.RoutingModel(manager, mp)
    dist_cb = model.RegisterTransitMatrix(dist.tolist())
    if inst.charge_return:
        model.SetArcCostEvaluatorOfAllVehicles(dist_cb)
    else:
        cost = dist.copy()
        cost[:, np.unique(e_node)] = 0
        model.SetArcCostEvaluatorOfAllVehicles(model.RegisterTransitMatrix(cost.tolist()))
    if np.isfinite(inst.budget).any():
        direct = dist[s_node, e_node]
        cap = np.where(np.isfinite(inst.budget), np.floor(inst.budget * scale + 1e-9), _BIG)
        cap = np.minimum(np.maximum(cap, direct), _BIG).astype(np.int64)
        model.AddDimensionWithVehicleCapacity(dist_cb, 0, cap.tolist(), True, "distance")
    if (inst.visits < m).any():
        unit = model.RegisterUnaryTransitVector([0] * n_d + [1] * m)
        model.AddDimensionWithVehicleCapacity(unit, 0, inst.visits.tolist(), True, "visits")
    pen = np.clip(np.rint(np.where(inst.required, 0, inst.prize) * scale), 1, _BIG)
    pen = pen.astype(np.int64).tolist()
    required = inst.required.tolist()
    restricted: list[bool] = np.logical_not(inst.ok.all(axis=0)).tolist()
    vehicles = np.arange(n_v)
    for j in range(m):  # the Python API adds disjunctions one node at a time
        index = manager.NodeToIndex(n_d + j)
        if not required[j]:
            model.AddDisjunction([index], pen[j])
        if restricted[j]:
            # (SetAllowedVehiclesForIndex's absl::Span argument is not wrapped for Python)
            model.VehicleVar(index).RemoveValues(vehicles[~inst.ok[:, j]].tolist())
    return _Model(manager, model, n_d)


def _routes(rm: _Model, sol: Any, n_vehicles: int) -> list[list[int]]:
    """Per vehicle, the task positions of an OR-Tools assignment's routes."""
    model, manager, n_d = rm.model, rm.manager, rm.n_depots
    routes = []
    for v in range(n_vehicles):
        idx = sol.Value(model.NextVar(model.Start(v)))
        route = []
        while not model.IsEnd(idx):
            route.append(manager.IndexToNode(idx) - n_d)
            idx = sol.Value(model.NextVar(idx))
        routes.append(route)
    return routes
