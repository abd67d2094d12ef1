"""Routing scheduler: one prize-collecting vehicle routing model per role, solved by OR-Tools.

Each replan builds and solves (with OR-Tools' routing library, ``pywrapcp.RoutingModel``) up to two
models, first the **action** model, then the **perception** model:

* **Vehicles** are the available agents of the role (not ``HOMING``). A vehicle starts where the
  agent is, or at its depot slot with a full battery if the agent is on a forced return (it
  recharges first, see :attr:`fcplan.taskgraph.TaskGraph.agent_start_pos`), and ends at its depot
  slot.
* **Nodes** are the tasks that role can serve: fire tasks for action agents; search blocks *and*
  fire tasks for perception agents. Hybrids (camera and water) that still have water are action
  vehicles (fires only, no altitude is set for them, as in ``greedy``); hybrids with an empty
  tank are perception vehicles.
* **Visits are optional** (prize collecting): leaving task ``k`` unvisited costs a drop penalty
  equal to its value converted to pixels (below). Each task is visited at most once per model.
* **Dimensions**: ``distance`` (travel px) whose per-vehicle capacity is the agent's remaining
  range (``battery / 0.1`` px, a full battery for forced returns) and which includes the leg back
  to the depot slot, so every route always leaves the way home; ``visits`` counts task visits,
  capped by ``max_visits`` per vehicle and, for action vehicles, by the water left in the tank
  (each fire visit uses one dump). Per-vehicle capacities use
  ``RoutingModel.AddDimensionWithVehicleCapacity``; distances and visit counts are registered as
  a matrix / vector (``RegisterTransitMatrix``, ``RegisterUnaryTransitVector``), never as Python
  callbacks, so the search never calls back into Python. Tasks beyond a full-battery round trip
  of an agent's depot slot, or that the agent cannot reach and still fly home from, are removed
  from that node's vehicle variable (``VehicleVar(index).RemoveValues``; in OR-Tools 9.15 the
  Python wrapper of ``SetAllowedVehiclesForIndex`` rejects every argument).

**Objective** (minimised): total travel in px plus the sum of the drop penalties of the candidate
tasks left out, both in px-equivalent units. OR-Tools needs integers: distances are scaled by
``scale`` (10: decimetres) and rounded *up* (so a route the solver accepts is within the battery
in real px too), capacities are rounded down, penalties are rounded (at least 1, so a visit stays
optional). The objective in :class:`fcplan.scheduling.SolveStats` is the sum of the models'
OR-Tools objectives divided by ``scale`` (px). With ``charge_return=False`` (default) the legs
into the depot slots cost nothing (an agent replans every second, long before it would fly home;
charging the way home would pull the search towards the depot) but they still count in the
battery dimension; with ``charge_return=True`` the travel is the whole path start -> tasks ->
depot slot.

**Values** (drop penalties: how many px a vehicle would fly to serve the task):

* action, fire ``k``: ``fire_base_px + fire_value_px * value_k * freshness_k`` where ``value_k``
  is the task's known cells weighted by the facilities it threatens and ``freshness_k`` is 1
  while the fire was sensed within ``fresh_s`` seconds, then decays as
  ``exp(-(staleness - fresh_s) / fresh_s)`` (as in ``greedy``). Action agents have nothing else
  to do, so the base term (default 2000 px, more than most trips across a map) makes every
  reachable fire worth a visit while the tank and ``max_visits`` allow; the value term decides
  which fires when they do not, and travel decides the order;
* perception, search block ``k``: ``search_value_px * value_k`` (its coverage age in s, more
  near known fire), optionally discounted by ``h / (h + eta_k)`` (``search_horizon_s = h > 0``,
  ``eta_k`` the earliest arrival of any perception vehicle; off by default: it did not help);
* perception, fire ``k`` ("watching"): ``watch_value_px * value_k * w_k``. Only sensed cells can
  be pruned, and a fire being fought keeps adding unsensed cells, so ``w_k = 1`` for the fires
  a dump is imminent at: the *first* tasks of this replan's action routes (one per connected
  fire, the most valuable, for at most ``max_watch_fraction`` of the perception vehicles, at least
  one, so the others keep searching); this is why the action model is solved first. Other fires
  get ``w_k = clip((staleness - fresh_s) / fresh_s, 0, 1)``: a fire not sensed for a while is
  worth refreshing for the action agents. The default ``watch_value_px = 1000`` px per cell makes
  watching beat searching almost always (100 px per cell did not: scores were lower).

A perception route whose first task is a fire becomes a **watch**: the route is cut to that fire
(the agent hovers over it until the next replan) at ``watch_altitude`` (low: reliable sensing);
other perception routes fly at ``search_altitude`` (high: a wide view). Altitudes are clipped to
each agent's bounds. Agents with an empty route are not mentioned in the plan (they keep their
current route), as in ``greedy``.

**Model size**: each role's candidate nodes are its ``max(max_nodes, nodes_per_vehicle * V)``
most valuable tasks that one of its ``V`` vehicles can reach (default 60, or 2 per vehicle on big
teams); the others are not offered this replan. On big task graphs this is what keeps a replan
within its time limit. Routes hold at most ``max_visits`` (4) tasks.

**Search and time**: the search starts from ``first_solution`` (default
``PARALLEL_CHEAPEST_INSERTION``, which weighs insertions against drop penalties) and improves it
with ``metaheuristic`` (default ``GUIDED_LOCAL_SEARCH``):

* default mode: until ``time_limit`` seconds per replan (default 0.1 s; the ``time_limit``
  argument of :meth:`RoutingScheduler.plan` overrides it when given), model building included
  and about 10 % (at most 5 ms) kept back for turning routes into the plan. The action model gets
  a share in proportion to its node count (25 % to 50 %), the perception model the rest. A
  ``branch_limit`` (search steps, a machine-independent count) ends the search of small models
  early so they do not spin until the limit. If the limit ends a model's search before any
  solution, the first-solution heuristic is run alone past the limit (about a millisecond;
  ``rescue=True``, status ``time_limit``, noted in the message) rather than failing. The plan
  depends on the machine's speed in this mode: it is **not** reproducible run to run;
* ``deterministic=True``: the search stops after ``solution_limit`` solutions or
  ``branch_limit`` branches, whichever comes first, never on a wall time (also the LNS
  sub-searches' own time limit is made unreachable), so the same graph gives the same plan run
  to run and on any machine: use it for reproducible benchmarks. Its time per replan varies
  with the model (p50 45-66 ms, p95 80-130 ms on scenarios #1, #12, #24; 0.2-0.7 s on synthetic
  graphs of 10 x 100 to 100 x 2000 agents x tasks).

**Status**: routing never proves optimality. ``feasible``: a solution was found and the local
search reached a local optimum (OR-Tools ``ROUTING_SUCCESS``; guided local search then goes on
until the limit), or the deterministic limits stopped it; ``time_limit``: the wall-time limit
stopped the search before the local search converged
(``ROUTING_PARTIAL_SUCCESS_LOCAL_OPTIMUM_NOT_REACHED``) or the plan was rescued; the worse of the
two models is reported. If a model finds no solution (only possible with ``rescue=False``),
:class:`RoutingFailedError` is raised and :func:`fcplan.scheduling.solve` falls back to
``greedy`` for that replan (``status="fallback"``, the reason in the message).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0))
>>> plan = RoutingScheduler(deterministic=True).plan(g, time_limit=None, rng=None)
>>> plan.stats.status in ("feasible", "time_limit"), plan.stats.size["vehicles"]
(True, 4)

:func:`solve_routes` is the model on plain arrays (one vehicle from (0, 0) to its depot slot at
(0, 10), two mandatory stops):

>>> sol = solve_routes(
...     start=np.array([[0.0, 0.0]]), end=np.array([[0.0, 10.0]]),
...     nodes=np.array([[10.0, 10.0], [10.0, 0.0]]), penalty=np.full(2, np.inf),
...     budget=np.array([100.0]), charge_return=True, deterministic=True)
>>> sol.routes, round(sol.travel_px, 3)
(((1, 0),), 30.0)
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode

__all__ = ["RoutingScheduler", "RouteSolution", "RoutingFailedError", "solve_routes"]

_FSS = routing_enums_pb2.FirstSolutionStrategy.Value
_LSM = routing_enums_pb2.LocalSearchMetaheuristic.Value
_RSS = routing_enums_pb2.RoutingSearchStatus.Value
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


def _pairwise(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = a[:, None, :] - b[None, :, :]
    return np.sqrt(np.einsum("ijk,ijk->ij", d, d))


def _search_parameters(
    time_left: float | None,
    deterministic: bool,
    solution_limit: int,
    first_solution: str,
    metaheuristic: str,
):
    p = pywrapcp.DefaultRoutingSearchParameters()
    p.first_solution_strategy = _FSS.Value(first_solution)
    p.local_search_metaheuristic = _LSM.Value(metaheuristic)
    if deterministic:
        p.solution_limit = int(solution_limit)
        # the completion searches of the LNS operators have a wall-time limit (0.1 s by
        # default): make it unreachable so that nothing depends on the machine's speed
        p.lns_time_limit.FromSeconds(3600)
    elif time_left is not None:
        p.time_limit.FromMicroseconds(max(int(time_left * 1e6), 1))
    return p


def _model_parameters():
    mp = pywrapcp.DefaultRoutingModelParameters()
    # small models: an uncompressed search trail is faster than zlib's
    mp.solver_parameters.compress_trail = mp.solver_parameters.NO_COMPRESSION
    return mp


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
    deterministic : bool
        Stop after ``solution_limit`` solutions instead of a wall time.
    solution_limit : int
        Solutions to examine in deterministic mode.
    branch_limit : int, optional
        Stop the search after this many search branches (a machine-independent work unit), in
        both modes. Metaheuristics on tiny models can search on without ever finding another
        solution; this limit ends them. None: no such limit.
    first_solution, metaheuristic : str
        Names of OR-Tools ``FirstSolutionStrategy`` and ``LocalSearchMetaheuristic`` values.
    scale : float
        Integer units per px (10: decimetres).
    rescue : bool
        If the wall-time limit ends the search before a first solution, run the first-solution
        heuristic alone without a wall-time limit (typically about a millisecond; the result
        has ``status="time_limit"`` and ``rescued=True``) instead of raising.

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
    start = np.asarray(start, dtype=np.float64).reshape(-1, 2)
    end = np.asarray(end, dtype=np.float64).reshape(-1, 2)
    nodes = np.asarray(nodes, dtype=np.float64).reshape(-1, 2)
    penalty = np.asarray(penalty, dtype=np.float64)
    budget = np.asarray(budget, dtype=np.float64)
    n_v, n_n = len(start), len(nodes)
    ok = np.ones((n_v, n_n), dtype=bool) if allowed is None else np.asarray(allowed, dtype=bool)
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
    if n_v == 0 or keep.size == 0:
        return RouteSolution(
            ((),) * n_v, out_dropped, 0.0, out_dropped, "feasible",
            {"vehicles": n_v, "nodes": 0, "dimensions": 0},
        )  # fmt: skip
    ok = ok[:, keep]
    m = keep.size
    # node order in the model: V starts, V ends, m tasks
    pts = np.concatenate([start, end, nodes[keep]])
    dist_px = _pairwise(pts, pts)
    dist = np.ceil(dist_px * scale - 1e-9).astype(np.int64)
    direct = dist[np.arange(n_v), n_v + np.arange(n_v)]
    cap = np.maximum(np.floor(budget * scale + 1e-9), direct).astype(np.int64)
    cap = np.minimum(cap, _BIG)

    manager = pywrapcp.RoutingIndexManager(
        len(pts), n_v, list(range(n_v)), list(range(n_v, 2 * n_v))
    )
    model = pywrapcp.RoutingModel(manager, _model_parameters())
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
    pen = np.where(np.isfinite(penalty[keep]), penalty[keep], 0.0)
    pen_int = np.clip(np.rint(pen * scale), 1, _BIG).astype(np.int64)
    restricted = ~ok.all(axis=0)
    vehicles = np.arange(n_v)
    for j in range(m):  # the Python API adds disjunctions one node at a time
        index = manager.NodeToIndex(2 * n_v + j)
        if not mandatory[keep[j]]:
            model.AddDisjunction([index], int(pen_int[j]))
        if restricted[j]:
            # (SetAllowedVehiclesForIndex's absl::Span argument is not wrapped for Python in 9.15)
            model.VehicleVar(index).RemoveValues(vehicles[~ok[:, j]].tolist())
    t0 = time.perf_counter()
    time_left = None if time_limit is None else time_limit - (t0 - t_enter)
    params = _search_parameters(
        time_left, deterministic, solution_limit, first_solution, metaheuristic
    )
    if branch_limit is not None:
        model.AddSearchMonitor(model.solver().BranchesLimit(int(branch_limit)))
    sol = model.SolveWithParameters(params)
    hit_time = time_left is not None and time.perf_counter() - t0 >= 0.95 * time_left
    status = model.status()
    rescued = False
    if sol is None and rescue and time_left is not None:
        # the wall-time limit ended the search before a first solution (OR-Tools reports this as
        # ROUTING_FAIL_TIMEOUT or, when the limit is already spent at the start, ROUTING_FAIL):
        # take the first-solution heuristic's answer without a wall-time limit (about a
        # millisecond on these models); a truly infeasible model fails again and raises below
        params = _search_parameters(None, True, 1, first_solution, metaheuristic)
        sol = model.SolveWithParameters(params)
        status, rescued, hit_time = model.status(), sol is not None, True
    if sol is None:
        name = _RSS.Name(status) if status in _RSS.values() else str(status)
        raise RoutingFailedError(
            f"no routing solution ({name}) for {n_v} vehicles x {m} nodes within "
            + (f"{solution_limit} solutions" if deterministic else f"{time_limit} s")
            + (f" and {branch_limit} branches" if branch_limit is not None else "")
        )
    routes = []
    travel = 0.0
    visited = np.zeros(m, dtype=bool)
    for v in range(n_v):
        idx = model.Start(v)
        path = [v]
        route = []
        while not model.IsEnd(idx):
            idx = sol.Value(model.NextVar(idx))
            node = manager.IndexToNode(idx)
            path.append(node)
            if node >= 2 * n_v:
                route.append(int(keep[node - 2 * n_v]))
                visited[node - 2 * n_v] = True
        legs = dist_px[path[:-1], path[1:]]
        travel += float(legs.sum() if charge_return else legs[:-1].sum())
        routes.append(tuple(route))
    dropped = float(pen[~visited].sum()) + out_dropped
    return RouteSolution(
        routes=tuple(routes),
        objective_px=sol.ObjectiveValue() / scale + out_dropped,
        travel_px=travel,
        dropped_px=dropped,
        status="time_limit"
        if rescued or (
            status == _RSS.ROUTING_PARTIAL_SUCCESS_LOCAL_OPTIMUM_NOT_REACHED
            and not deterministic and hit_time
        )
        else "feasible",
        rescued=rescued,
        size={"vehicles": n_v, "nodes": m, "dimensions": dims},
    )  # fmt: skip


class RoutingScheduler:
    """Prize-collecting vehicle routing per role with OR-Tools (see the module docstring).

    Parameters
    ----------
    time_limit : float
        Default seconds per replan (both models together), used when :meth:`plan` gets
        ``time_limit=None``.
    deterministic : bool
        Stop each model's search after ``solution_limit`` solutions instead of a wall time:
        identical plans run to run.
    solution_limit : int
        Solutions per model in deterministic mode.
    branch_limit : int, optional
        Search branches per model (both modes; ends the search of small models early).
    max_visits : int
        Most tasks per route.
    max_nodes, nodes_per_vehicle : int
        Candidate tasks per role per replan: the ``max(max_nodes, nodes_per_vehicle * V)`` most
        valuable reachable ones, ``V`` the role's vehicles.
    fire_base_px : float
        Drop penalty (px) of any fire task for action agents, on top of the value term: action
        agents have nothing else to do, so every reachable fire is worth a trip this long.
    fire_value_px : float
        Drop penalty (px) per unit of (freshness-weighted) fire value for action agents.
    watch_value_px : float
        Drop penalty (px) per unit of fire value for perception agents watching a fire that is
        being fought or is stale.
    search_value_px : float
        Drop penalty (px) per unit of search value (coverage age, s) for perception agents.
    search_horizon_s : float
        If > 0, a search block's penalty is multiplied by ``h / (h + eta)`` with ``eta`` the
        earliest arrival (s) of any perception vehicle at the block (0: no discount).
    fresh_s : float
        A fire sensed within this many seconds counts as fresh.
    watch_altitude, search_altitude : float
        Altitudes (m) of watching and searching perception agents (clipped to their bounds).
    max_watch_fraction : float
        Largest share of the perception vehicles offered a fire being fought to watch (at
        least one; one fire per connected fire), so the others keep searching.
    charge_return : bool
        Count the way back to the depot slot in the objective (it always counts for the battery).
    first_solution, metaheuristic : str
        OR-Tools ``FirstSolutionStrategy`` / ``LocalSearchMetaheuristic`` names.
    scale : float
        Integer units per px in the model (10: decimetres).
    rescue : bool
        When the time limit ends a model's search before any solution, use the first-solution
        heuristic's routes found just after the limit (status ``time_limit``, noted in the
        message) rather than raising (and falling back to greedy).
    """

    name = "routing"

    def __init__(
        self,
        time_limit: float = 0.1,
        deterministic: bool = False,
        solution_limit: int = 40,
        branch_limit: int | None = 2000,
        max_visits: int = 4,
        max_nodes: int = 60,
        nodes_per_vehicle: int = 2,
        fire_base_px: float = 2000.0,
        fire_value_px: float = 200.0,
        watch_value_px: float = 1000.0,
        search_value_px: float = 10.0,
        search_horizon_s: float = 0.0,
        fresh_s: float = 5.0,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        max_watch_fraction: float = 0.5,
        charge_return: bool = False,
        first_solution: str = "PARALLEL_CHEAPEST_INSERTION",
        metaheuristic: str = "GUIDED_LOCAL_SEARCH",
        scale: float = 10.0,
        rescue: bool = True,
    ) -> None:
        for what, value, enum in (
            ("first_solution", first_solution, _FSS),
            ("metaheuristic", metaheuristic, _LSM),
        ):
            names = list(enum.keys())
            if value not in names:
                raise ValueError(f"unknown {what} {value!r}; one of {', '.join(names)}")
        if not time_limit > 0:
            raise ValueError(f"time_limit must be > 0 s, got {time_limit!r}")
        self.time_limit = float(time_limit)
        self.deterministic = bool(deterministic)
        self.solution_limit = int(solution_limit)
        self.branch_limit = None if branch_limit is None else int(branch_limit)
        self.max_visits = int(max_visits)
        self.max_nodes = int(max_nodes)
        self.nodes_per_vehicle = int(nodes_per_vehicle)
        self.fire_base_px = float(fire_base_px)
        self.fire_value_px = float(fire_value_px)
        self.watch_value_px = float(watch_value_px)
        self.search_value_px = float(search_value_px)
        self.search_horizon_s = float(search_horizon_s)
        self.fresh_s = float(fresh_s)
        self.watch_altitude = float(watch_altitude)
        self.search_altitude = float(search_altitude)
        self.max_watch_fraction = float(max_watch_fraction)
        self.charge_return = bool(charge_return)
        self.first_solution = first_solution
        self.metaheuristic = metaheuristic
        self.scale = float(scale)
        self.rescue = bool(rescue)

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng=None) -> Plan:
        """Route both roles on ``graph`` within ``time_limit`` seconds (default: the setting).

        Raises
        ------
        RoutingFailedError
            If a model finds no solution in time (:func:`fcplan.scheduling.solve` then falls
            back to greedy).
        """
        limit = self.time_limit if time_limit is None else float(time_limit)
        # keep a little of the limit for turning routes into the plan and freeing the models
        deadline = time.perf_counter() + limit - min(0.1 * limit, 0.005)
        start = graph.agent_start_pos
        budget = graph.agent_budget_px
        trip = graph.in_round_trip
        free = graph.agent_mode != Mode.HOMING
        actors = np.flatnonzero(free & graph.agent_can_act & (graph.agent_tank > 0))
        sensors = np.flatnonzero(
            free & graph.agent_can_sense & ~(graph.agent_can_act & (graph.agent_tank > 0))
        )
        fires, blocks = graph.fire_tasks, graph.search_tasks
        stale = graph.task_staleness[fires]
        fresh = np.exp(-np.maximum(stale - self.fresh_s, 0.0) / max(self.fresh_s, 1e-9))
        act_value = self.fire_base_px + self.fire_value_px * graph.task_value[fires] * fresh
        act_value = np.where(graph.task_value[fires] > 0, act_value, 0.0)

        act_nodes = self._candidates(graph, actors, fires, act_value, start, budget, trip)
        sense_value_guess = np.r_[
            self.watch_value_px * graph.task_value[fires],
            self.search_value_px * graph.task_value[blocks],
        ]
        n_sense = min(
            self._n_candidates(sensors.size),
            int((sense_value_guess > 0).sum()) if sensors.size else 0,
        )  # for the time split only
        routes: dict[str, tuple[str, ...]] = {}
        alts: dict[str, float] = {}
        sols: dict[str, RouteSolution] = {}

        # 1. action agents -> fires (one visit per dump left in the tank)
        first_fires: list[int] = []
        if actors.size and act_nodes[0].size:
            share = act_nodes[0].size / (act_nodes[0].size + n_sense)
            share = 1.0 if n_sense == 0 else min(max(share, 0.25), 0.5)
            sol = self._solve(
                graph, actors, act_nodes, start, budget, trip, deadline, share,
                capacity=graph.agent_tank[actors],
            )  # fmt: skip
            sols["action"] = sol
            for v, route in enumerate(sol.routes):
                if route:
                    ks = act_nodes[0][list(route)]
                    routes[graph.agent_ids[actors[v]]] = tuple(graph.task_ids[k] for k in ks)
                    first_fires.append(int(ks[0]))

        # 2. perception agents -> search blocks and fires to watch
        if sensors.size:
            fought = self._fought(graph, fires, first_fires, sensors.size)
            share_stale = np.clip((stale - self.fresh_s) / max(self.fresh_s, 1e-9), 0.0, 1.0)
            watch = self.watch_value_px * graph.task_value[fires] * np.maximum(fought, share_stale)
            tasks = np.r_[fires, blocks].astype(np.int64)
            search = self.search_value_px * graph.task_value[blocks]
            if self.search_horizon_s > 0 and blocks.size:
                # information is worth less the later it comes: discount each block by the
                # earliest arrival of any perception vehicle (keeps searchers near the action)
                eta = (
                    _pairwise(start[sensors], graph.task_pos[blocks])
                    / graph.agent_speed[sensors, None]
                )
                search = search * self.search_horizon_s / (self.search_horizon_s + eta.min(0))
            value = np.r_[watch, search]
            nodes = self._candidates(graph, sensors, tasks, value, start, budget, trip)
            if nodes[0].size:
                sol = self._solve(graph, sensors, nodes, start, budget, trip, deadline, 1.0)
                sols["perception"] = sol
                for v, route in enumerate(sol.routes):
                    if not route:
                        continue
                    i = int(sensors[v])
                    ks = nodes[0][list(route)]
                    if graph.task_kind[ks[0]] == TaskKind.FIRE:
                        ks, z = ks[:1], self.watch_altitude  # watch: hover over the fire
                    else:
                        z = self.search_altitude
                    routes[graph.agent_ids[i]] = tuple(graph.task_ids[k] for k in ks)
                    alts[graph.agent_ids[i]] = graph.clip_altitude(i, z)

        status = (
            "time_limit" if any(s.status == "time_limit" for s in sols.values()) else "feasible"
        )
        size = {
            "models": len(sols),
            "vehicles": sum(s.size["vehicles"] for s in sols.values()),
            "nodes": sum(s.size["nodes"] for s in sols.values()),
            "dimensions": sum(s.size["dimensions"] for s in sols.values()),
            "agents": graph.n_agents,
            "tasks": graph.n_tasks,
        }
        message = "; ".join(
            f"{role}: {s.size['vehicles']} vehicles x {s.size['nodes']} nodes, travel "
            f"{s.travel_px:.0f} px, dropped {s.dropped_px:.0f} px, {s.status}"
            + (" (rescued: first solution after the limit)" if s.rescued else "")
            for role, s in sols.items()
        )
        return Plan(
            routes=routes,
            altitudes=alts,
            stats=SolveStats(
                status=status,
                objective=float(sum(s.objective_px for s in sols.values())),
                size=size,
                message=message,
            ),
        )

    # ------------------------------------------------------------------ helpers
    def _fought(
        self, graph: TaskGraph, fires: np.ndarray, first_fires: list[int], n_sensors: int
    ) -> np.ndarray:
        """(len(fires),) bool: the fires worth watching because a dump is imminent: first tasks
        of action routes, one per connected fire (the most valuable), at most
        ``max_watch_fraction`` of the perception vehicles (at least one)."""
        out = np.zeros(fires.size, dtype=bool)
        if not first_fires:
            return out
        ks = np.unique(np.asarray(first_fires, dtype=np.int64))
        ks = ks[np.argsort(-graph.task_value[ks], kind="stable")]
        _, first = np.unique(graph.task_cluster[ks], return_index=True)
        ks = ks[np.sort(first)]  # the most valuable fire of each cluster, by value
        n_watch = max(1, int(self.max_watch_fraction * n_sensors))
        out[np.isin(fires, ks[:n_watch])] = True
        return out

    def _n_candidates(self, n_vehicles: int) -> int:
        """Candidate nodes for a model with ``n_vehicles`` vehicles."""
        return max(self.max_nodes, self.nodes_per_vehicle * n_vehicles)

    def _candidates(
        self,
        graph: TaskGraph,
        agents: np.ndarray,
        tasks: np.ndarray,
        value: np.ndarray,
        start: np.ndarray,
        budget: np.ndarray,
        trip: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(task rows, penalties px) of the most valuable tasks (see :meth:`_n_candidates`) some
        agent of ``agents`` can serve (positive value, within a round trip, reachable with the way
        home)."""
        if agents.size == 0 or tasks.size == 0:
            return np.zeros(0, np.int64), np.zeros(0)
        d = (
            _pairwise(start[agents], graph.task_pos[tasks])
            + graph.task_home_distance[np.ix_(agents, tasks)]
        )
        reach = (trip[np.ix_(agents, tasks)] & (d <= budget[agents, None])).any(axis=0)
        ok = np.flatnonzero(reach & (value > 0))
        top = ok[np.argsort(-value[ok], kind="stable")[: self._n_candidates(agents.size)]]
        top = np.sort(top)  # task order: the model does not depend on value ties
        return tasks[top], value[top]

    def _solve(
        self,
        graph: TaskGraph,
        agents: np.ndarray,
        nodes: tuple[np.ndarray, np.ndarray],
        start: np.ndarray,
        budget: np.ndarray,
        trip: np.ndarray,
        deadline: float,
        share: float,
        capacity: np.ndarray | None = None,
    ) -> RouteSolution:
        """Solve one role's model with ``share`` of the time left before ``deadline``."""
        tasks, penalty = nodes
        left = max(deadline - time.perf_counter(), 0.0) * share
        return solve_routes(
            start[agents],
            graph.agent_home[agents],
            graph.task_pos[tasks],
            penalty,
            budget[agents],
            capacity=capacity,
            allowed=trip[np.ix_(agents, tasks)],
            max_visits=self.max_visits,
            charge_return=self.charge_return,
            time_limit=max(left, 1e-6),
            deterministic=self.deterministic,
            solution_limit=self.solution_limit,
            branch_limit=self.branch_limit,
            first_solution=self.first_solution,
            metaheuristic=self.metaheuristic,
            scale=self.scale,
            rescue=self.rescue,
        )
