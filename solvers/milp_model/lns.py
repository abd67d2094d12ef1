"""Large-neighbourhood search (LNS) on a route model too large to solve at once.

Starting from a complete solution (the warm start), each round frees the routes of a few agents
near one another (a *neighbourhood*: the agent chosen as its seed and the agents whose starts are
nearest to it, as many as fit in ``max_routes`` routes), fixes every other route, and solves the
restricted model exactly (:func:`solvers.milp_model.decompose.restrict`; the backend's own work
limit per round). A better restricted solution replaces the current one, so the objective never
falls and every intermediate solution is feasible: the search can stop at any round.

Seeds are taken in a seeded random order, skipping agents that a neighbourhood solved without
improvement since the last improvement already held: once every agent is in such a
neighbourhood no single move can improve (the solution is a local optimum for these
neighbourhoods) and the search stops (``converged``). It also stops after ``rounds`` rounds or at
the wall-clock ``deadline``. Nearby agents compete for the same fires and search blocks, so
neighbourhoods of neighbours hold the interactions that matter; far-apart agents interact
through nothing (or the model splits into parts, :func:`solvers.milp_model.decompose.components`).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp import solve_cpsat
>>> from solvers.milp_model import build_milp_model
>>> from solvers.milp_model.start import initial_solution
>>> g = synthetic_task_graph(12, 40, np.random.default_rng(0))
>>> m = build_milp_model(g)
>>> x0 = initial_solution(m, g, {})
>>> res = large_neighbourhood_search(
...     m, x0, g.agent_start_pos, lambda sub, hint: solve_cpsat(sub, hint=hint),
...     max_routes=150, rounds=20, seed=0)
>>> bool(m.is_feasible(res.x)), m.objective(res.x) >= m.objective(x0), res.stopped
(True, True, 'converged')
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fcplan.scheduling import SolveStats
from solvers.milp_model.decompose import restrict
from solvers.milp_model.types import IncompletePlanError, MilpModel

__all__ = ["LnsResult", "SubSolve", "large_neighbourhood_search"]

#: ``solve(model, hint) -> (x, stats)``: one exact solve of a restricted model (may raise when
#: :class:`~solvers.milp_model.types.IncompletePlanError` when it finds nothing within its
#: limits; the round then changes nothing).
SubSolve = Callable[[MilpModel, np.ndarray], tuple[np.ndarray, SolveStats]]


@dataclass(frozen=True)
class LnsResult:
    """The outcome of a search."""

    x: np.ndarray  # (n,) the best solution found
    rounds: int  # neighbourhoods solved
    improved: int  # rounds that improved the solution
    work: float  # the sub-solves' own work (CP-SAT deterministic seconds), summed
    stopped: str  # "converged", "rounds" or "deadline"


def _neighbourhood(
    model: MilpModel, agents: np.ndarray, pos: np.ndarray, seed_agent: int, max_routes: int
) -> np.ndarray:
    """Agents nearest to ``seed_agent`` (itself first) while their routes fit ``max_routes``."""
    d = np.hypot(*(pos[agents] - pos[seed_agent]).T)
    order = agents[np.lexsort((agents, d))]
    counts = np.bincount(model.route_agent, minlength=int(pos.shape[0]))[order]
    n = max(1, int(np.searchsorted(np.cumsum(counts), max_routes, side="right")))
    out: np.ndarray = order[:n]
    return out


def large_neighbourhood_search(
    model: MilpModel,
    x0: np.ndarray,
    positions: np.ndarray,
    solve: SubSolve,
    *,
    max_routes: int,
    rounds: int,
    seed: int,
    deadline: float | None = None,
) -> LnsResult:
    """Improve the feasible solution ``x0`` of ``model`` by re-solving neighbourhoods (module
    docstring); ``positions`` (A, 2) are the agents' start positions (by agent row)."""
    x = np.asarray(x0, dtype=np.float64).copy()
    agents = np.unique(model.route_agent)
    if agents.size == 0:
        return LnsResult(x, 0, 0, 0.0, "converged")
    order = agents[np.random.default_rng(seed).permutation(agents.size)]
    covered = np.zeros(int(positions.shape[0]), dtype=bool)
    done = improved = 0
    work = 0.0
    stopped = "rounds"
    while done < rounds:
        if deadline is not None and time.perf_counter() > deadline:
            stopped = "deadline"
            break
        left = order[~covered[order]]
        if left.size == 0:
            stopped = "converged"
            break
        hood = _neighbourhood(model, agents, positions, int(left[0]), max_routes)
        free = np.flatnonzero(np.isin(model.route_agent, hood))
        sub = restrict(model, free, x)
        now = sub.model.c @ x[sub.cols]
        done += 1
        try:
            xs, stats = solve(sub.model, x[sub.cols])
        except IncompletePlanError:  # nothing found within the round's limit: no move
            covered[hood] = True
            continue
        work += float(stats.size.get("deterministic_time", 0.0))
        if sub.model.c @ xs > now + 1e-9:
            x[sub.cols] = xs
            improved += 1
            covered[:] = False
        covered[hood] = True
    return LnsResult(x, done, improved, work, stopped)
