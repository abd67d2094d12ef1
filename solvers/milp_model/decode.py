"""From solution vectors to plans, and from any scheduler's plan back to the model's objective.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> from solvers.milp_model import build_milp_model, brute_force_optimum
>>> m = build_milp_model(g)
>>> x, best = brute_force_optimum(m)
>>> obj, feasible = plan_objective(g, decode_plan(m, x, g))
>>> feasible, bool(np.isclose(obj, best))
(True, True)
"""

from __future__ import annotations

import numpy as np

from fcplan.plan import Plan
from fcplan.taskgraph import TaskGraph, TaskKind
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.routes import agent_roles
from solvers.milp_model.types import MilpModel, MilpParams

__all__ = ["chosen_routes", "decode_plan", "in_route_space", "plan_objective"]


def chosen_routes(model: MilpModel, x: np.ndarray) -> np.ndarray:
    """Rows of the routes set to 1 in ``x``, by agent."""
    y = np.asarray(x, dtype=np.float64)[: model.n_routes] > 0.5
    rows = np.flatnonzero(y)
    out: np.ndarray = rows[np.argsort(model.route_agent[rows], kind="stable")]
    return out


def decode_plan(
    model: MilpModel, x: np.ndarray, graph: TaskGraph, stats: object | None = None
) -> Plan:
    """Turn a solution vector into a :class:`Plan`.

    Each chosen route becomes its agent's route (task ids in visiting order); agents with a
    camera fly at the route's altitude (``watch_altitude`` for a watch route, ``dump_altitude``
    for a hybrid's dump route, the search altitude for a search route, clipped to their bounds). Agents with no route
    chosen are not mentioned (they keep their current route).

    Parameters
    ----------
    model : MilpModel
    x : ndarray, (n,)
        A solution (values are rounded).
    graph : TaskGraph
        The graph the model was built for.
    stats : SolveStats, optional
        Attached to the plan.
    """
    routes: dict[str, tuple[str, ...]] = {}
    alts: dict[str, float] = {}
    for r in chosen_routes(model, x).tolist():
        a = int(model.route_agent[r])
        aid = graph.agent_ids[a]
        tasks = model.route_tasks[r]
        routes[aid] = tuple(graph.task_ids[k] for k in tasks[tasks >= 0].tolist())
        z = float(model.altitude[r])
        if graph.agent_can_sense[a] and np.isfinite(z):
            alts[aid] = graph.clip_altitude(a, z)
    return Plan(routes=routes, altitudes=alts, stats=stats)


def plan_objective(
    graph: TaskGraph, plan: Plan, params: MilpParams | None = None
) -> tuple[float, bool]:
    """Score any scheduler's plan on this model's objective (for cross-scheduler comparisons).

    The model is built with exactly the plan's routes (:func:`build_milp_model` with
    ``routes=``; each agent's route valued as a dump route when it has water and starts at a
    fire, a watch when a camera agent starts at a fire, else a search), all of them chosen, and
    every cover and freeze variable set to its best value.

    Returns
    -------
    objective : float
        ``c @ x`` of the encoded plan.
    feasible : bool
        Whether the plan lies in the model's feasible set: every route has a shape the model
        enumerates (:func:`in_route_space`) and the encoded plan satisfies every row (a plan may
        break rules that only this model imposes, e.g. one watcher per connected fire; its gap
        to the MILP bound is then not meaningful).

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> from fcplan.scheduling import make_scheduler
    >>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
    >>> plan = make_scheduler("milp").plan(g, time_limit=None, rng=None)
    >>> obj, ok = plan_objective(g, plan)
    >>> ok, bool(np.isclose(obj, plan.stats.objective))
    (True, True)
    """
    p = params or MilpParams()
    given = {
        graph.agent_index[a]: [[graph.task_index[t] for t in route]]
        for a, route in plan.routes.items()
        if route
    }
    model = build_milp_model(graph, p, routes=given)
    y = np.r_[np.ones(model.n_routes), np.zeros(model.n_vars - model.n_routes)]
    x = model.best_auxiliaries(y)
    shapes = all(in_route_space(graph, p, a, r[0]) for a, r in given.items())
    return model.objective(x), bool(shapes and model.is_feasible(x))


def in_route_space(graph: TaskGraph, params: MilpParams, agent: int, route: list[int]) -> bool:
    """Whether the model could enumerate ``route`` (task rows) for ``agent`` (every task a
    candidate): one kind of task, suited to the role, at most ``slots`` dumps within the tank,
    one watched fire, or at most ``search_slots`` blocks starting within ``search_reach_s``,
    distinct, and flyable (``route_ok``)."""
    roles = agent_roles(graph)
    fire = graph.task_kind[route] == TaskKind.FIRE
    if not route or len(set(route)) != len(route) or 0 < fire.sum() < len(route):
        return False
    if not roles.ok1[agent, route].all() or not graph.route_ok(agent, route):
        return False
    if not fire[0]:
        reach = graph.start_task_distance[agent, route[0]] / graph.agent_speed[agent]
        return len(route) <= params.search_slots and reach <= params.search_reach_s
    if roles.dumper[agent]:
        return len(route) <= min(params.slots, int(roles.tank[agent]))
    return len(route) == 1
