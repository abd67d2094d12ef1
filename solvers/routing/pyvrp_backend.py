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

Perturbation: on a tour (one vehicle through required tasks only: a TSP or shortest Hamiltonian
path) each iteration perturbs 3 to 40 moves (:data:`TOUR_PERTURBATION`) instead of PyVRP's
default 1 to 25. It was chosen on 5-6 seeds per instance, where it reached 0-0.78 % above the
optimum on att48, eil51 and berlin52 at 0.1 s (default: up to 1.74 %) and 0-0.37 % on st70, eil76,
kroA100 and rd100 at 1 s (default: up to 1.29 %, kroA100's plateau). Ten seeds at 1 CPU second
later showed a trade-off, not a winner: (3, 40) keeps kroA100 and rd100 at 0 % but leaves eil76
at 1.04 % on average and 1.67 % at worst, while (1, 25) keeps eil76 within 0.93 % and leaves
kroA100 at up to 2.66 %; no range tried keeps both within 1 % on every seed
(``bench_tsplib.py --perturbations``). On the scheduler's prize-collecting models the default was
better at equal CPU (0.13 % against 0.22-0.28 % above the best found), so it stays there
(``bench/README.md``).

Two phases on a tour: the search's budget (iterations, or the wall-clock run time) is split in
halves; the second half is a new search (seed ``seed + 1``) started from the best solution of
the first, i.e. one restart from the incumbent (:data:`TOUR_PHASES`). Chosen on the validation
set of TSPLIB instances that the target table does not contain (pr76, kroC100, kroD100, eil101,
lin105; ``bench_tsplib.py --cpu-limits 0.1 1 --seeds 20 --first-seed 10 --instances validation
--phases 1 2 3``): at 1 CPU second two phases took eil101 from 0.70 % on average and 1.59 % at
worst to 0.36 % and 0.48 %, and kept the other four at 0.00-0.01 %; three were no better than
two (eil101 0.33 % / 1.11 %); at 0.1 CPU s the phases neither helped nor hurt on average over
the five (0.85 % one phase, 0.78 % two). The scheduler's prize-collecting models keep one
search (``bench/README.md``, "Two phases on tours").

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
from pyvrp.search import PerturbationParams
from pyvrp.stop import MaxIterations, MaxRuntime

from solvers.routing.core import RoutesResult, RoutingInstance
from solvers.routing.insertion import settle

__all__ = ["TOUR_PERTURBATION", "TOUR_PHASES", "PyVRPOptions", "solve_pyvrp"]

#: Perturbation moves per iteration (least, most) on tours (see the module docstring).
TOUR_PERTURBATION = (3, 40)
#: Searches a tour's budget is split into, each from the previous one's best (module docstring).
TOUR_PHASES = 2


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
    perturbation : tuple of int, optional
        Least and most perturbation moves per iteration of the iterated local search (PyVRP's
        ``PerturbationParams``). None: :data:`TOUR_PERTURBATION` on a tour (one vehicle through
        required tasks only), PyVRP's default ``(1, 25)`` otherwise (module docstring).
    """

    iterations: int = 2000
    seed: int = 0
    scale: float = 10.0
    reserve_s: float = 0.001
    wall_fraction: float = 0.9
    perturbation: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        if self.iterations < 0:
            raise ValueError(f"iterations must be >= 0, got {self.iterations!r}")
        if not 0 < self.wall_fraction <= 1:
            raise ValueError(f"wall_fraction must be in (0, 1], got {self.wall_fraction!r}")
        if not self.scale > 0:
            raise ValueError(f"scale must be > 0, got {self.scale!r}")
        lo, hi = self.perturbation if self.perturbation is not None else (0, 1)
        if not 0 <= lo <= hi or hi < 1:
            raise ValueError(
                f"perturbation must be (lo, hi) with 0 <= lo <= hi and hi >= 1, "
                f"got {self.perturbation!r}"
            )


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
    if deadline is not None and deadline - time.perf_counter() - opts.reserve_s <= 0:
        return _out_of_time(inst, warm)  # (before building the data)
    data = _data(inst, opts.scale)
    phases = TOUR_PHASES if _is_tour(inst) else 1
    run_s = 0.0  # wall-clock mode: the search's run time
    if deadline is not None:
        time_left = deadline - time.perf_counter() - opts.reserve_s
        if time_left <= 0:
            return _out_of_time(inst, warm)
        run_s = opts.wall_fraction * time_left
    init = None
    if warm is not None and from_warm:
        init = pyvrp.Solution(data, [pyvrp.Route(data, r, v) for v, r in enumerate(warm) if r])
    # prizes may dwarf distances: PyVRP's penalties on excess duration or load must be able to
    # outweigh a prize, else no penalty makes collecting it infeasible
    max_prize = max((c.prize for c in data.clients()), default=0)
    params = pyvrp.SolveParams(
        penalty=pyvrp.PenaltyParams(
            max_penalty=max(pyvrp.PenaltyParams().max_penalty, 10.0 * max_prize)
        ),
        perturbation=PerturbationParams(*_perturbation(inst, opts)),
    )
    best, iterations, start = None, 0, init
    for phase in range(phases):
        if deadline is None:  # the iterations split as evenly as they go
            n = int(opts.iterations)
            stop: Any = MaxIterations(n // phases + (phase < n % phases))
        else:
            stop = MaxRuntime(run_s / phases)
        seed = (int(opts.seed) + phase) % 2**32
        res = pyvrp.solve(data, stop, seed=seed, collect_stats=False, params=params,
                          initial_solution=start)  # fmt: skip
        iterations += int(res.num_iterations)
        if best is None or _better(res.best, best):
            best = res.best
        start = best
    assert best is not None
    routes: list[list[int]] | None = None
    if best.is_feasible():
        routes = [[] for _ in range(inst.n_vehicles)]
        for route in best.routes():
            routes[route.vehicle_type()] = [a.idx for a in route if a.type == _CLIENT]
        if inst.fit(routes) != routes:  # a forbidden task (profiles only make it expensive)
            routes = None
    return settle(inst, routes, warm, backend="pyvrp", timed_out=deadline is not None,
                  warm_started=init is not None,
                  work={"iterations": iterations})  # fmt: skip


_CLIENT = pyvrp.ActivityType.CLIENT


def _better(a: Any, b: Any) -> bool:
    """Whether PyVRP solution ``a`` beats ``b``: feasible first, then the lower cost (arc costs
    and the prizes of unvisited clients: the models set no fixed or duration costs)."""
    if a.is_feasible() != b.is_feasible():
        return bool(a.is_feasible())
    return bool(_cost(a) < _cost(b))


def _cost(sol: Any) -> int:
    return int(sol.distance_cost() + sol.duration_cost() + sol.fixed_vehicle_cost()
               + sol.uncollected_prizes())  # fmt: skip


def _is_tour(inst: RoutingInstance) -> bool:
    """One vehicle through required tasks only (a TSP or shortest Hamiltonian path)."""
    return inst.n_vehicles == 1 and bool(inst.required.all()) and inst.visits[0] >= inst.n_tasks


def _perturbation(inst: RoutingInstance, opts: PyVRPOptions) -> tuple[int, int]:
    """The perturbation range for ``inst`` (resolves ``None``, see :class:`PyVRPOptions`)."""
    if opts.perturbation is not None:
        return opts.perturbation
    return TOUR_PERTURBATION if _is_tour(inst) else (1, 25)


def _out_of_time(inst: RoutingInstance, warm: list[list[int]] | None) -> RoutesResult:
    """The result of a call whose time ran out before any search (the time-limit rule)."""
    return settle(inst, None, warm, backend="pyvrp", timed_out=True, warm_started=False,
                  work={"iterations": 0})  # fmt: skip


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
