"""Benchmark the routing core on TSPLIB instances with known optima.

Each instance is posed as in MEASUREMENTS.md: one vehicle from city 1 back to city 1, every other
city a required task, the closing leg charged, TSPLIB ``EUC_2D`` distances. Prints the gap to the
published optimum (%) at each wall-time limit for

* ``core-ortools``: :func:`solvers.routing.solve_routes` with ``backend="ortools"`` (defaults);
* ``core-pyvrp``: the same with ``backend="pyvrp"``;
* ``ortools-gls``: OR-Tools' routing library alone, as its TSP guide sets it up
  (``PATH_CHEAPEST_ARC`` then guided local search, no fcplan code);
* ``pyvrp``: PyVRP alone (``pyvrp.Model``, default parameters, seed 0, no fcplan code);

and, with ``--first-solutions``, the core's OR-Tools backend with each first-solution strategy.
With ``--deterministic`` the core runs at its default deterministic work limits instead (OR-Tools:
2,000 solutions; PyVRP: 2,000 iterations) and the CPU seconds each took are printed (a measure
that does not depend on the machine's load).

Usage::

    nice python bench/bench_tsplib.py                          # 0.1 / 1 / 10 s (~6 min)
    nice python bench/bench_tsplib.py --limits 0.1 1 --configs core-ortools core-pyvrp
    nice python bench/bench_tsplib.py --first-solutions --limits 0.1 1
    nice python bench/bench_tsplib.py --deterministic
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from solvers.routing import OrToolsOptions, PyVRPOptions, solve_routes
from solvers.routing.tsplib import OPTIMA, read_coords, tour_length, tsplib_distances

DATA = Path(__file__).resolve().parent.parent / "tests" / "solvers" / "data" / "tsplib"
#: the instances of the table (ulysses22 and att48 are also shipped, for the tests)
INSTANCES = ("eil51", "berlin52", "st70", "eil76", "kroA100", "rd100", "ch130")
CONFIGS = ("core-ortools", "core-pyvrp", "ortools-gls", "pyvrp")
FIRST_SOLUTIONS = (
    "PATH_CHEAPEST_ARC",
    "SAVINGS",
    "CHRISTOFIDES",
    "PARALLEL_CHEAPEST_INSERTION",
    "LOCAL_CHEAPEST_INSERTION",
    "GLOBAL_CHEAPEST_ARC",
)


def core(xy: np.ndarray, dist: np.ndarray, limit: float | None, backend: str, opts=None) -> float:
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


def pyvrp_alone(xy: np.ndarray, dist: np.ndarray, limit: float) -> float:
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
    res = m.solve(MaxRuntime(limit), seed=0, display=False)
    tour = [0] + [a.idx + 1 for r in res.best.routes() for a in r if a.is_client()]
    return tour_length(dist, tour)


def run(name: str, xy: np.ndarray, dist: np.ndarray, limit: float | None) -> float:
    if name == "core-ortools":
        return core(xy, dist, limit, "ortools")
    if name == "core-pyvrp":
        return core(xy, dist, limit, "pyvrp")
    if name == "ortools-gls":
        assert limit is not None
        return ortools_gls(xy, dist, limit)
    if name == "pyvrp":
        assert limit is not None
        return pyvrp_alone(xy, dist, limit)
    return core(xy, dist, limit, "ortools", OrToolsOptions(first_solution=name))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limits", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    ap.add_argument("--configs", nargs="+", default=list(CONFIGS))
    ap.add_argument("--instances", nargs="+", default=list(INSTANCES))
    ap.add_argument("--first-solutions", action="store_true")
    ap.add_argument("--deterministic", action="store_true")
    args = ap.parse_args()
    configs = list(FIRST_SOLUTIONS) if args.first_solutions else args.configs
    print(f"# load average at start: {os.getloadavg()[0]:.2f} (2 cores)")
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
    for limit in args.limits:
        print(f"\n## gap to the optimum (%) at {limit:g} s")
        print(f"{'instance':<9} {'optimum':>7}  {head}")
        for name in args.instances:
            xy, kind = read_coords(DATA / f"{name}.tsp")
            dist = tsplib_distances(xy, kind)
            gaps = [100 * (run(c, xy, dist, limit) / OPTIMA[name] - 1) for c in configs]
            print(f"{name:<9} {OPTIMA[name]:>7}  " + "  ".join(f"{g:>14.2f}" for g in gaps),
                  flush=True)  # fmt: skip
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
