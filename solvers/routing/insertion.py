"""Cheapest insertion: complete routes that a search cut by the clock left unfinished.

For a task ``k`` left out, a vehicle ``v`` and an arc ``(a, b)`` of its path (start, tasks, end),
inserting ``k`` lengthens the route by ``d[a, k] + d[k, b] - d[a, b]`` and costs that much, or
``d[a, k]`` when ``b`` is the end and the closing leg is free (``charge_return=False``). It is
feasible when the vehicle may serve ``k``, has a visit left and the longer route fits its budget,
and it pays when its cost is below the prize ``p_k`` (a required task always pays). Each step
makes the insertion of largest gain ``p_k - cost`` until none pays: the result is a local optimum
for single insertions, which a route cut short by a time-out is not.

Examples
--------
>>> import numpy as np
>>> from solvers.routing.core import RoutingInstance
>>> xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], dtype=float)
>>> dist = np.linalg.norm(xy[:, None] - xy[None], axis=2)
>>> inst = RoutingInstance.of(dist, starts=[0], ends=[3])  # tasks: locations 1 and 2
>>> complete_by_insertion(inst, [[]])  # positions into inst.tasks
([[0, 1]], True)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from solvers.routing.core import TOL, RoutesResult, RoutingInstance

__all__ = ["complete_by_insertion", "settle"]


def complete_by_insertion(
    inst: RoutingInstance, routes: Sequence[Sequence[int]]
) -> tuple[list[list[int]], bool]:
    """``(routes, changed)``: ``routes`` (task positions, feasible) completed by cheapest
    insertion (see the module docstring).

    Required tasks go first (the cheapest feasible insertion of any of them), then the
    insertion of largest gain. Each vehicle keeps, per task, its cheapest feasible insertion;
    after an insertion only that vehicle's row is recomputed, so a step costs one pass over one
    route's arcs and the free tasks (ties: the lower vehicle, then task, then position).
    """
    out = [list(r) for r in routes]
    n_v, m = inst.n_vehicles, inst.n_tasks
    used = np.zeros(m, dtype=bool)
    for r in out:
        used[r] = True
    length = np.array([inst.route_legs(v, r).sum() for v, r in enumerate(out)])
    cost = np.full((n_v, m), np.inf)  # cheapest feasible insertion of each task per vehicle
    where = np.zeros((n_v, m), dtype=np.int64)
    longer = np.zeros((n_v, m))
    for v in range(n_v):
        _row(inst, out[v], v, length[v], used, cost, where, longer)
    changed = False
    while True:
        fits = np.isfinite(cost)
        must = fits & inst.required[None, :]
        if must.any():  # required tasks first, cheapest first
            flat = int(np.argmin(np.where(must, cost, np.inf)))
        else:
            gain = np.where(fits, inst.prize[None, :] - np.where(fits, cost, 0.0), -np.inf)
            flat = int(np.argmax(gain))
            if not gain.flat[flat] > 0:
                break
        v, k = divmod(flat, m)
        out[v].insert(int(where[v, k]), k)
        length[v] += longer[v, k]
        used[k] = changed = True
        cost[:, k] = np.inf
        _row(inst, out[v], v, length[v], used, cost, where, longer)
    return out, changed


def _row(
    inst: RoutingInstance,
    route: list[int],
    v: int,
    length: float,
    used: np.ndarray,
    cost: np.ndarray,
    where: np.ndarray,
    longer: np.ndarray,
) -> None:
    """Vehicle ``v``'s cheapest feasible insertion of every free task into ``route``: its cost
    (inf: none), position and added length go into row ``v`` of ``cost``, ``where``,
    ``longer``."""
    cost[v] = np.inf
    free = np.flatnonzero(~used & inst.ok[v])
    if free.size == 0 or len(route) >= inst.visits[v]:
        return
    d, k_loc = inst.dist, inst.tasks[free]
    path = np.concatenate(([inst.starts[v]], inst.tasks[route], [inst.ends[v]]))
    a, b = path[:-1], path[1:]
    add = d[a[:, None], k_loc[None, :]] + d[k_loc[None, :], b[:, None]] - d[a, b][:, None]
    c = add
    if not inst.charge_return:  # the arc into the end is free: inserting before it costs d[a, k]
        c = add.copy()
        c[-1] = d[a[-1], k_loc]
    c = np.where(length + add <= inst.budget[v] + TOL, c, np.inf)
    best = np.argmin(c, axis=0)
    cols = np.arange(free.size)
    cost[v, free] = c[best, cols]
    where[v, free] = best
    longer[v, free] = add[best, cols]


def settle(
    inst: RoutingInstance,
    routes: Sequence[Sequence[int]] | None,
    warm: list[list[int]] | None,
    *,
    backend: str,
    timed_out: bool,
    warm_started: bool,
    work: dict,
) -> RoutesResult:
    """The result of a search that ended with ``routes`` (task positions; None: nothing found),
    by the time-limit rule of :mod:`solvers.routing.core`: a search cut by the clock is completed
    by insertion, or replaced by the warm start ``warm`` (itself completed by insertion) when
    that is better or the search found nothing; with neither, the routes are built by cheapest
    insertion from empty routes (``from_insertion``)."""
    status = "time_limit" if timed_out else "feasible"
    flags = {"warm_started": warm_started, "work": work}
    if routes is None:
        if warm is None:
            built, _ = complete_by_insertion(inst, [[] for _ in range(inst.n_vehicles)])
            return inst.result(built, "time_limit", backend, from_insertion=True, **flags)
        kept, changed = complete_by_insertion(inst, warm)
        return inst.result(kept, "time_limit", backend, kept_warm_start=True, repaired=changed,
                           **flags)  # fmt: skip
    repaired = False
    if timed_out:
        routes, repaired = complete_by_insertion(inst, routes)
        if warm is not None and sum(inst.evaluate(warm)) < sum(inst.evaluate(routes)):
            return inst.result(warm, status, backend, kept_warm_start=True, **flags)
    return inst.result(routes, status, backend, repaired=repaired, **flags)
