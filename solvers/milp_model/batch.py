"""The route set of every agent at once: the build of :mod:`solvers.milp_model.build`, vectorised
across agents, bit-identical to it.

The readable build (``build_milp_model(..., batched=False)``) enumerates and values one
agent and one kind of route at a time. Each agent costs a fixed few dozen numpy calls (candidate
ranking, route enumeration, the covers of every route's legs, dominance, sparse assembly), so
the build grew by about 2 to 10 ms per agent whatever the model's size, and at the ``scale``
tier's 18-30 agents it alone took two to three times the 0.1 s replan limit (``python
bench/bench_milp_build.py --designs scale-tier``; figures in ``bench/README.md``). Here every step
runs once for all agents:

* **candidates**: one (agents x tasks) score array per kind and a stable sort per row (ties to
  the lower row, as :func:`~solvers.milp_model.routes.top_candidates`); the searchers' straight
  flights to their scored ends are valued by one :func:`~solvers.milp_model.kernels.discounted_pairs`
  call over every searcher's segments (each searcher's blocks in reach, as
  ``BuildContext.near_blocks``), then one dense product per searcher, as the readable build does;
* **enumeration**: agents with the same number of candidates and route length share one
  table of orders (:func:`~solvers.milp_model.routes.enumerate_routes`'s arithmetic on an
  (agents, orders, slots) array);
* **values and covers**: every distinct leg of every route in one
  :func:`~solvers.milp_model.kernels.discounted_pairs` call, each route's cover the maximum
  over its legs, levels rounded as before;
* **dominance**: one :func:`~solvers.milp_model.kernels.dominated_sparse` pass with the agent
  and the kind in each route's key, so groups never mix agents.

The routes come out in the readable build's order (agent by agent; dumps or watches, then
searches; enumeration order within), with the same values, covers and arrival times bit for bit:
``tests/solvers/test_milp_batch.py`` checks whole models against the readable build on episode
and synthetic graphs. With a ``deadline`` the build reads the clock between its steps and
between chunks of the coverage kernel's segments, and gives up (``TimeoutError``) once the
deadline has passed or a stage's end, projected from the chunks done, would pass it.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp_model.build import build_milp_model
>>> g = synthetic_task_graph(6, 30, np.random.default_rng(0))
>>> fast, slow = build_milp_model(g), build_milp_model(g, batched=False)
>>> bool(np.array_equal(fast.c, slow.c)), (fast.A_ub != slow.A_ub).nnz
(True, 0)
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from solvers.milp_model.context import BuildContext, RouteSet, projected_past
from solvers.milp_model.kernels import discounted_pairs, dominated_sparse
from solvers.milp_model.objective import dump_value
from solvers.milp_model.prune import route_keys
from solvers.milp_model.routes import _orders
from solvers.milp_model.types import DUMP, SEARCH, WATCH

__all__ = ["batched_route_set"]


#: Segments valued per call of the coverage kernel when a deadline is set (the clock is read
#: between calls; the pairs do not depend on how the segments are split).
CHUNK_SEGMENTS = 1024


def _check(deadline: float | None, step: str) -> None:
    if deadline is not None and time.perf_counter() > deadline:
        raise TimeoutError(f"the wall-clock limit passed while building the model ({step})")


def _pairs(
    args: tuple[np.ndarray, ...],
    fixed: tuple[np.ndarray, float, float],
    deadline: float | None,
    step: str,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`discounted_pairs` of the segments ``args`` (per-segment arrays in its order:
    p, q, z, lo, hi, speed, t_start, then ``fixed`` = centres, block, horizon, then origin,
    radius). With a ``deadline`` the segments go in chunks, and the build gives up
    (``TimeoutError``) as soon as the deadline has passed, or once 80 % of the stage's length
    projected from the chunks done would end past it, leaving a fallback the time the rest
    would have wasted."""
    centres, block, horizon = fixed

    def value(seg: slice) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p, q, z, lo, hi, speed, t_start, origin, radius = (a[seg] for a in args)
        return discounted_pairs(
            p, q, z, lo, hi, speed, t_start, centres, block, horizon, origin, radius
        )

    n = len(args[0])
    if deadline is None or n <= CHUNK_SEGMENTS:
        out = value(slice(None))
        _check(deadline, step)
        return out
    parts = []
    start = time.perf_counter()
    for lo in range(0, n, CHUNK_SEGMENTS):
        si, bi, val = value(slice(lo, lo + CHUNK_SEGMENTS))
        parts.append((si + lo, bi, val))
        now = time.perf_counter()
        done = min(lo + CHUNK_SEGMENTS, n)
        _check(deadline, step)
        if done < n and projected_past(start, now, done, n, deadline):
            raise TimeoutError(
                f"building the model was projected past the wall-clock limit ({step}: "
                f"{done} of {n} segments in {now - start:.3f} s)"
            )
    return (np.concatenate([q[0] for q in parts]), np.concatenate([q[1] for q in parts]),
            np.concatenate([q[2] for q in parts]))  # fmt: skip


def _smallest(key: np.ndarray, k: int) -> np.ndarray:
    """(S, N) bool: per row the ``k`` smallest of ``key``, ties by column (the first ``k`` of a
    stable ``argsort``, as a set), through ``np.partition`` instead of a sort of every row."""
    n = key.shape[1]
    if k <= 0 or n == 0:
        return np.zeros(key.shape, dtype=bool)
    if k >= n:
        return np.ones(key.shape, dtype=bool)
    cut = np.partition(key, k - 1, axis=1)[:, k - 1 : k]
    below = key < cut
    tie = key == cut
    room = k - below.sum(axis=1, keepdims=True)
    out: np.ndarray = below | (tie & (np.cumsum(tie, axis=1) <= room))
    return out


def _top(score: np.ndarray, allowed: np.ndarray, n: int) -> list[np.ndarray]:
    """Per row, :func:`~solvers.milp_model.routes.top_candidates` of that row."""
    ok = allowed & (score > 0)
    key = np.where(ok, -score, np.inf)
    r, c = np.nonzero(_smallest(key, n) & ok)
    order = np.lexsort((c, key[r, c], r))
    ends = np.cumsum(np.bincount(r, minlength=len(score))).tolist()
    return [c[order[a:b]] for a, b in zip([0, *ends][:-1], ends, strict=True)]


def _enumerate(
    ctx: BuildContext,
    agents: np.ndarray,
    cands: list[np.ndarray],
    lengths: np.ndarray,
    n_first: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The routes of ``agents`` over their candidate lists (``enumerate_routes`` of each, in
    agent order), padded to the model's width: (agent (R,), tasks, arrival (R, W), px (R,))."""
    g, width = ctx.graph, ctx.width
    m = np.array([c.size for c in cands], dtype=np.int64)
    nf = m if n_first is None else n_first
    parts: list[tuple[np.ndarray, ...]] = []
    groups = np.unique(np.c_[m, lengths, nf], axis=0) if len(agents) else np.zeros((0, 3))
    for mg, lg, fg in groups.tolist():
        if mg == 0 or lg < 1:
            continue
        sel = np.flatnonzero((m == mg) & (lengths == lg) & (nf == fg))
        ag = agents[sel]
        cg = np.stack([cands[i] for i in sel.tolist()])  # (G, m)
        order = _orders(mg, lg)
        if n_first is not None:
            order = order[order[:, 0] < fg]
        valid = order >= 0
        idx = np.where(valid, order, 0)
        d_start = g.start_task_distance[ag[:, None], cg]
        d_home = g.task_home_distance[ag[:, None], cg]
        pos = g.task_pos[cg]  # (G, m, 2), pairwise_distance's arithmetic per agent
        dx = pos[:, :, 0, None] - pos[:, None, :, 0]
        dy = pos[:, :, 1, None] - pos[:, None, :, 1]
        dx *= dx
        dy *= dy
        dx += dy
        d_between = np.sqrt(dx, out=dx)
        leg = np.zeros((len(ag), *order.shape))
        leg[:, :, 0] = d_start[:, idx[:, 0]]
        if lg > 1:
            inner = d_between[:, idx[:, :-1], idx[:, 1:]]
            leg[:, :, 1:] = np.where(valid[None, :, 1:], inner, 0.0)
        flown = np.cumsum(leg, axis=2)
        last = idx[np.arange(len(order)), valid.sum(axis=1) - 1]
        px = flown[:, :, -1] + d_home[:, last]
        keep = px <= g.agent_budget_px[ag][:, None]
        speed = np.maximum(g.agent_speed[ag], 1e-9)
        t0 = ctx.roles.t0[ag]
        arrival = np.where(valid[None], t0[:, None, None] + flown / speed[:, None, None], np.nan)
        tasks = np.where(valid[None], cg[:, idx], -1)
        r_ag, r_i = np.nonzero(keep)
        pad = width - lg
        parts.append((
            sel[r_ag],
            np.pad(tasks[r_ag, r_i], ((0, 0), (0, pad)), constant_values=-1),
            np.pad(arrival[r_ag, r_i], ((0, 0), (0, pad)), constant_values=np.nan),
            px[r_ag, r_i],
        ))  # fmt: skip
    if not parts:
        return (np.zeros(0, np.int64), np.zeros((0, width), np.int64), np.zeros((0, width)),
                np.zeros(0))  # fmt: skip
    which = np.concatenate([q[0] for q in parts])
    at = np.argsort(which, kind="stable")  # agent order; each agent's routes in their order
    return (
        agents[which[at]],
        np.concatenate([q[1] for q in parts])[at],
        np.concatenate([q[2] for q in parts])[at],
        np.concatenate([q[3] for q in parts])[at],
    )


class _Agents:
    """Per-agent constants of the build: speeds, one-task arrivals, altitudes, reach."""

    def __init__(self, ctx: BuildContext) -> None:
        g, roles = ctx.graph, ctx.roles
        n = g.n_agents
        self.t0 = roles.t0
        self.speed = np.maximum(g.agent_speed, 1e-9)
        self.raw_speed = g.agent_speed.astype(np.float64)
        self.direct = roles.t0[:, None] + g.start_task_distance / self.speed[:, None]  # (A, K)
        self.z_watch = np.full(n, np.nan)
        self.z_search = np.full(n, np.nan)
        for a in np.flatnonzero(roles.sensor).tolist():
            self.z_watch[a], self.z_search[a] = ctx.altitudes(a)
        self._ctx = ctx

    def reach(self, agents: np.ndarray, z: np.ndarray, factor: float = 1.0) -> np.ndarray:
        """``BuildContext.near_blocks``'s radius for ``agents`` at altitudes ``z``."""
        return self._ctx.reach(agents, z, factor)


def _scored_ends(
    ctx: BuildContext, ag: _Agents, searchers: np.ndarray, max_ends: int
) -> tuple[np.ndarray, np.ndarray]:
    """(S, B) blocks in each searcher's sight and the blocks scored as ends of its flights."""
    g = ctx.graph
    z = ag.z_search[searchers]
    rel = ctx.block_pos[None, :, :] - g.agent_start_pos[searchers][:, None, :]
    d = np.hypot(rel[..., 0], rel[..., 1])
    seen = d <= ag.reach(searchers, z)[:, None]
    ends = d <= ag.reach(searchers, z, factor=2.0)[:, None]
    many = np.flatnonzero(ends.sum(axis=1) > max_ends)
    if many.size:  # the nearest ends and those of most value per second, as the readable build
        rows = searchers[many]
        eta = ag.t0[rows, None] + g.start_task_distance[rows][:, ctx.blocks] / ag.speed[rows, None]
        in_end = ends[many]
        proxy = ctx.block_value[None, :] / (1.0 + eta)
        half = max_ends // 2
        pick = _smallest(np.where(in_end, eta, np.inf), half)
        pick |= _smallest(np.where(in_end, -proxy, np.inf), half)
        ends[many] = pick & in_end
    return seen, ends


def _search_candidates(
    ctx: BuildContext, ag: _Agents, searchers: np.ndarray, max_ends: int, deadline: float | None
) -> tuple[list[np.ndarray], np.ndarray]:
    """Each searcher's candidate blocks (task rows, near ones first) and how many are near."""
    g, p = ctx.graph, ctx.p
    seen, ends = _scored_ends(ctx, ag, searchers, max_ends)
    s_row, s_end = np.nonzero(ends)  # one straight flight per (searcher, end), searcher-major
    who = searchers[s_row]
    z = ag.z_search[who]
    si, bi, val = _pairs(
        (g.agent_start_pos[who], ctx.block_pos[s_end], z, g.agent_alt_range[who, 0],
         g.agent_alt_range[who, 1], ag.raw_speed[who], ag.t0[who], g.agent_start_pos[who],
         ag.reach(who, z)),
        (ctx.block_pos, float(p.search_block_px), p.search_horizon_s), deadline, "search ends",
    )  # fmt: skip
    first_seg = np.searchsorted(s_row, np.arange(len(searchers) + 1))
    first_pair = np.searchsorted(si, first_seg)  # pairs come ordered by segment
    score = np.zeros((len(searchers), g.n_tasks))
    for r in range(len(searchers)):
        e_rows, seen_rows = np.flatnonzero(ends[r]), np.flatnonzero(seen[r])
        a, b = first_pair[r], first_pair[r + 1]
        dense = np.zeros((e_rows.size, seen_rows.size))  # the readable build's (ends, seen)
        dense[si[a:b] - first_seg[r], np.searchsorted(seen_rows, bi[a:b])] = val[a:b]
        score[r, ctx.blocks[e_rows]] = dense @ ctx.block_value[seen_rows]
    ok = ctx.roles.ok1[searchers] & ~ctx.fire[None, :]
    close = ag.direct[searchers] <= (ag.t0[searchers] + p.search_reach_s)[:, None]
    near = _top(score, ok & close, p.search_candidates)
    far = _top(score, ok, p.search_candidates)
    cands = [np.r_[n_, f_[~np.isin(f_, n_)]] for n_, f_ in zip(near, far, strict=True)]
    return cands, np.array([n_.size for n_ in near], dtype=np.int64)


def _covers(
    ctx: BuildContext, ag: _Agents, agent: np.ndarray, tasks: np.ndarray, arrival: np.ndarray,
    alt: np.ndarray, deadline: float | None,
) -> sp.csr_array:  # fmt: skip
    """(R, B) cover levels of every route (``route_cover`` of each agent and kind, rounded)."""
    g, p = ctx.graph, ctx.p
    n_r, n_b = len(agent), ctx.blocks.size
    sensing = ctx.roles.sensor[agent]
    legs_r, legs_j = np.nonzero((tasks >= 0) & sensing[:, None])
    if legs_r.size == 0 or n_b == 0:
        return sp.csr_array((n_r, n_b), dtype=np.int64)
    to = g.task_pos[tasks[legs_r, legs_j]]
    prev = tasks[legs_r, np.maximum(legs_j - 1, 0)]
    first = legs_j == 0
    frm = np.where(first[:, None], g.agent_start_pos[agent[legs_r]], g.task_pos[prev])
    t_start = np.where(first, ag.t0[agent[legs_r]], arrival[legs_r, np.maximum(legs_j - 1, 0)])
    # legs repeat across routes: a leg is fixed by its agent, altitude and the route's tasks up to
    # it (they fix where it starts and when), so each distinct prefix is valued once
    base = g.n_tasks + 1
    prefix = np.c_[agent[legs_r] * 2 + (alt[legs_r] == ag.z_search[agent[legs_r]]),
                   np.where(legs_j[:, None] >= np.arange(tasks.shape[1]), tasks[legs_r] + 1, 0)]  # fmt: skip
    if 2 * g.n_agents * base ** tasks.shape[1] < 2**62:  # one int64 per prefix: a 1-D sort
        key = prefix[:, 0]
        for j in range(1, prefix.shape[1]):
            key = key * base + prefix[:, j]
        _, first_leg, inv = np.unique(key, return_index=True, return_inverse=True)
    else:
        _, first_leg, inv = np.unique(prefix, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    u_agent = agent[legs_r[first_leg]]
    si, bi, val = _pairs(
        (frm[first_leg], to[first_leg], alt[legs_r[first_leg]], g.agent_alt_range[u_agent, 0],
         g.agent_alt_range[u_agent, 1], ag.raw_speed[u_agent], t_start[first_leg],
         g.agent_start_pos[u_agent], ag.reach(u_agent, alt[legs_r[first_leg]])),
        (ctx.block_pos, float(p.search_block_px), p.search_horizon_s), deadline, "covers",
    )  # fmt: skip
    n_legs = first_leg.size
    first_pair = np.searchsorted(si, np.arange(n_legs + 1))
    k = np.diff(first_pair)[inv]
    rr = np.repeat(legs_r, k)
    at = np.repeat(first_pair[inv], k) + (np.arange(rr.size) - np.repeat(np.cumsum(k) - k, k))
    cell = rr * n_b + bi[at]
    order = np.argsort(cell, kind="stable")
    cell, share = cell[order], val[at][order]
    if cell.size == 0:
        return sp.csr_array((n_r, n_b), dtype=np.int64)
    heads = np.flatnonzero(np.r_[True, cell[1:] != cell[:-1]])
    best = np.maximum.reduceat(share, heads)  # the best of the route's legs, per block
    level = np.floor(p.cover_levels * best + 0.5).astype(np.int64)
    on = level != 0
    cell = cell[heads][on]
    return sp.csr_array((level[on], (cell // n_b, cell % n_b)), shape=(n_r, n_b))


def batched_route_set(ctx: BuildContext, prune: bool, deadline: float | None) -> RouteSet:
    """The routes of every agent (see the module docstring): the readable build's
    ``RouteSet``, bit for bit."""
    g, p, roles = ctx.graph, ctx.p, ctx.roles
    ag = _Agents(ctx)
    all_tasks = np.arange(g.n_tasks)
    found = []
    dumpers = np.flatnonzero(roles.dumper)
    if dumpers.size:
        score = dump_value(g, p, ctx.weight, all_tasks, ag.direct[dumpers])
        cands = _top(score, roles.ok1[dumpers] & ctx.fire[None, :], p.fire_candidates)
        length = np.minimum(p.slots, roles.tank[dumpers])
        found.append((DUMP, *_enumerate(ctx, dumpers, cands, length, None)))
    watchers = np.flatnonzero(roles.sensor & ~roles.dumper)
    if watchers.size:
        score = dump_value(g, p, ctx.weight, all_tasks, ag.direct[watchers])
        cands = _top(score, roles.ok1[watchers] & ctx.fire[None, :], p.watch_candidates)
        found.append((WATCH, *_enumerate(ctx, watchers, cands, np.ones_like(watchers), None)))
    _check(deadline, "fire routes")
    searchers = np.flatnonzero(roles.sensor) if ctx.blocks.size else np.zeros(0, np.int64)
    if searchers.size:
        cands, n_near = _search_candidates(ctx, ag, searchers, p.max_scored_ends, deadline)
        slots = np.full(searchers.size, p.search_slots)
        found.append((SEARCH, *_enumerate(ctx, searchers, cands, slots, n_near)))
    _check(deadline, "search routes")
    width = ctx.width
    agent = np.concatenate([np.zeros(0, np.int64), *(f[1] for f in found)])
    kind = np.concatenate(
        [np.zeros(0, np.int8), *(np.full(len(f[1]), f[0], np.int8) for f in found)]
    )
    order = np.argsort(agent * 2 + (kind == SEARCH), kind="stable")  # the readable build's order
    agent, kind = agent[order], kind[order]
    tasks = np.concatenate([np.zeros((0, width), np.int64), *(f[2] for f in found)])[order]
    arrival = np.concatenate([np.zeros((0, width)), *(f[3] for f in found)])[order]
    length = np.concatenate([np.zeros(0), *(f[4] for f in found)])[order]
    value = np.zeros(len(agent))
    dump = kind == DUMP
    if dump.any():
        t = tasks[dump]
        fire_only = np.where((t >= 0) & ctx.fire[np.maximum(t, 0)], t, -1)
        value[dump] = dump_value(g, p, ctx.weight, fire_only, arrival[dump]).sum(axis=1)
    alt = np.where(kind == SEARCH, ag.z_search[agent], ag.z_watch[agent])
    cover = _covers(ctx, ag, agent, tasks, arrival, alt, deadline)
    _check(deadline, "covers")
    keep = np.ones(len(agent), dtype=bool)
    if prune and len(agent):
        search = kind == SEARCH
        keys = np.where(search[:, None], route_keys(tasks, by_first=True),
                        route_keys(tasks, by_first=False))  # fmt: skip
        keys = np.c_[agent, kind, keys]
        keep = ~dominated_sparse(keys, value, cover)
    return RouteSet(
        agent=agent[keep], kind=kind[keep], tasks=tasks[keep], arrival=arrival[keep],
        length=length[keep], value=value[keep], altitude=alt[keep],
        cover=cover[keep] if not keep.all() else cover,
    )  # fmt: skip
