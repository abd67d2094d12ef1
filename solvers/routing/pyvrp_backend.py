"""The PyVRP backend of :func:`solvers.routing.solve_routes`.

Model (``pyvrp.ProblemData``, PyVRP >= 0.14): the distinct start/end locations are depots, each
task a client (``required`` for an infinite prize, else optional with ``prize``), each vehicle its
own vehicle type (``num_available=1``, its start and end depot), so that routes map back to
vehicles. PyVRP needs integers: distances are multiplied by ``scale`` and rounded **up**
(``ceil(scale * d)``), prizes rounded to the nearest integer (at least 1), budgets rounded down.
The budget is the route's *duration* (``shift_duration``; the duration matrix is the scaled
distance), because the *distance* matrix is the objective's arc cost, whose legs into end depots
are free when ``charge_return=False``. Capacities (visits) are a load dimension (each client
delivers 1) only when one binds. Tasks only some vehicles may serve: one routing profile per
distinct pattern of allowed tasks, whose matrices put forbidden tasks ``BIG`` away.

Search: PyVRP's iterated local search from the warm start (else from its own random start, made
locally optimal), stopped

* in deterministic mode after ``iterations`` iterations (``pyvrp.stop.MaxIterations``) with the
  fixed ``seed``: PyVRP is single-threaded, so the routes are the same in any process;
* in wall-clock mode at ``wall_fraction`` of the time left before the deadline once the data
  are built, less ``reserve_s`` (``pyvrp.stop.MaxRuntime``; it is checked once an iteration, and
  building the neighbourhoods and the first local optimum come before any check).

PyVRP keeps the best *feasible* solution it found; if it found none (or, with forbidden tasks,
one that breaks the input's rules), the search is treated as having found nothing.

Examples
--------
>>> import numpy as np
>>> from solvers.routing.core import RoutingInstance
>>> xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], dtype=float)
>>> inst = RoutingInstance.of(np.linalg.norm(xy[:, None] - xy[None], axis=2), [0])
>>> sorted(solve_pyvrp(inst, PyVRPOptions(iterations=50), None, None).routes[0])
[1, 2, 3]
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyvrp
from pyvrp.stop import MaxIterations, MaxRuntime

from solvers.routing.core import RoutesResult, RoutingInstance
from solvers.routing.insertion import settle

__all__ = ["PyVRPOptions", "solve_pyvrp"]


@dataclass(frozen=True, slots=True)
class PyVRPOptions:
    """Search settings of the PyVRP backend (see the module docstring).

    Parameters
    ----------
    iterations : int
        Iterated-local-search iterations in deterministic mode.
    seed : int
        PyVRP's random seed (both modes).
    scale : float
        Integer units per distance unit.
    reserve_s : float
        Seconds kept back from the deadline (wall-clock mode) for reading the routes.
    wall_fraction : float
        Share of the time left (after ``reserve_s``) given to ``MaxRuntime``.
    """

    iterations: int = 2000
    seed: int = 0
    scale: float = 10.0
    reserve_s: float = 0.001
    wall_fraction: float = 0.9

    def __post_init__(self) -> None:
        if self.iterations < 0:
            raise ValueError(f"iterations must be >= 0, got {self.iterations!r}")
        if not 0 < self.wall_fraction <= 1:
            raise ValueError(f"wall_fraction must be in (0, 1], got {self.wall_fraction!r}")
        if not self.scale > 0:
            raise ValueError(f"scale must be > 0, got {self.scale!r}")


def solve_pyvrp(
    inst: RoutingInstance,
    opts: PyVRPOptions,
    deadline: float | None,
    warm: list[list[int]] | None,
    from_warm: bool = True,
) -> RoutesResult:
    """Search ``inst`` with PyVRP until ``deadline`` (``perf_counter`` time; None:
    deterministic, ``opts.iterations``), starting from ``warm`` (task positions) if given and
    ``from_warm``."""
    data = _data(inst, opts.scale)
    if deadline is None:
        stop: Any = MaxIterations(int(opts.iterations))
    else:
        time_left = deadline - time.perf_counter() - opts.reserve_s
        if time_left <= 0:
            return settle(inst, None, warm, backend="pyvrp", timed_out=True,
                          warm_started=False, work={"iterations": 0})  # fmt: skip
        stop = MaxRuntime(opts.wall_fraction * time_left)
    init = None
    if warm is not None and from_warm:
        init = pyvrp.Solution(data, [pyvrp.Route(data, r, v) for v, r in enumerate(warm) if r])
    # prizes may dwarf distances: PyVRP's penalties on excess duration or load must be able to
    # outweigh a prize, else no penalty makes collecting it infeasible
    max_prize = max((c.prize for c in data.clients()), default=0)
    params = pyvrp.SolveParams(
        penalty=pyvrp.PenaltyParams(
            max_penalty=max(pyvrp.PenaltyParams().max_penalty, 10.0 * max_prize)
        )
    )
    res = pyvrp.solve(data, stop, seed=int(opts.seed), collect_stats=False, params=params,
                      initial_solution=init)  # fmt: skip
    routes: list[list[int]] | None = None
    if res.best.is_feasible():
        routes = [[] for _ in range(inst.n_vehicles)]
        for route in res.best.routes():
            routes[route.vehicle_type()] = [a.idx for a in route if a.type == _CLIENT]
        if inst.fit(routes) != routes:  # a forbidden task (profiles only make it expensive)
            routes = None
    return settle(inst, routes, warm, backend="pyvrp", timed_out=deadline is not None,
                  warm_started=init is not None,
                  work={"iterations": int(res.num_iterations)})  # fmt: skip


_CLIENT = pyvrp.ActivityType.CLIENT


def _data(inst: RoutingInstance, scale: float) -> Any:
    """The ``pyvrp.ProblemData`` of ``inst`` (see the module docstring)."""
    n_v, m = inst.n_vehicles, inst.n_tasks
    depots, inv = np.unique(np.r_[inst.starts, inst.ends], return_inverse=True)
    n_d = len(depots)
    locs = np.r_[depots, inst.tasks]
    dur = np.ceil(inst.dist[np.ix_(locs, locs)] * scale - 1e-9).astype(np.int64)
    np.fill_diagonal(dur, 0)
    cost = dur.copy()
    s_dep, e_dep = inv[:n_v], inv[n_v:]
    if not inst.charge_return:
        cost[:, np.unique(e_dep)] = 0
    load = bool((inst.visits < m).any())
    prize = np.clip(np.rint(np.where(inst.required, 0, inst.prize) * scale), 1, 2**40)
    required = inst.required.tolist()
    clients = [
        pyvrp.Client(
            location=n_d + j, delivery=[1] if load else [], prize=0 if required[j] else int(p),
            required=required[j],
        )
        for j, p in enumerate(prize.tolist())
    ]  # fmt: skip
    patterns, profile = np.unique(inst.ok, axis=0, return_inverse=True)
    profile = profile.reshape(-1)
    if inst.ok.all():
        dists, durs = [cost], [dur]
    else:
        # a forbidden task costs more than any route and any prize (never worth a visit), and
        # takes longer than any budget
        big = int(dur.max()) * (m + 2) + int(prize.max()) + 1
        dists, durs = [], []
        for row in patterns:
            far = np.r_[np.zeros(n_d, bool), ~row]
            for mat, out in ((cost, dists), (dur, durs)):
                prof = np.where(far[:, None] | far[None, :], big, mat)
                np.fill_diagonal(prof, 0)
                out.append(prof)
    direct = dur[s_dep, e_dep]
    shift = np.where(np.isfinite(inst.budget), np.floor(inst.budget * scale + 1e-9), -1)
    vehicle_types = []
    for v in range(n_v):
        kw: dict[str, Any] = {}
        if shift[v] >= 0:
            kw["shift_duration"] = int(max(shift[v], direct[v]))
        if load:
            kw["capacity"] = [int(inst.visits[v])]
        if len(dists) > 1:
            kw["profile"] = int(profile[v])
        vehicle_types.append(
            pyvrp.VehicleType(1, start_depot=int(s_dep[v]), end_depot=int(e_dep[v]), **kw)
        )
    return pyvrp.ProblemData(
        [pyvrp.Location(0.0, 0.0) for _ in locs],
        clients,
        [pyvrp.Depot(location=d) for d in range(n_d)],
        vehicle_types,
        dists,
        durs,
    )
