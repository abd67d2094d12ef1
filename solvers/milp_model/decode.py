"""From solution vectors to plans, and from any scheduler's plan back to the model's objective."""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.taskgraph import TaskGraph, TaskKind
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.types import AUX, MilpModel, MilpParams

__all__ = ["decode_plan", "plan_objective"]


def decode_plan(
    model: MilpModel, x: np.ndarray, graph: TaskGraph, stats: object | None = None
) -> Plan:
    """Turn a solution vector into a :class:`Plan`.

    Routes list each agent's chosen tasks in slot order; agents with nothing chosen are not
    mentioned (they keep their current route). Agents with a camera fly at ``watch_altitude``
    when their route starts with a fire task and at ``search_altitude`` otherwise (clipped to
    their bounds), as greedy does.

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
    x = np.asarray(x, dtype=np.float64)
    chosen = np.flatnonzero((x > 0.5) & (model.var_kind != AUX))
    chosen = chosen[np.lexsort((model.var_slot[chosen], model.var_agent[chosen]))]
    agents = model.var_agent[chosen]
    tasks = model.var_task[chosen]
    p = model.params
    routes: dict[str, tuple[str, ...]] = {}
    alts: dict[str, float] = {}
    for a in np.unique(agents):
        ks = tasks[agents == a]
        aid = graph.agent_ids[a]
        routes[aid] = tuple(graph.task_ids[k] for k in ks)
        if graph.agent_can_sense[a]:
            z = p.watch_altitude if graph.task_kind[ks[0]] == TaskKind.FIRE else p.search_altitude
            alts[aid] = graph.clip_altitude(a, z)
    return Plan(routes=routes, altitudes=alts, stats=stats)


def plan_objective(
    graph: TaskGraph, plan: Plan, params: MilpParams | None = None
) -> tuple[float, bool]:
    """Score any scheduler's plan on this MILP's objective (for cross-scheduler comparisons).

    The model is built without candidate pruning (every task is a candidate), each agent's first
    ``slots`` route entries become the matching variables (``DUMP`` for agents with water on
    fires, ``WATCH`` for camera agents on fires, ``SEARCH`` on blocks), and each coupling variable
    is set to 1 exactly when its rows allow it (the best choice, its coefficient being positive).
    Route entries with no variable (beyond the conservative battery rows' pre-filter) add nothing.

    Returns
    -------
    objective : float
        ``c @ x`` of the encoded plan.
    feasible : bool
        Whether the encoded plan satisfies every row of the model (a plan may break rows that
        only this model imposes, e.g. the search spread rows; its gap to the MILP bound is then
        not meaningful).

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> from fcplan.scheduling import make_scheduler
    >>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
    >>> obj, ok = plan_objective(g, make_scheduler("milp").plan(g, time_limit=5.0, rng=None))
    >>> bool(np.isclose(obj, make_scheduler("milp").plan(g, time_limit=5.0, rng=None).stats.objective))
    True
    """
    p = params or MilpParams()
    p = MilpParams(
        **{**_asdict(p), "fire_candidates": graph.n_tasks, "search_candidates": graph.n_tasks}
    )
    model = build_milp_model(graph, p)
    x = np.zeros(model.n_vars)
    lookup = {
        (int(a), int(k), int(s)): i
        for i, (a, k, s) in enumerate(
            zip(model.var_agent, model.var_task, model.var_slot, strict=True)
        )
        if model.var_kind[i] != AUX
    }
    for agent, route in plan.routes.items():
        a = graph.agent_index[agent]
        for s, task in enumerate(route[: p.slots]):
            i = lookup.get((a, graph.task_index[task], s))
            if i is not None:
                x[i] = 1.0
    aux = np.flatnonzero(model.var_kind == AUX)
    x[aux] = 1.0
    slack = model.b_ub - model.A_ub @ x
    bad_rows = np.flatnonzero(slack < -1e-9)
    if bad_rows.size and aux.size:
        rows_aux = model.A_ub[bad_rows][:, aux]
        x[aux[np.unique(rows_aux.nonzero()[1])]] = 0.0
    feasible = bool(np.all(model.A_ub @ x <= model.b_ub + 1e-9))
    return float(model.c @ x), feasible


def _asdict(p: MilpParams) -> dict[str, Any]:
    return {f: getattr(p, f) for f in p.__dataclass_fields__}
