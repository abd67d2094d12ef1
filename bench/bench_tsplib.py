"""Benchmark the routing core on TSPLIB instances with known optima.

Each instance is posed as in MEASUREMENTS.md: one vehicle from city 1 back to city 1, every other
city a required task, the closing leg charged, TSPLIB ``EUC_2D`` distances. Prints the gap to the
published optimum (%) at each wall-time limit for

* ``core-ortools``: :func:`solvers.routing.solve_routes` with ``backend="ortools"`` (defaults);
* ``core-pyvrp``: the same with ``backend="pyvrp"``;
* ``ortools-gls``: OR-Tools' routing library alone, as its TSP guide sets it up
  (``PATH_CHEAPEST_ARC`` then guided local search, no fcplan code);
* ``pyvrp``: PyVRP alone (``pyvrp.Model``, default parameters, no fcplan code);

With ``--repeats N`` every cell of the wall-clock table is run ``N`` times (the PyVRP configs
with seeds ``0..N-1``, OR-Tools, which has no seed, again: its wall-clock search differs between
runs) and shows the mean and the largest gap: a wall-clock search is a random draw, and one run
does not say whether a target is met typically or by luck. Without it each cell is one run, seed 0.

And, with ``--first-solutions``, the core's OR-Tools backend with each first-solution strategy.
With ``--deterministic`` the core runs at its default deterministic work limits instead (OR-Tools:
2,000 solutions; PyVRP: 2,000 iterations) and the CPU seconds each took are printed (a measure
that does not depend on the machine's load). With ``--cpu-limits`` the core's PyVRP backend
(its model and settings, :func:`solvers.routing.pyvrp_backend.solve_pyvrp`'s parameters) is
stopped on this process's CPU time instead of the wall clock, over ``--seeds`` seeds (mean and
max gap): the time budgets of the targets, measured the same on a loaded machine. OR-Tools has
no CPU-time limit, so it is not in that table.

Usage::

    nice python bench/bench_tsplib.py                          # 0.1 / 1 / 10 s (~6 min)
    nice python bench/bench_tsplib.py --limits 0.1 1 --configs core-ortools core-pyvrp
    nice python bench/bench_tsplib.py --repeats 3                 # mean / max of 3 runs (~18 min)
    nice python bench/bench_tsplib.py --first-solutions --limits 0.1 1
    nice python bench/bench_tsplib.py --deterministic
    nice python bench/bench_tsplib.py --cpu-limits 0.1 1 --seeds 5
    nice python bench/bench_tsplib.py --cpu-limits 1 --seeds 20 --first-seed 10 \
        --instances validation --phases 1 2 3     # choose a setting on the validation set
"""

from __future__ import annotations

import argparse
import itertools
import os
import time
from pathlib import Path

import numpy as np

from solvers.routing import OrToolsOptions, PyVRPOptions, solve_routes
from solvers.routing.tsplib import OPTIMA, read_coords, tour_length, tsplib_distances

DATA = Path(__file__).resolve().parent.parent / "tests" / "solvers" / "data" / "tsplib"
#: the instances of the table (ulysses22 and att48 are also shipped, for the tests)
INSTANCES = ("eil51", "berlin52", "st70", "eil76", "kroA100", "rd100", "ch130")
#: the validation set (``--instances validation``): settings are chosen on these, not the table
VALIDATION = ("pr76", "kroC100", "kroD100", "eil101", "lin105")
CONFIGS = ("core-ortools", "core-pyvrp", "ortools-gls", "pyvrp")
FIRST_SOLUTIONS = (
    "PATH_CHEAPEST_ARC",
    "SAVINGS",
    "CHRISTOFIDES",
    "PARALLEL_CHEAPEST_INSERTION",
    "LOCAL_CHEAPEST_INSERTION",
    "GLOBAL_CHEAPEST_ARC",
)


def core(
    xy: np.ndarray, dist: np.ndarray, limit: float | None, backend: str, opts: object = None
) -> float:
    res = solve_routes(
        dist, starts=[0], time_limit=limit, deterministic=limit is None, backend=backend,
        options=opts,
    )  # fmt: skip
    return tour_length(dist, [0, *res.routes[0]])


def ortools_gls(xy: np.ndarray, dist: np.ndarray, limit: float) -> float:
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2

    manager = pywrapcp.RoutingIndexManager(len(dist), 1, 0)
    model = pywrapcp.RoutingModel(manager)
    cb = model.RegisterTransitMatrix(dist.astype(np.int64).tolist())
    model.SetArcCostEvaluatorOfAllVehicles(cb)
    p = pywrapcp.DefaultRoutingSearchParameters()
    p.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    p.local_search_metaheuristic = routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    p.time_limit.FromMilliseconds(int(limit * 1000))
    sol = model.SolveWithParameters(p)
    idx, tour = model.Start(0), []
    while not model.IsEnd(idx):
        tour.append(manager.IndexToNode(idx))
        idx = sol.Value(model.NextVar(idx))
    return tour_length(dist, tour)


def pyvrp_alone(xy: np.ndarray, dist: np.ndarray, limit: float, seed: int = 0) -> float:
    from pyvrp import Model
    from pyvrp.stop import MaxRuntime

    m = Model()
    locs = [m.add_location(x=float(x), y=float(y)) for x, y in xy]
    m.add_depot(locs[0])
    for loc in locs[1:]:
        m.add_client(loc)
    m.add_vehicle_type(1)
    for i, a in enumerate(locs):
        for j, b in enumerate(locs):
            if i != j:
                m.add_edge(a, b, distance=int(dist[i, j]))
    res = m.solve(MaxRuntime(limit), seed=seed, display=False)
    tour = [0] + [a.idx + 1 for r in res.best.routes() for a in r if a.is_client()]
    return tour_length(dist, tour)


def pyvrp_cpu(
    dist: np.ndarray,
    limit: float,
    seed: int,
    perturbation: tuple[int, int] | None = None,
    phases: int | None = None,
) -> float:
    """The core's PyVRP model and parameters of a tour, stopped after ``limit`` CPU seconds
    (``perturbation``: another (least, most) perturbation range than the core's; ``phases``:
    searches the budget is split into, each from the previous one's best, as the core does)."""
    import pyvrp

    from solvers.routing.core import RoutingInstance
    from solvers.routing.pyvrp_backend import TOUR_PERTURBATION, TOUR_PHASES, _better, _data

    start = time.process_time()
    inst = RoutingInstance.of(dist, [0])
    pert = TOUR_PERTURBATION if perturbation is None else perturbation
    params = pyvrp.SolveParams(perturbation=pyvrp.search.PerturbationParams(*pert))
    data = _data(inst, PyVRPOptions().scale)
    phases = TOUR_PHASES if phases is None else phases
    best = None
    for phase in range(phases):
        until = start + limit * (phase + 1) / phases
        res = pyvrp.solve(data, lambda _, t=until: time.process_time() >= t, seed=seed + phase,
                          collect_stats=False, params=params, initial_solution=best)  # fmt: skip
        if best is None or _better(res.best, best):
            best = res.best
    tour = [0] + [int(inst.tasks[a.idx]) for r in best.routes() for a in r if a.is_client()]
    return tour_length(dist, tour)


def run(name: str, xy: np.ndarray, dist: np.ndarray, limit: float | None, seed: int = 0) -> float:
    """Tour length of config ``name`` at wall-clock ``limit`` (``seed``: the PyVRP configs')."""
    if name == "core-ortools":
        return core(xy, dist, limit, "ortools")
    if name == "core-pyvrp":
        return core(xy, dist, limit, "pyvrp", PyVRPOptions(seed=seed))
    if name == "ortools-gls":
        assert limit is not None
        return ortools_gls(xy, dist, limit)
    if name == "pyvrp":
        assert limit is not None
        return pyvrp_alone(xy, dist, limit, seed)
    return core(xy, dist, limit, "ortools", OrToolsOptions(first_solution=name))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limits", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    ap.add_argument("--configs", nargs="+", default=list(CONFIGS))
    ap.add_argument("--instances", nargs="+", default=list(INSTANCES))
    ap.add_argument("--first-solutions", action="store_true")
    ap.add_argument("--deterministic", action="store_true")
    ap.add_argument("--cpu-limits", type=float, nargs="+")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=1, help="runs of every wall-clock cell")
    ap.add_argument(
        "--perturbations",
        nargs="+",
        default=None,
        metavar="LO,HI",
        help="with --cpu-limits: one table per PyVRP perturbation range",
    )
    ap.add_argument(
        "--phases",
        type=int,
        nargs="+",
        default=None,
        help="with --cpu-limits: one table per number of search phases",
    )
    ap.add_argument("--first-seed", type=int, default=0, help="with --cpu-limits")
    args = ap.parse_args()
    if args.instances == ["validation"]:
        args.instances = list(VALIDATION)
    configs = list(FIRST_SOLUTIONS) if args.first_solutions else args.configs
    print(f"# load average at start: {os.getloadavg()[0]:.2f} (2 cores)")
    if args.cpu_limits:
        ranges: list[tuple[int, int] | None] = [None]  # the core's own range
        if args.perturbations:
            ranges = [(int(r.split(",")[0]), int(r.split(",")[1])) for r in args.perturbations]
        seeds = range(args.first_seed, args.first_seed + args.seeds)
        for pert, phases in itertools.product(ranges, args.phases or [None]):
            what = "" if pert is None else f", perturbation {pert[0]}-{pert[1]}"
            what += "" if phases is None else f", {phases} phase(s)"
            print(f"## core-pyvrp stopped on CPU time{what}: gap (%) mean / max over "
                  f"seeds {seeds.start}-{seeds.stop - 1}")  # fmt: skip
            print(f"{'instance':<9} {'optimum':>7}  " + "  ".join(
                f"{f'{lim:g} cpu s':>14}" for lim in args.cpu_limits))  # fmt: skip
            for name in args.instances:
                xy, kind = read_coords(DATA / f"{name}.tsp")
                dist = tsplib_distances(xy, kind)
                cells = []
                for lim in args.cpu_limits:
                    gaps = [
                        100 * (pyvrp_cpu(dist, lim, s, pert, phases) / OPTIMA[name] - 1)
                        for s in seeds
                    ]
                    cells.append(f"{np.mean(gaps):>6.2f} / {max(gaps):>5.2f}")
                print(f"{name:<9} {OPTIMA[name]:>7}  " + "  ".join(f"{c:>14}" for c in cells),
                      flush=True)  # fmt: skip
        return
    if args.deterministic:
        print(f"{'instance':<9} {'optimum':>7}  " + "  ".join(
            f"{c + ' gap %':>16} {'cpu s':>5}" for c in ("core-ortools", "core-pyvrp")))  # fmt: skip
        for name in args.instances:
            xy, kind = read_coords(DATA / f"{name}.tsp")
            dist = tsplib_distances(xy, kind)
            cells = []
            for backend, opts in (("ortools", OrToolsOptions()), ("pyvrp", PyVRPOptions())):
                t0 = time.process_time()
                length = core(xy, dist, None, backend, opts)
                cells.append(f"{100 * (length / OPTIMA[name] - 1):>16.2f} "
                             f"{time.process_time() - t0:>5.1f}")  # fmt: skip
            print(f"{name:<9} {OPTIMA[name]:>7}  " + "  ".join(cells), flush=True)
        return
    head = "  ".join(f"{c[:14]:>14}" for c in configs)
    n = max(args.repeats, 1)
    for limit in args.limits:
        what = "" if n == 1 else f", mean / max of {n} runs (PyVRP seeds 0-{n - 1})"
        print(f"\n## gap to the optimum (%) at {limit:g} s{what}")
        print(f"{'instance':<9} {'optimum':>7}  {head}")
        for name in args.instances:
            xy, kind = read_coords(DATA / f"{name}.tsp")
            dist = tsplib_distances(xy, kind)
            cells = []
            for c in configs:
                gaps = [100 * (run(c, xy, dist, limit, s) / OPTIMA[name] - 1) for s in range(n)]
                cells.append(f"{gaps[0]:.2f}" if n == 1 else f"{np.mean(gaps):.2f}/{max(gaps):.2f}")
            print(f"{name:<9} {OPTIMA[name]:>7}  " + "  ".join(f"{c:>14}" for c in cells),
                  flush=True)  # fmt: skip
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
