"""Tests for the routing core (solvers.routing.solve_routes) on plain distance matrices: optimal
on small instances against brute force, every constraint kept, warm starts, and the time-limit
rule, for both backends."""

from __future__ import annotations

import itertools
import subprocess
import sys

import numpy as np
import pytest

from solvers.routing import (
    OrToolsOptions,
    PyVRPOptions,
    RoutingFailedError,
    solve_routes,
)
from solvers.routing.core import RoutingInstance
from solvers.routing.insertion import complete_by_insertion

BACKENDS = ["ortools", "pyvrp"]


def euclid(pts: np.ndarray) -> np.ndarray:
    return np.linalg.norm(pts[:, None] - pts[None], axis=2)


def random_instance(seed: int, n_v: int, n_t: int, *, shared_depot: bool = False):
    """Locations: the vehicles' starts, their ends, then the tasks, in a 1000 x 1000 square."""
    rng = np.random.default_rng(seed)
    starts = rng.uniform(0, 1000, (n_v, 2))
    ends = starts.copy() if shared_depot else rng.uniform(0, 1000, (n_v, 2))
    pts = np.concatenate([starts, ends, rng.uniform(0, 1000, (n_t, 2))])
    return euclid(pts), np.arange(n_v), n_v + np.arange(n_v), rng


def brute_force(dist, starts, ends, prizes, budgets, caps, allowed, charge_return) -> float:
    """Exact optimum of the core's model by enumerating every assignment of tasks to vehicles
    (or none) and every visiting order."""
    n_v = len(starts)
    tasks = [k for k in range(len(dist)) if k not in set(starts) | set(ends)]

    def best_route(v, subset):
        if not subset:
            return 0.0  # an unused vehicle costs nothing
        if len(subset) > caps[v] or any(not allowed[v, k] for k in subset):
            return np.inf
        best = np.inf
        for order in itertools.permutations(subset):
            path = [starts[v], *order, ends[v]]
            legs = [dist[a, b] for a, b in itertools.pairwise(path)]
            if sum(legs) > budgets[v] + 1e-9:
                continue
            best = min(best, sum(legs) if charge_return else sum(legs[:-1]))
        return best

    best = np.inf
    for owner in itertools.product(range(-1, n_v), repeat=len(tasks)):
        dropped = sum(prizes[k] for k, o in zip(tasks, owner, strict=True) if o < 0)
        if not np.isfinite(dropped):
            continue
        total = dropped
        for v in range(n_v):
            total += best_route(v, tuple(k for k, o in zip(tasks, owner, strict=True) if o == v))
        best = min(best, total)
    return best


def check_feasible(res, dist, starts, ends, budgets, caps, allowed, prizes):
    seen = [k for r in res.routes for k in r]
    assert len(seen) == len(set(seen)), "a task is visited twice"
    for v, r in enumerate(res.routes):
        path = [starts[v], *r, ends[v]]
        length = sum(dist[a, b] for a, b in itertools.pairwise(path))
        assert length <= budgets[v] + 1e-6 or not r, f"vehicle {v}: {length} > {budgets[v]}"
        assert len(r) <= caps[v]
        assert all(allowed[v, k] for k in r)
    assert all(k in seen for k in range(len(dist)) if np.isinf(prizes[k]) and k not in starts)


# ---------------------------------------------------------------------------- optimality
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("seed", range(6))
def test_prize_collecting_routes_are_optimal_on_small_instances(backend, seed):
    """Two vehicles with their own starts and ends, five tasks with random prizes (one
    required), budgets, capacities, a forbidden pair and either return rule: the objective
    equals the brute-force optimum (up to the integer rounding), and the routes keep every
    constraint."""
    dist, starts, ends, rng = random_instance(seed, 2, 5)
    n_loc = len(dist)
    prizes = np.r_[np.zeros(4), rng.uniform(50, 900, 5)]
    prizes[4 + seed % 5] = np.inf
    budgets = rng.uniform(2000, 3500, 2)
    caps = np.array([3, 2])
    allowed = np.ones((2, n_loc), dtype=bool)
    allowed[1, 4 + (seed + 1) % 5] = False
    charge_return = bool(seed % 2)
    res = solve_routes(
        dist, starts=starts, ends=ends, prizes=prizes, budgets=budgets, capacities=caps,
        allowed=allowed, charge_return=charge_return, deterministic=True, backend=backend,
    )  # fmt: skip
    check_feasible(res, dist, starts, ends, budgets, caps, allowed, prizes)
    best = brute_force(dist, starts, ends, prizes, budgets, caps, allowed, charge_return)
    assert res.objective == pytest.approx(best, abs=1.0)
    assert res.objective == pytest.approx(res.travel + res.dropped)
    assert res.status == "feasible" and np.isnan(res.bound)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("n", [5, 7, 9])
def test_open_path_through_required_tasks_is_optimal(backend, n):
    """One vehicle from its start to another end through ``n`` required tasks: the length equals
    the brute-force shortest Hamiltonian path."""
    dist, starts, ends, _ = random_instance(100 + n, 1, n)
    res = solve_routes(dist, starts=starts, ends=ends, deterministic=True, backend=backend)
    perms = np.array(list(itertools.permutations(range(2, 2 + n))))
    paths = np.concatenate([np.zeros((len(perms), 1), int), perms, np.ones((len(perms), 1), int)],
                           axis=1)  # fmt: skip
    best = dist[paths[:, :-1], paths[:, 1:]].sum(axis=1).min()
    assert sorted(res.routes[0]) == list(range(2, 2 + n))
    assert res.travel == pytest.approx(best, rel=1e-9, abs=0.1 * (n + 1))


# ---------------------------------------------------------------------------- constraints
@pytest.mark.parametrize("backend", BACKENDS)
def test_budgets_capacities_and_allowed_vehicles_bind(backend):
    """A task worth less than its detour is dropped, one beyond the budget is never visited
    whatever its prize, the capacity caps the visits, and a task only one vehicle may serve goes
    to that vehicle."""
    pts = np.array([[0, 0], [1000, 0], [100, 0], [0, 300], [5000, 0], [100, 10], [990, 0.0]])
    dist = euclid(pts)
    prizes = np.array([0, 0, 1e5, 10.0, 1e9, 1e5, 1e5])
    allowed = np.ones((2, 7), dtype=bool)
    allowed[0, 6] = False
    kw = {"starts": [0, 1], "prizes": prizes, "budgets": [1000.0, 1000.0], "allowed": allowed,
          "deterministic": True, "backend": backend}  # fmt: skip
    res = solve_routes(dist, **kw)
    assert set(res.routes[0]) == {2, 5} and res.routes[1] == (6,)
    assert res.dropped == pytest.approx(10.0 + 1e9)
    capped = solve_routes(dist, capacities=[1, 1], **kw)
    assert len(capped.routes[0]) == 1 and capped.routes[1] == (6,)


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_closing_leg(backend):
    """With ``charge_return=False`` the leg into the end costs nothing (it still counts against
    the budget): the far task is visited last, and the reported travel leaves that leg out."""
    pts = np.array([[0, 0], [10, 0], [500, 0.0]])
    res = solve_routes(euclid(pts), starts=[0], charge_return=False, deterministic=True,
                       backend=backend)  # fmt: skip
    assert res.routes == ((1, 2),)
    assert res.travel == pytest.approx(500.0)
    tight = solve_routes(euclid(pts), starts=[0], prizes=[0, 1e4, 1e4], budgets=[999.0],
                         charge_return=False, deterministic=True, backend=backend)  # fmt: skip
    assert tight.routes == ((1,),)


def test_empty_inputs_and_bad_arguments():
    """No tasks or no vehicles give empty routes; malformed input raises ValueError; a required
    task nobody can reach raises RoutingFailedError."""
    dist = euclid(np.array([[0, 0], [10, 0.0]]))
    assert solve_routes(dist, starts=[0, 1]).routes == ((), ())
    assert solve_routes(dist, starts=[], prizes=[5.0, 5.0]).routes == ()
    with pytest.raises(ValueError, match="square"):
        solve_routes(np.zeros((2, 3)), starts=[0])
    with pytest.raises(ValueError, match="starts"):
        solve_routes(dist, starts=[5])
    with pytest.raises(ValueError, match="backend"):
        solve_routes(dist, starts=[0], backend="nope")
    with pytest.raises(ValueError, match="OrToolsOptions"):
        solve_routes(dist, starts=[0], options=PyVRPOptions())
    with pytest.raises(ValueError, match="first_solution"):
        OrToolsOptions(first_solution="NOPE")
    with pytest.raises(RoutingFailedError, match="unreachable"):
        solve_routes(dist, starts=[0], budgets=[5.0])


# ---------------------------------------------------------------------------- warm start
@pytest.mark.parametrize("backend", BACKENDS)
def test_warm_start_is_used_and_never_worsened(backend):
    """A warm start (with a foreign location, a duplicate and a route too long for its budget)
    is cut to fit and the search starts from it: the result is flagged ``warm_started`` and is no
    worse than the fitted warm start."""
    dist, starts, ends, rng = random_instance(3, 2, 12)
    prizes = np.r_[np.zeros(4), rng.uniform(100, 600, 12)]
    budgets = np.array([2500.0, 2500.0])
    warm = [[4, 5, 6, 7, 8, 9, 10, 11], [5, 12, 0]]
    inst = RoutingInstance.of(dist, starts, ends, prizes, budgets)
    fitted = inst.warm_routes(warm)
    assert fitted is not None and all(
        inst.route_legs(v, r).sum() <= budgets[v] for v, r in enumerate(fitted)
    )
    assert fitted[1][0] == 12 - 4  # location 5 went to vehicle 0; location 0 is no task
    res = solve_routes(dist, starts=starts, ends=ends, prizes=prizes, budgets=budgets,
                       warm_start=warm, deterministic=True, backend=backend)  # fmt: skip
    assert res.warm_started and not res.kept_warm_start
    assert res.objective <= sum(inst.evaluate(fitted)) + 1e-9


@pytest.mark.parametrize("backend", BACKENDS)
def test_time_out_before_any_search_keeps_the_warm_start_or_builds_by_insertion(backend):
    """With no time left the search cannot run: the (fitted) warm start comes back, completed
    by cheapest insertion, as ``time_limit`` with ``kept_warm_start``; without a warm start the
    routes are cheapest insertion's from empty routes (``from_insertion``): an empty plan is
    never handed back as a decision, and the result is what insertion alone gives."""
    dist, starts, ends, rng = random_instance(4, 2, 20)
    prizes = np.r_[np.zeros(4), np.full(20, 1e4)]
    kw = {"starts": starts, "ends": ends, "prizes": prizes, "backend": backend}
    inst = RoutingInstance.of(dist, starts, ends, prizes)
    res = solve_routes(dist, time_limit=0.0, warm_start=[[4, 5], [6]], **kw)
    assert res.status == "time_limit" and res.kept_warm_start
    kept, _ = complete_by_insertion(inst, inst.warm_routes([[4, 5], [6]]))
    assert res.routes == inst.result(kept, "time_limit", backend).routes
    assert {4, 5, 6} <= {k for r in res.routes for k in r}
    cold = solve_routes(dist, time_limit=0.0, **kw)
    built, _ = complete_by_insertion(inst, [[], []])
    assert cold.status == "time_limit" and cold.from_insertion and not cold.kept_warm_start
    assert cold.routes == inst.result(built, "time_limit", backend).routes
    assert cold.n_visits == 20  # every prize (1e4) is worth its detour


@pytest.mark.parametrize("seed", range(4))
def test_insertion_completes_routes_cut_short(seed):
    """Cheapest insertion turns partial routes into feasible ones that no single feasible
    insertion improves, and serves every required task."""
    dist, starts, ends, rng = random_instance(seed, 3, 25)
    prizes = np.r_[np.zeros(6), rng.uniform(0, 800, 25)]
    prizes[6:9] = np.inf
    budgets, caps = rng.uniform(2500, 4000, 3), np.array([4, 5, 6])
    inst = RoutingInstance.of(dist, starts, ends, prizes, budgets, caps)
    routes, changed = complete_by_insertion(inst, [[3], [], []])
    assert changed
    assert inst.fit(routes) == routes  # feasible as they are
    seen = {k for r in routes for k in r}
    assert set(np.flatnonzero(inst.required)) <= seen
    for k in set(range(inst.n_tasks)) - seen:
        for v, r in enumerate(routes):
            for p in range(len(r) + 1):
                longer = r[:p] + [k] + r[p:]
                if inst.fit([[]] * v + [longer])[v] != longer:
                    continue  # infeasible
                gain = sum(inst.evaluate(routes)) - sum(
                    inst.evaluate(routes[:v] + [longer] + routes[v + 1 :])
                )
                assert gain <= 1e-9, f"inserting task {k} into vehicle {v} at {p} pays {gain}"


# ---------------------------------------------------------------------------- reproducibility
_SCRIPT = """
import numpy as np
from solvers.routing import OrToolsOptions, PyVRPOptions, solve_routes
rng = np.random.default_rng(7)
pts = rng.uniform(0, 1000, (43, 2))
dist = np.linalg.norm(pts[:, None] - pts[None], axis=2)
prizes = np.r_[np.zeros(3), rng.uniform(100, 900, 40)]
for backend, opts in (("ortools", OrToolsOptions(solution_limit=300)),
                      ("pyvrp", PyVRPOptions(iterations=500))):
    res = solve_routes(dist, starts=[0, 1, 2], prizes=prizes, budgets=[3000.0] * 3,
                       capacities=[8, 8, 8], deterministic=True, backend=backend, options=opts)
    print(backend, res.routes, repr(res.objective))
"""


def test_deterministic_mode_is_identical_across_processes():
    """Deterministic mode gives the same routes and objective in two fresh processes and in
    this one (work limits and fixed seeds, nothing read from the clock)."""
    runs = [
        subprocess.run(
            [sys.executable, "-c", _SCRIPT], capture_output=True, text=True, check=True
        ).stdout  # fmt: skip
        for _ in range(2)
    ]
    assert runs[0] == runs[1]
    assert runs[0].count("ortools") == 1 and runs[0].count("pyvrp") == 1


def test_pyvrp_searches_a_tour_in_two_phases_and_keeps_the_better():
    """On a tour (one vehicle through required tasks only) the PyVRP backend splits its
    deterministic budget into TOUR_PHASES searches (their iterations add up to the option's),
    the second started from the first's best, so the result is never worse than one search of
    half the budget; a prize-collecting model runs one search of the whole budget."""
    from solvers.routing import pyvrp_backend
    from solvers.routing.pyvrp_backend import TOUR_PHASES, solve_pyvrp

    assert TOUR_PHASES == 2
    rng = np.random.default_rng(3)
    dist = euclid(rng.uniform(0, 1000, (30, 2)))
    tour = RoutingInstance.of(dist, [0])
    res = solve_pyvrp(tour, PyVRPOptions(iterations=301), None, None)
    assert res.work["iterations"] == 301
    one = pyvrp_backend.TOUR_PHASES
    try:
        pyvrp_backend.TOUR_PHASES = 1
        half = solve_pyvrp(tour, PyVRPOptions(iterations=151), None, None)
    finally:
        pyvrp_backend.TOUR_PHASES = one
    assert res.objective <= half.objective + 1e-9
    prizes = RoutingInstance.of(dist, [0], prizes=np.full(30, 50.0))
    assert solve_pyvrp(prizes, PyVRPOptions(iterations=301), None, None).work["iterations"] == 301
