"""Tests for the routing core against TSPLIB's known optima (solvers.routing.tsplib and the
instances shipped in tests/solvers/data/tsplib)."""

from __future__ import annotations

from pathlib import Path

import pytest

from solvers.routing import OrToolsOptions, PyVRPOptions, solve_routes
from solvers.routing.tsplib import OPTIMA, read_tour, read_tsplib, tour_length

DATA = Path(__file__).parent / "data" / "tsplib"

#: deterministic work budgets of the gap test: each backend's default (OR-Tools: 2,000 solutions,
#: 16 s of CPU for the four instances; PyVRP: 2,000 iterations, 1 s)
BUDGETS = {"ortools": OrToolsOptions(), "pyvrp": PyVRPOptions()}


@pytest.mark.parametrize("name", sorted(OPTIMA))
def test_shipped_instances_match_their_published_optima(name):
    """Each shipped instance's optimal tour visits every city once and has exactly the
    published optimal length under TSPLIB's distance (the data and the distance function are
    right)."""
    dist = read_tsplib(DATA / f"{name}.tsp")
    tour = read_tour(DATA / f"{name}.opt.tour")
    assert sorted(tour) == list(range(len(dist)))
    assert tour_length(dist, tour) == OPTIMA[name]


@pytest.mark.parametrize("backend", ["ortools", "pyvrp"])
@pytest.mark.parametrize("name", ["ulysses22", "att48", "eil51", "berlin52"])
def test_tsp_tour_within_1_percent_of_optimum(name, backend):
    """Posed as a TSP (one vehicle from city 1 back to it, every other city required, the
    closing leg charged), the core's tour on TSPLIB instances of 22-52 cities is within 1 % of
    the published optimum at the backend's default deterministic work budget (OR-Tools: 2,000
    solutions; PyVRP: 2,000 iterations), and never below it."""
    dist = read_tsplib(DATA / f"{name}.tsp")
    res = solve_routes(dist, starts=[0], deterministic=True, backend=backend,
                       options=BUDGETS[backend])  # fmt: skip
    assert sorted(res.routes[0]) == list(range(1, len(dist)))
    length = tour_length(dist, [0, *res.routes[0]])
    assert length == res.travel
    assert OPTIMA[name] <= length <= 1.01 * OPTIMA[name]
