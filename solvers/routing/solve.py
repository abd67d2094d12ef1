"""``solve_routes``: one prize-collecting routing problem on a distance matrix, by either backend.

The model, the instance checks and the time-limit rule are in :mod:`solvers.routing.core`; this
module picks the backend (:mod:`solvers.routing.ortools_backend` or
:mod:`solvers.routing.pyvrp_backend`) and hands it the instance, so that the core imports no
backend and no backend imports this dispatcher.

Examples
--------
>>> import numpy as np
>>> d = np.array([[0, 1, 2], [1, 0, 1], [2, 1, 0]], dtype=float)
>>> solve_routes(d, starts=[0], deterministic=True).routes
((1, 2),)
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from solvers.routing.core import BACKENDS, RoutesResult, RoutingInstance
from solvers.routing.ortools_backend import OrToolsOptions, solve_ortools
from solvers.routing.pyvrp_backend import PyVRPOptions, solve_pyvrp

__all__ = ["solve_routes"]


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
