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

from solvers.routing.core import TOL, RoutesResult, RoutingFailedError, RoutingInstance

__all__ = ["complete_by_insertion", "settle"]


def complete_by_insertion(
    inst: RoutingInstance, routes: Sequence[Sequence[int]]
) -> tuple[list[list[int]], bool]:
    """``(routes, changed)``: ``routes`` (task positions, feasible) completed by cheapest
    insertion (see the module docstring)."""
    out = [list(r) for r in routes]
    d, tasks = inst.dist, inst.tasks
    used = np.zeros(inst.n_tasks, dtype=bool)
    for r in out:
        used[r] = True
    length = np.array([inst.route_legs(v, r).sum() for v, r in enumerate(out)])
    changed = False
    while not used.all():
        free = np.flatnonzero(~used)
        veh, pos, a, b = _arcs(inst, out)
        k_loc = tasks[free]
        longer = d[a[:, None], k_loc[None, :]] + d[k_loc[None, :], b[:, None]] - d[a, b][:, None]
        cost = longer
        if not inst.charge_return:
            closing = pos == np.array([len(out[v]) for v in veh])  # arcs into the end
            cost = np.where(closing[:, None], d[a[:, None], k_loc[None, :]], longer)
        fits = (
            inst.ok[np.ix_(veh, free)]
            & (np.array([len(out[v]) for v in veh]) < inst.visits[veh])[:, None]
            & (length[veh][:, None] + longer <= inst.budget[veh][:, None] + TOL)
        )
        must = fits & inst.required[free][None, :]
        if must.any():  # required tasks first, cheapest first
            gain = np.where(must, -cost, -np.inf)
        else:
            gain = np.where(fits, inst.prize[free][None, :] - cost, -np.inf)
        i, j = np.unravel_index(int(np.argmax(gain)), gain.shape)
        if not (must.any() or gain[i, j] > 0):
            break
        v, k = int(veh[i]), int(free[j])
        out[v].insert(int(pos[i]), k)
        length[v] += longer[i, j]
        used[k] = changed = True
    return out, changed


def _arcs(
    inst: RoutingInstance, routes: list[list[int]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every arc of every vehicle's path: (vehicle, insertion position in its route, from
    location, to location)."""
    veh: list[int] = []
    pos: list[int] = []
    a: list[int] = []
    b: list[int] = []
    for v, r in enumerate(routes):
        path = [int(inst.starts[v]), *(int(inst.tasks[k]) for k in r), int(inst.ends[v])]
        veh += [v] * (len(path) - 1)
        pos += range(len(path) - 1)
        a += path[:-1]
        b += path[1:]
    return np.array(veh), np.array(pos), np.array(a), np.array(b)


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
    by insertion, or replaced by the warm start ``warm`` when that is better or the search found
    nothing; with neither, :class:`~solvers.routing.core.RoutingFailedError` is raised."""
    status = "time_limit" if timed_out else "feasible"
    flags = {"warm_started": warm_started, "work": work}
    if routes is None:
        if warm is None:
            raise RoutingFailedError(
                f"{backend}: no routes for {inst.n_vehicles} vehicles x {inst.n_tasks} tasks "
                "within the limit, and no warm start"
            )
        return inst.result(warm, "time_limit", backend, kept_warm_start=True, **flags)
    repaired = False
    if timed_out:
        routes, repaired = complete_by_insertion(inst, routes)
        if warm is not None and sum(inst.evaluate(warm)) < sum(inst.evaluate(routes)):
            return inst.result(warm, status, backend, kept_warm_start=True, **flags)
    return inst.result(routes, status, backend, repaired=repaired, **flags)
