"""Building the route model of a task graph: routes per agent, their values, the cover and freeze
variables, and the rows (see :mod:`solvers.milp_model`).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> m = build_milp_model(g)
>>> m.n_routes == m.size["routes"], set(m.row_kind) <= {
...     "agent", "dump_once", "watch_once", "search_once", "cover", "freeze_dump",
...     "freeze_watch"}
(True, True)
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence

import numpy as np
import scipy.sparse as sp

from fcplan.taskgraph import TaskGraph
from fcplan.taskgraph.types import pairwise_distance
from solvers.milp_model.batch import batched_route_set
from solvers.milp_model.constraints import model_rows
from solvers.milp_model.context import BuildContext, RouteSet, projected_past
from solvers.milp_model.kernels import dominated
from solvers.milp_model.objective import (
    CELL_RATE,
    FireSnapshot,
    dump_value,
    route_cover,
    straight_cover,
)
from solvers.milp_model.prune import route_keys
from solvers.milp_model.routes import enumerate_routes, top_candidates
from solvers.milp_model.types import (
    COVER,
    DUMP,
    FREEZE,
    OBJECTIVE_SCALE,
    ROUTE,
    SEARCH,
    WATCH,
    MilpModel,
    MilpParams,
)

__all__ = ["build_milp_model"]


def _pad(a: np.ndarray, width: int, fill: float) -> np.ndarray:
    return np.pad(a, ((0, 0), (0, width - a.shape[1])), constant_values=fill)


def _agent_routes(
    ctx: BuildContext, a: int
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """The enumerated routes of agent ``a``: (kind, tasks, arrival, length) per kind."""
    g, p, roles = ctx.graph, ctx.p, ctx.roles
    t0 = float(roles.t0[a])
    speed = max(float(g.agent_speed[a]), 1e-9)
    direct = t0 + g.start_task_distance[a] / speed  # (K,) arrival on a one-task route
    out = []
    if roles.dumper[a]:
        score = dump_value(g, p, ctx.weight, np.arange(g.n_tasks), direct)
        cands = top_candidates(score, roles.ok1[a] & ctx.fire, p.fire_candidates)
        length = min(p.slots, int(roles.tank[a]))
        out.append((DUMP, *enumerate_routes(g, a, cands, length, t0)))
    elif roles.sensor[a]:
        score = dump_value(g, p, ctx.weight, np.arange(g.n_tasks), direct)
        cands = top_candidates(score, roles.ok1[a] & ctx.fire, p.watch_candidates)
        out.append((WATCH, *enumerate_routes(g, a, cands, 1, t0)))
    if roles.sensor[a] and ctx.blocks.size:
        _, z = ctx.altitudes(a)
        seen = ctx.near_blocks(a, z)  # every block with a positive score is among these
        ends = ctx.near_blocks(a, z, factor=2.0)  # heading for a farther block: as for these
        n_ends = p.max_scored_ends
        if ends.size > n_ends:  # the nearest ends and those of most value per second
            eta = t0 + g.start_task_distance[a, ctx.blocks[ends]] / speed
            proxy = ctx.block_value[ends] / (1.0 + eta)
            pick = np.r_[np.argsort(eta, kind="stable")[: n_ends // 2],
                         np.argsort(-proxy, kind="stable")[: n_ends // 2]]  # fmt: skip
            ends = ends[np.unique(pick)]
        score_b = straight_cover(g, a, ctx.block_pos[ends], ctx.blocks[seen], z, t0, p)
        score = np.zeros(g.n_tasks)
        score[ctx.blocks[ends]] = score_b @ ctx.block_value[seen]
        ok = roles.ok1[a] & ~ctx.fire
        near = top_candidates(score, ok & (direct <= t0 + p.search_reach_s), p.search_candidates)
        far = top_candidates(score, ok, p.search_candidates)
        cands = np.r_[near, far[~np.isin(far, near)]]
        first = np.arange(cands.size) < near.size
        out.append((SEARCH, *enumerate_routes(g, a, cands, p.search_slots, t0, first)))
    return out


def _given_routes(
    ctx: BuildContext, a: int, routes: Sequence[Sequence[int]]
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """Agent ``a``'s ``routes`` (task rows) as (kind, tasks, arrival, length) rows: dumps when the
    agent has water and the route starts at a fire, a watch for a camera agent's fire, else a
    search; lengths and arrivals as :func:`enumerate_routes` computes them."""
    g, roles = ctx.graph, ctx.roles
    out = []
    for route in routes:
        rows = np.asarray(route, dtype=np.int64)
        if rows.size == 0:
            continue
        first_fire = bool(ctx.fire[rows[0]])
        kind = DUMP if first_fire and roles.dumper[a] else WATCH if first_fire else SEARCH
        pos = g.task_pos[rows]
        between = pairwise_distance(pos, pos)[np.arange(rows.size - 1), np.arange(1, rows.size)]
        legs = np.r_[g.start_task_distance[a, rows[0]], between]
        flown = np.cumsum(legs)
        arrival = float(roles.t0[a]) + flown / max(float(g.agent_speed[a]), 1e-9)
        px = float(flown[-1] + g.task_home_distance[a, rows[-1]])
        out.append((kind, rows[None, :], arrival[None, :], np.array([px])))
    return out


def _valued(
    ctx: BuildContext,
    a: int,
    kind: int,
    route: tuple[np.ndarray, np.ndarray, np.ndarray],
    prune: bool,
) -> RouteSet:
    """The routes of one agent and kind with their values, altitudes and covers, without the
    dominated ones when ``prune`` (:mod:`solvers.milp_model.prune`)."""
    tasks, arrival, length = route
    g, p = ctx.graph, ctx.p
    n = len(tasks)
    width = max(ctx.width, tasks.shape[1])
    value = np.zeros(n)
    if kind == DUMP:
        fire_only = np.where((tasks >= 0) & ctx.fire[np.maximum(tasks, 0)], tasks, -1)
        value = dump_value(g, p, ctx.weight, fire_only, arrival).sum(axis=1)
    alt = np.full(n, np.nan)
    cover = sp.csr_array((n, ctx.blocks.size), dtype=np.int64)
    if ctx.roles.sensor[a]:
        z_watch, z_search = ctx.altitudes(a)
        z = z_search if kind == SEARCH else z_watch
        alt[:] = z
        near = ctx.near_blocks(a, z)
        t0 = float(ctx.roles.t0[a])
        share = route_cover(g, a, tasks, arrival, ctx.blocks[near], z, t0, p)
        level = np.floor(p.cover_levels * share + 0.5).astype(np.int64)
        rr, bb = np.nonzero(level)
        cover = sp.csr_array((level[rr, bb], (rr, near[bb])), shape=(n, ctx.blocks.size))
    keep = np.ones(n, dtype=bool)
    if prune:
        keep = ~dominated(route_keys(tasks, by_first=kind == SEARCH), value, cover)
    return RouteSet(
        agent=np.full(int(keep.sum()), a, dtype=np.int64),
        kind=np.full(int(keep.sum()), kind, dtype=np.int8),
        tasks=_pad(tasks[keep], width, -1),
        arrival=_pad(arrival[keep], width, np.nan),
        length=length[keep],
        value=value[keep],
        altitude=alt[keep],
        cover=cover[keep] if not keep.all() else cover,
    )


def _route_set(
    ctx: BuildContext,
    given: Mapping[int, Sequence[Sequence[int]]] | None,
    deadline: float | None,
    prune: bool,
) -> RouteSet:
    """The routes of every agent, one agent and kind at a time: the readable build, which
    :func:`solvers.milp_model.batch.batched_route_set` reproduces across agents bit for bit."""
    parts = []
    n = ctx.graph.n_agents
    start = time.perf_counter()
    for a in range(n):
        if deadline is not None and a:
            now = time.perf_counter()
            if now > deadline:
                raise TimeoutError(
                    f"the wall-clock limit passed while enumerating routes (agent {a})"
                )
            if projected_past(start, now, a, n, deadline):
                raise TimeoutError(
                    f"building the model was projected to take {(now - start) * n / a:.3f} s "
                    f"({a} of {n} agents in {now - start:.3f} s), past the wall-clock limit"
                )
        raw = _agent_routes(ctx, a) if given is None else _given_routes(ctx, a, given.get(a, ()))
        parts += [
            _valued(ctx, a, kind, (t, arr, px), prune and given is None)
            for kind, t, arr, px in raw
            if len(t)
        ]
    width = max([ctx.width] + [r.tasks.shape[1] for r in parts])
    if not parts:
        z = np.zeros(0)
        return RouteSet(
            z.astype(np.int64), z.astype(np.int8), np.zeros((0, width), np.int64),
            np.zeros((0, width)), z, z, z, sp.csr_array((0, ctx.blocks.size), dtype=np.int64),
        )  # fmt: skip
    return RouteSet(
        agent=np.concatenate([r.agent for r in parts]),
        kind=np.concatenate([r.kind for r in parts]),
        tasks=np.concatenate([_pad(r.tasks, width, -1) for r in parts]),
        arrival=np.concatenate([_pad(r.arrival, width, np.nan) for r in parts]),
        length=np.concatenate([r.length for r in parts]),
        value=np.concatenate([r.value for r in parts]),
        altitude=np.concatenate([r.altitude for r in parts]),
        cover=sp.vstack([r.cover for r in parts], format="csr"),
    )


def _fire_visits(ctx: BuildContext, rs: RouteSet) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(R, L) connected fire of each route entry (-1: none), and which entries dump on it and
    which sense it (a watch, or a dump by an agent with a camera)."""
    g = ctx.graph
    on = rs.tasks >= 0
    k = np.maximum(rs.tasks, 0)
    cl = np.where(on & ctx.fire[k], g.task_cluster[k], -1)
    dump = (rs.kind == DUMP)[:, None] & (cl >= 0)
    sees = ((rs.kind == WATCH) | ((rs.kind == DUMP) & ctx.roles.sensor[rs.agent]))[:, None]
    return cl, dump, sees & (cl >= 0)


def _freeze(
    ctx: BuildContext, rs: RouteSet, cl: np.ndarray, dump: np.ndarray, sees: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Connected fires with a dump route and a sensing route: labels and coefficients
    ``0.1 q gamma (H - t_c)+^2 / 2``, ``t_c`` the earliest arrival of an agent with water at a
    task of the fire (straight from its start: it depends on the graph only)."""
    g, p, roles = ctx.graph, ctx.p, ctx.roles
    if p.growth_cells_s <= 0 or not dump.any():
        return np.zeros(0, np.int64), np.zeros(0)
    labels = np.intersect1d(np.unique(cl[dump]), np.unique(cl[sees]))
    speed = np.maximum(g.agent_speed, 1e-9)[:, None]
    direct = roles.t0[:, None] + g.start_task_distance / speed  # (A, K)
    direct = np.where(roles.ok1 & roles.dumper[:, None] & ctx.fire[None, :], direct, np.inf)
    per_task = direct.min(axis=0) if len(direct) else np.full(g.n_tasks, np.inf)  # (K,)
    t_first = np.full(labels.size, np.inf)
    mine = np.isin(g.task_cluster, labels)
    np.minimum.at(t_first, np.searchsorted(labels, g.task_cluster[mine]), per_task[mine])
    gap = np.maximum(p.horizon_s - t_first, 0.0)
    coef = CELL_RATE * p.prune_confidence * p.growth_cells_s * gap * gap / 2.0
    return labels.astype(np.int64), coef


def build_milp_model(
    graph: TaskGraph,
    params: MilpParams | None = None,
    *,
    routes: Mapping[int, Sequence[Sequence[int]]] | None = None,
    recent_fire: Sequence[FireSnapshot | tuple[np.ndarray, np.ndarray]] = (),
    deadline: float | None = None,
    prune: bool = True,
    batched: bool = True,
) -> MilpModel:
    """Build the route model of ``graph`` (see :mod:`solvers.milp_model`).

    Parameters
    ----------
    graph : TaskGraph
    params : MilpParams, optional
    routes : mapping of agent row -> sequence of routes (task rows), optional
        Use exactly these routes instead of enumerating them (to score other plans).
    recent_fire : sequence of FireSnapshot or (positions (F, 2), cells (F,))
        The fire tasks of recent graphs (:func:`solvers.milp_model.objective.hidden_cells`);
        the schedulers pass those of the last ``recent_fire_s`` seconds, as
        :class:`~solvers.milp_model.objective.FireSnapshot` that keep their counts.
    deadline : float, optional
        A :func:`time.perf_counter` time: building stops with ``TimeoutError`` once it has
        passed, or once the build, projected from the agents done so far (``batched=False``) or
        from the chunks of segments valued so far (the default), would end past it.
    prune : bool
        Leave out dominated routes (:mod:`solvers.milp_model.prune`; the optimum is the same).
    batched : bool
        Enumerate and value every agent's routes at once (:mod:`solvers.milp_model.batch`,
        default), or one agent at a time (the readable build; the same model bit for bit).

    Raises
    ------
    ValueError
        If the model would hold more than ``params.max_routes`` routes.
    TimeoutError
        If ``deadline`` passed, or was projected to pass, while the routes were being enumerated.
    """
    p = params or MilpParams()
    ctx = BuildContext(graph, p, recent_fire)
    if batched and routes is None:
        rs = batched_route_set(ctx, prune, deadline)
    else:
        rs = _route_set(ctx, routes, deadline, prune)
    if len(rs.agent) > p.max_routes:
        raise ValueError(f"{len(rs.agent)} routes exceed max_routes={p.max_routes}")
    swept = np.unique(rs.cover.indices)
    cl, dump, sees = _fire_visits(ctx, rs)
    labels, freeze_coef = _freeze(ctx, rs, cl, dump, sees)
    n_r, n_b, n_z = len(rs.agent), swept.size, labels.size
    mat, b, families = model_rows(
        rs.agent, rs.tasks, rs.cover[:, swept], cl, dump, sees, labels, rs.kind == SEARCH
    )
    c = np.concatenate([rs.value, ctx.block_value[swept] / p.cover_levels, freeze_coef])
    c = np.round(c * OBJECTIVE_SCALE) / OBJECTIVE_SCALE  # exact for every backend
    size = {
        "variables": int(c.size),
        "routes": int(n_r),
        "covers": int(n_b),
        "freezes": int(n_z),
        "constraints": int(b.size),
        "nonzeros": int(mat.nnz),
        "agents": int(graph.n_agents),
        "tasks": int(graph.n_tasks),
        "fires": int(ctx.fire.sum()),
    }
    return MilpModel(
        c=c.astype(np.float64),
        A_ub=mat,
        b_ub=b,
        ub=np.concatenate([np.ones(n_r), np.full(n_b, float(p.cover_levels)), np.ones(n_z)]),
        var_kind=np.concatenate(
            [np.full(n_r, ROUTE), np.full(n_b, COVER), np.full(n_z, FREEZE)]
        ).astype(np.int8),
        var_ref=np.concatenate([np.arange(n_r), ctx.blocks[swept], labels]).astype(np.int64),
        route_agent=rs.agent,
        route_kind=rs.kind,
        route_tasks=rs.tasks,
        route_arrival=rs.arrival,
        route_length=rs.length,
        route_value=rs.value,
        altitude=rs.altitude,
        row_kind=families,
        agent_ids=graph.agent_ids,
        task_ids=graph.task_ids,
        params=p,
        size=size,
    )
