"""How OR-Tools searches a routing model: parameters, limits, and the rescue after a time-out.

The search starts from a first-solution heuristic (``first_solution``, an OR-Tools
``FirstSolutionStrategy`` name) and improves it with a local-search metaheuristic
(``metaheuristic``, a ``LocalSearchMetaheuristic`` name). It stops

* in the default mode at the wall-time limit, or
* with ``deterministic=True`` after ``solution_limit`` solutions, never on a wall time (the LNS
  sub-searches' own time limit is made unreachable too), so the same model gives the same
  routes on any machine,

and in both modes after ``branch_limit`` search branches (a machine-independent work unit that
ends the search of small models early). If the wall-time limit ends the search before any
solution, the first-solution heuristic is run alone past the limit (``rescue``) rather than
failing.
"""

from __future__ import annotations

import time
from typing import Any

from ortools.constraint_solver import pywrapcp, routing_enums_pb2

__all__ = [
    "FIRST_SOLUTIONS",
    "METAHEURISTICS",
    "SEARCH_STATUS",
    "model_parameters",
    "search",
    "search_parameters",
]

#: OR-Tools enums: first-solution strategies, metaheuristics, search statuses (by name)
FIRST_SOLUTIONS = routing_enums_pb2.FirstSolutionStrategy.Value
METAHEURISTICS = routing_enums_pb2.LocalSearchMetaheuristic.Value
SEARCH_STATUS = routing_enums_pb2.RoutingSearchStatus.Value


def search_parameters(
    time_left: float | None,
    deterministic: bool,
    solution_limit: int,
    first_solution: str,
    metaheuristic: str,
) -> Any:
    """OR-Tools ``RoutingSearchParameters`` for one search (see the module docstring)."""
    p = pywrapcp.DefaultRoutingSearchParameters()
    p.first_solution_strategy = FIRST_SOLUTIONS.Value(first_solution)
    p.local_search_metaheuristic = METAHEURISTICS.Value(metaheuristic)
    if deterministic:
        p.solution_limit = int(solution_limit)
        # the completion searches of the LNS operators have a wall-time limit (0.1 s by
        # default): make it unreachable so that nothing depends on the machine's speed
        p.lns_time_limit.FromSeconds(3600)
    elif time_left is not None:
        p.time_limit.FromMicroseconds(max(int(time_left * 1e6), 1))
    return p


def model_parameters() -> Any:
    """OR-Tools ``RoutingModelParameters`` of the (small) models built here."""
    mp = pywrapcp.DefaultRoutingModelParameters()
    # small models: an uncompressed search trail is faster than zlib's
    mp.solver_parameters.compress_trail = mp.solver_parameters.NO_COMPRESSION
    return mp


def search(
    model: Any,
    t0: float,
    time_left: float | None,
    *,
    deterministic: bool,
    solution_limit: int,
    branch_limit: int | None,
    first_solution: str,
    metaheuristic: str,
    rescue: bool,
) -> tuple[Any, int, bool, bool]:
    """Search ``model`` (started at ``perf_counter`` time ``t0`` with ``time_left`` seconds).

    Returns
    -------
    solution : OR-Tools assignment or None
    status : int
        The model's ``RoutingSearchStatus`` after the search.
    rescued : bool
        The time limit ended the search before any solution; ``solution`` is the
        first-solution heuristic's, found after the limit.
    hit_time : bool
        The search ran until (95 % of) the wall-time limit, or was rescued.
    """
    params = search_parameters(
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
        # millisecond on these models); a truly infeasible model fails again
        params = search_parameters(None, True, 1, first_solution, metaheuristic)
        sol = model.SolveWithParameters(params)
        status, rescued, hit_time = model.status(), sol is not None, True
    return sol, status, rescued, hit_time
