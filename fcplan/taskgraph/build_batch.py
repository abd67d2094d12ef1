"""The task graphs of many worlds at once: the batched kernel of
:meth:`fcplan.taskgraph.TaskGraphBuilder.build`.

:func:`build_graphs` returns, for each world, the graph its own builder would build from its
team and belief (bit for bit, views included: ``tests/taskgraph/test_build_batch.py``). The
builder stays the specification; here the parts of a graph with known fire that are numpy work
on ragged sets run once for all the worlds, on flat arrays with a world index:

* the known cells of every world binned into tiles by one stable sort of ``world * tiles +
  tile`` (within a world, the builder's own sort) and segment reductions (``reduceat``) for the
  tiles' bounding boxes, cell counts and last sightings;
* the facility threat's distances and closeness, and the known cells near each search block
  (one ``bincount`` with a per-world offset: sums of whole cell counts, exact in any order)
  and the search values.

The connected-fire labels of all worlds come from one :func:`scipy.ndimage.label` of their tile
grids stacked (what :func:`~fcplan.taskgraph.clusters.label_tiles` numbers, per world; the
builders' label memos are neither read nor filled). Per world remain: the threat's matrix
product (each world's own rows, so that the product is the builder's), the task ids (strings),
the per-graph arrays and distance tables and the graph itself; and every graph without known
fire (the builder's own path, already cheap).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from fcplan.taskgraph.build import (
    TaskGraphBuilder,
    _neighbours,
    _rect_distance,
    graph_fields,
    penalty_weighted,
    tile_keys,
    tile_runs,
    unique_ids,
)
from fcplan.taskgraph.clusters import EIGHT_CONNECTED
from fcplan.taskgraph.types import TaskGraph

__all__ = ["build_graphs"]


def build_graphs(
    builders: Sequence[TaskGraphBuilder], teams: Sequence[Any], beliefs: Sequence[Any]
) -> list[TaskGraph]:
    """``[builders[i].build(teams[i], beliefs[i]) for i ...]``, the graphs with known fire of
    builders of the same scenario and parameters computed together (module docstring)."""
    out: list[TaskGraph | None] = [None] * len(builders)
    fire: list[int] = []
    ref = None
    for i, (bld, team, bel) in enumerate(zip(builders, teams, beliefs, strict=True)):
        if bel.known.size:
            tc = bld._team_consts(team)
            tile = bld.params.tile_px or tc.tile
            key = (bld.scenario, bld.params, float(tile[0]), float(tile[1]))
            if ref is None:
                ref = key
            if key == ref:
                fire.append(i)
                continue
        out[i] = bld.build(team, bel)
    if fire:
        graphs = _fire_graphs(
            [builders[i] for i in fire], [teams[i] for i in fire], [beliefs[i] for i in fire]
        )
        for i, g in zip(fire, graphs, strict=True):
            out[i] = g
    return out  # type: ignore[return-value]


def _tiles(
    bld: TaskGraphBuilder, beliefs: Sequence[Any], tile: tuple[float, float]
) -> tuple[np.ndarray, ...]:
    """``TaskGraphBuilder._fire_tiles`` of every world: (n, 2) tile centres, (n,) cell counts,
    staleness, world of each tile, tile x and y, and the (m + 1,) cuts of the worlds' tiles."""
    m = len(beliefs)
    w = bld._w
    tw, th = tile
    ntx = int(np.ceil(w / tw))
    nty = int(np.ceil(w / th)) + 1
    known = [b.known for b in beliefs]
    sizes = np.array([k.size for k in known], dtype=np.int64)
    allk = np.concatenate(known)
    seen_all = np.concatenate([b.last_seen_at(k) for b, k in zip(beliefs, known, strict=True)])
    kx, ky = np.divmod(allk, w)
    key = tile_keys(kx, ky, tile, nty)
    n_tiles = ntx * nty
    key += np.repeat(np.arange(m, dtype=np.int64) * n_tiles, sizes)
    order, ks, starts, pos, counts = tile_runs(key, kx, ky)  # by world, then the builder's order
    last = np.maximum.reduceat(seen_all[order], starts)
    world, tkey = np.divmod(ks[starts], n_tiles)
    ticks = np.array([b.tick for b in beliefs], dtype=np.int64)
    stale = (ticks[world] - last) / bld._tps
    tile_x, tile_y = np.divmod(tkey, nty)
    cuts = np.searchsorted(world, np.arange(m + 1))
    return pos, counts, stale, world, tile_x, tile_y, cuts, np.array([ntx, nty])


def _fire_graphs(
    builders: Sequence[TaskGraphBuilder], teams: Sequence[Any], beliefs: Sequence[Any]
) -> list[TaskGraph]:
    """The graphs of worlds with known fire (``TaskGraphBuilder._fire_fields``, batched)."""
    bld = builders[0]
    m, nb, blk = len(builders), bld._nb, bld._blk
    tcs = [b._team_consts(t) for b, t in zip(builders, teams, strict=True)]
    tile0 = bld.params.tile_px or tcs[0].tile
    tile = (float(tile0[0]), float(tile0[1]))
    pos, counts, stale, world, tile_x, tile_y, cuts, (ntx, nty) = _tiles(bld, beliefs, tile)
    consts, radius = bld._consts, bld.params.threat_radius_px
    n_fac = len(consts.fac_pos)
    if n_fac:
        d_fac = _rect_distance(pos, consts.fac_rect)
        close = np.minimum(np.maximum(1.0 - d_fac / radius, 0.0), 1.0)
        speed = max(0.24 * consts.max_fuel * 10.0, 1e-9)
        threat_time = np.where(d_fac < radius, d_fac / speed, np.inf)
    else:
        threat_time = np.full((len(pos), 0), np.inf)
    fbxy = pos // blk
    np.minimum(fbxy, nb - 1, out=fbxy)
    fb = (fbxy @ (nb, 1.0)).astype(np.int64)
    nbb = nb * nb + 1
    near = np.bincount(
        (_neighbours(nb)[fb] + (world * nbb)[:, None]).ravel(),
        weights=np.repeat(counts, 9),
        minlength=m * nbb,
    ).reshape(m, nbb)[:, : nb * nb]
    ages = np.stack([b.coverage_age_s(blk).ravel() for b in beliefs])
    search_value = np.minimum(ages, bld.params.search_value_cap_s) * (
        1.0 + np.minimum(near, 50) / 10.0
    )
    ids = [f"fire:{x}:{y}" for x, y in pos.astype(np.int64).tolist()]
    clusters = _labels(world, tile_x, tile_y, cuts, int(ntx), int(nty))
    known_cells = np.add.reduceat(counts, cuts[:-1]).tolist()
    out = []
    for j, (b, team, bel, tc) in enumerate(zip(builders, teams, beliefs, tcs, strict=True)):
        s, e = int(cuts[j]), int(cuts[j + 1])
        fire_ids = unique_ids(ids[s:e])
        cluster = clusters[s:e]
        threat = penalty_weighted(close[s:e], consts.fac_pen) if n_fac else np.zeros(e - s)
        agent_pos = team.pos.copy()
        fields, views = graph_fields(
            b, tc, agent_pos, pos[s:e], counts[s:e], stale[s:e], cluster, threat,
            threat_time[s:e], fb[s:e], ages[j], search_value[j], fire_ids, known_cells[j],
        )  # fmt: skip
        out.append(b._finish(team, tc, bel.tick, agent_pos, tile, fields, views))
    return out


def _labels(world: np.ndarray, tx: np.ndarray, ty: np.ndarray, cuts: np.ndarray, ntx: int,
            nty: int) -> np.ndarray:  # fmt: skip
    """Every world's :func:`fcplan.taskgraph.clusters.label_tiles` of its tiles (in raster order
    within each world) by one :func:`scipy.ndimage.label` of the worlds' tile grids stacked
    with an empty row between two worlds (no tile of one touches another's): scipy numbers the
    components by their first tile in raster order, so a world's components are numbered in its
    own order after the earlier worlds' and its labels are the global ones minus its first."""
    from scipy.ndimage import label

    rows = world * (ntx + 1) + tx
    grid = np.zeros((int(world[-1]) + 1) * (ntx + 1) * (nty + 1), dtype=bool)
    grid[rows * (nty + 1) + ty] = True
    labels, _ = label(grid.reshape(-1, nty + 1), structure=EIGHT_CONNECTED)
    out: np.ndarray = labels[rows, ty].astype(np.int64)
    out -= np.repeat(out[cuts[:-1]], np.diff(cuts))
    return out
