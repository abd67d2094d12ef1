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

import time
from collections.abc import Sequence
from typing import Any

from solvers.routing.instance import BACKENDS, RoutesResult, RoutingFailedError, RoutingInstance
from solvers.routing.ortools_backend import OrToolsOptions, solve_ortools
from solvers.routing.pyvrp_backend import PyVRPOptions, solve_pyvrp

__all__ = ["BACKENDS", "RoutesResult", "RoutingFailedError", "RoutingInstance", "solve_routes"]


def solve_routes(
    dist: Any,
    *,
    starts: Any,
    ends: Any = None,
    prizes: Any = None,
    budgets: Any = None,
    capacities: Any = None,
    allowed: Any = None,
    charge_return: bool = True,
    time_limit: float | None = 0.1,
    deterministic: bool = False,
    warm_start: Sequence[Sequence[int]] | None = None,
    search_from_warm: bool = True,
    backend: str = "ortools",
    options: Any = None,
) -> RoutesResult:
    """Solve one prize-collecting routing problem on a distance matrix (see the module
    docstring for the model and the time-limit rule).

    Parameters
    ----------
    dist : array_like, (L, L)
        Travel between locations (>= 0; need not be symmetric).
    starts : array_like of int, (V,)
        Start location of each vehicle.
    ends : array_like of int, (V,), optional
        End location of each vehicle (default: its start, closed tours). Locations that are no
        vehicle's start or end are the tasks.
    prizes : array_like, (L,), optional
        Prize of visiting each task location (``inf``: required; entries of start and end
        locations are ignored). Default: every task is required.
    budgets : array_like, (V,), optional
        Most route length of each vehicle, the leg to its end included (default: none).
    capacities : array_like of int, (V,), optional
        Most visits of each vehicle (default: none).
    allowed : array_like of bool, (V, L), optional
        Which vehicle may visit which task location (default: any).
    charge_return : bool
        Count the closing leg into the end in the objective (it always counts for the budget).
    time_limit : float, optional
        Wall seconds for the whole call (ignored when ``deterministic``; None: only the work
        limits of ``options``).
    deterministic : bool
        Stop on the backend's work limit only (identical routes in any process, any load).
    warm_start : sequence of sequence of int, optional
        Routes to start from, as task locations per vehicle (e.g. the previous replan's). Tasks
        that are not in this problem or not allowed are skipped, routes are cut to fit.
    search_from_warm : bool
        Start the search from the warm start (else from the backend's own start; the warm start
        is then only the answer when the clock ends the search before anything better).
    backend : {"ortools", "pyvrp"}
    options : OrToolsOptions or PyVRPOptions, optional
        The backend's search settings (default: its defaults).

    Returns
    -------
    RoutesResult

    Raises
    ------
    ValueError
        On malformed input or an unknown backend.
    RoutingFailedError
        If a required task cannot be served, or the search found nothing within its limit and
        there is no usable warm start.
    """
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; one of {', '.join(BACKENDS)}")
    if time_limit is not None and not time_limit >= 0:
        raise ValueError(f"time_limit must be >= 0 s or None, got {time_limit!r}")
    t0 = time.perf_counter()
    deadline = None if deterministic or time_limit is None else t0 + float(time_limit)
    inst = RoutingInstance.of(
        dist, starts, ends, prizes, budgets, capacities, allowed, charge_return
    )
    warm = inst.warm_routes(warm_start)
    if inst.n_tasks == 0 or inst.n_vehicles == 0:
        return inst.result([[] for _ in range(inst.n_vehicles)], "feasible", backend)
    if backend == "ortools":
        opts = options if options is not None else OrToolsOptions()
        if not isinstance(opts, OrToolsOptions):
            raise ValueError(f"backend 'ortools' takes OrToolsOptions, got {type(opts).__name__}")
        return solve_ortools(inst, opts, deadline, warm, search_from_warm)
    popts = options if options is not None else PyVRPOptions()
    if not isinstance(popts, PyVRPOptions):
        raise ValueError(f"backend 'pyvrp' takes PyVRPOptions, got {type(popts).__name__}")
    return solve_pyvrp(inst, popts, deadline, warm, search_from_warm)
