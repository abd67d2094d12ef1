"""Building task graphs from the team's belief: one :class:`TaskGraphBuilder` per episode.

At every replan the builder turns what the team knows into a :class:`TaskGraph`:

* **fire tasks**: the known burning cells binned into tiles no larger than an action agent's
  field of view (``tile_px``; default 90 % of the smallest action/hybrid view at its working
  altitude), so one dump at the tile's centre reaches every cell of the task. A task sits at the
  centre of its cells' bounding box and carries its cell count, its staleness (seconds since
  any of its cells was last sensed), its threat (penalty-weighted closeness to the facility
  footprints within ``threat_radius_px``; value ``cells * (1 + threat)``), the estimated time
  for it to reach each threatened facility (at the fastest first-tick spread of the scenario's
  fuel), and the connected fire it belongs to (:mod:`fcplan.taskgraph.clusters`);
* **search tasks**: one per grid block (``search_block_px``, 100 px: ``search:D-05``), valued by
  the age of the team's last look (capped at ``search_value_cap_s``) times
  ``1 + min(known cells in the 3 x 3 blocks around it, 50) / 10``;
* the **agents'** own state (the team always knows where it is and what it has left) and the
  **facilities**.

What never changes during an episode is computed once per builder and shared, read-only, by
every graph it builds: the scenario's facilities and depot, the agents' constants (roles,
speeds, altitude bounds, capacities, depot slots; rebuilt if the builder is given another team
object), and, without known fire, the search blocks' fields, their distances to the depot slots
and who can serve them. The agent-task distance tables are filled in at once (every consumer
reads them). Values derived from the shared arrays are kept in the graphs' common
:class:`~fcplan.taskgraph.types.SharedMemo`.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.belief import Belief
>>> world = World().reset(load_scenario(1), seed=0)
>>> belief = Belief(world.scenario)
>>> builder = TaskGraphBuilder(world.scenario)
>>> for _ in range(10):
...     belief.update(world.step())
>>> g = builder.build(world.team, belief)
>>> g.n_agents, g.n_tasks > 0
(4, True)
>>> builder.build(world.team, belief).agent_home is g.agent_home  # shared constants
True
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from fcplan._fast.taskgraph import new_frozen
from fcplan.scenario import Role
from fcplan.taskgraph.clusters import TileClusters
from fcplan.taskgraph.types import (
    SharedMemo,
    TaskGraph,
    TaskGraphParams,
    TaskKind,
    grid_block_name,
    pairwise_distance,
)
from fcplan.team import ACTION_ALTITUDE, DRAIN_PER_PX, fov_half_extent

__all__ = ["TaskGraphBuilder", "build_task_graph", "default_tile"]

_DEFAULT_PARAMS = TaskGraphParams()


def default_tile(team: Any) -> tuple[float, float]:
    """90 % of the smallest dump field of view among the team's action/hybrid agents (px)."""
    acting = np.flatnonzero(team.can_act)
    if acting.size == 0:
        return (54.0, 31.0)
    z = np.where(team.role[acting] == int(Role.ACTION), ACTION_ALTITUDE, team.alt_lo[acting])
    hx, hy = fov_half_extent(z.min())
    return (float(np.floor(1.8 * hx)), float(np.floor(1.8 * hy)))


@dataclass(frozen=True, eq=False)
class _ScenarioConsts:
    """What a task graph needs from a scenario that never changes (read-only arrays)."""

    fac_pos: np.ndarray
    fac_rect: np.ndarray
    fac_pen: np.ndarray
    fac_kinds: tuple[str, ...]
    depot_pos: np.ndarray
    max_fuel: float


def _scenario_consts(scenario: Any) -> _ScenarioConsts:
    facilities = scenario.scored_facilities
    return _ScenarioConsts(
        fac_pos=_frozen(np.array([f.center for f in facilities], dtype=np.float64).reshape(-1, 2)),
        fac_rect=_frozen(
            np.array([f.footprint for f in facilities], dtype=np.float64).reshape(-1, 4)
        ),
        fac_pen=_frozen(np.array([f.penalty for f in facilities], dtype=np.float64)),
        fac_kinds=tuple(f.kind for f in facilities),
        depot_pos=_frozen(np.array(scenario.depot.center, dtype=np.float64)),
        max_fuel=max((r.fuel for r in scenario.regions), default=1.0),
    )


@dataclass(frozen=True, eq=False)
class _TeamConsts:
    """The agent fields of a task graph that never change during a team's life (a team's role,
    altitude bounds, speed, battery and tank capacities and depot slots are set when it is
    built and never written), as read-only arrays shared by every graph of the team; the px
    from each depot slot to each search block and who can serve them; the default tile; and
    the memo of the graphs."""

    team: Any  # the team these are the constants of
    role: np.ndarray
    alt_range: np.ndarray
    speed: np.ndarray
    full_range: np.ndarray
    tank_capacity: np.ndarray
    home: np.ndarray
    can_sense: np.ndarray
    can_act: np.ndarray
    search_home: np.ndarray  # (A, nb * nb) px from each depot slot to each search block
    search_can_do: np.ndarray  # (A, nb * nb) TaskGraph.can_do of a graph without fire
    tile: tuple[float, float]
    memo: SharedMemo


class TaskGraphBuilder:
    """Builds the task graphs of one episode (see the module docstring).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    params : TaskGraphParams, optional
        How the belief is turned into tasks (default: ``TaskGraphParams()``).

    Attributes
    ----------
    scenario : fcplan.scenario.Scenario
    params : TaskGraphParams
    """

    def __init__(self, scenario: Any, params: TaskGraphParams | None = None) -> None:
        self.scenario = scenario
        self.params = p = params or _DEFAULT_PARAMS
        self._w = w = scenario.world_size
        self._tps = scenario.ticks_per_second
        self._consts = _scenario_consts(scenario)
        self._blk = blk = int(p.search_block_px)
        self._nb = nb = -(-w // blk)
        self._search_pos = _search_grid(w, blk)
        self._search_ids = _search_ids(nb, blk)
        self._search_only = _search_only(nb * nb, len(self._consts.fac_pos))
        self._clusters = TileClusters()
        self._team: _TeamConsts | None = None

    def build(self, team: Any, belief: Any) -> TaskGraph:
        """The task graph of the belief's tick.

        Parameters
        ----------
        team : fcplan.team.Team
            The agents' own states (the team always knows where it is and what it has left).
        belief : fcplan.belief.Belief
            What the team knows about the fire and what it has covered.
        """
        tc = self._team_consts(team)
        tick = belief.tick
        search_age = belief.coverage_age_s(self._blk).ravel()  # (nb, nb) [bx, by], raveled
        agent_pos = team.pos.copy()
        tile = self.params.tile_px or tc.tile
        if belief.known.size == 0:  # no known fire: search blocks only
            fields, views = self._search_fields(tc, search_age, agent_pos)
        else:
            tile = (float(tile[0]), float(tile[1]))
            fields, views = self._fire_fields(tc, belief, tile, search_age, agent_pos)
        return self._finish(team, tc, tick, agent_pos, tile, fields, views)

    # ------------------------------------------------------------------ constants
    def _team_consts(self, team: Any) -> _TeamConsts:
        """The constants of ``team``, computed on its first graph (and again for another team)."""
        tc = self._team
        if tc is not None and tc.team is team:
            return tc
        home = _frozen(team.home.copy())
        can_sense = _frozen(team.can_sense.copy())
        search_home = _frozen(pairwise_distance(home, self._search_pos))
        tc = self._team = _TeamConsts(
            team=team,
            role=_frozen(team.role.copy()),
            alt_range=_frozen(_columns(team.alt_lo, team.alt_hi)),
            speed=_frozen(team.speed * self._tps),
            full_range=_frozen(team.battery_capacity / DRAIN_PER_PX),
            tank_capacity=_frozen(team.tank_capacity.copy()),
            home=home,
            can_sense=can_sense,
            can_act=_frozen(team.can_act.copy()),
            search_home=search_home,
            search_can_do=_frozen(np.repeat(can_sense[:, None], search_home.shape[1], axis=1)),
            tile=default_tile(team),
            memo=SharedMemo(),
        )
        return tc

    # ------------------------------------------------------------------ tasks
    def _search_fields(
        self, tc: _TeamConsts, search_age: np.ndarray, agent_pos: np.ndarray
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Task fields and views of a graph without known fire (search blocks only)."""
        fields: dict[str, Any] = dict(self._search_only)
        # min(age, cap) * (1 + min(0, 50) / 10) == min(age, cap): the factor is exactly 1
        fields.update(
            task_ids=self._search_ids,
            task_pos=self._search_pos,
            task_value=np.minimum(search_age, self.params.search_value_cap_s),
            task_staleness=search_age,
            known_cells=0,
        )
        views = {
            "agent_task_distance": pairwise_distance(agent_pos, self._search_pos),
            "task_home_distance": tc.search_home,
            "can_do": tc.search_can_do,
        }
        return fields, views

    def _fire_tiles(
        self, belief: Any, tile: tuple[float, float]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The known cells binned into tiles: (n, 2) tile centres, (n,) cell counts, (n,)
        staleness in s and (n,) connected-fire labels."""
        w = self._w
        tw, th = tile
        ntx = int(np.ceil(w / tw))
        nty = int(np.ceil(w / th)) + 1
        known = belief.known
        kx, ky = np.divmod(known, w)  # known = flat x * W + y
        order, ks, starts, pos, counts = tile_runs(tile_keys(kx, ky, tile, nty), kx, ky)
        seen = belief.last_seen_at(known[order])
        last = np.maximum.reduceat(seen, starts)
        stale = (belief.tick - last) / self._tps
        tile_x, tile_y = np.divmod(ks[starts], nty)
        return pos, counts, stale, self._clusters(tile_x, tile_y, ntx, nty)

    def _threat(self, fire_pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n,) penalty-weighted closeness of each fire tile to the facility footprints and the
        (n, F) estimated time for it to reach each of them (inf beyond the threat radius)."""
        consts, radius = self._consts, self.params.threat_radius_px
        if not len(consts.fac_pos):
            return np.zeros(len(fire_pos)), np.full((len(fire_pos), 0), np.inf)
        d_fac = _rect_distance(fire_pos, consts.fac_rect)
        close = np.minimum(np.maximum(1.0 - d_fac / radius, 0.0), 1.0)
        speed = max(0.24 * consts.max_fuel * 10.0, 1e-9)  # px/s, first-tick spread at wind 5
        return penalty_weighted(close, consts.fac_pen), np.where(
            d_fac < radius, d_fac / speed, np.inf
        )

    def _fire_fields(
        self,
        tc: _TeamConsts,
        belief: Any,
        tile: tuple[float, float],
        search_age: np.ndarray,
        agent_pos: np.ndarray,
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Task fields and views of a graph with known fire: fire tiles, then search blocks."""
        nb = self._nb
        fire_pos, counts, fire_stale, cluster = self._fire_tiles(belief, tile)
        threat, threat_time = self._threat(fire_pos)

        # search value: age (capped) times (1 + nearby known fire)
        fbxy = fire_pos // self._blk
        np.minimum(fbxy, nb - 1, out=fbxy)
        fb = (fbxy @ (nb, 1.0)).astype(np.int64)  # block index bx * nb + by (small whole numbers)
        # the known cells of the blocks around each block, itself included (fire grows across
        # block borders): every tile's cells counted in the 3 x 3 blocks around its own (sums of
        # whole cell counts: exact in any order)
        near_fire = np.bincount(
            _neighbours(nb)[fb].ravel(), weights=np.repeat(counts, 9), minlength=nb * nb + 1
        )[: nb * nb]
        search_value = np.minimum(search_age, self.params.search_value_cap_s) * (
            1.0 + np.minimum(near_fire, 50) / 10.0
        )

        # ids from the truncated position (astype truncates toward zero, as int() does)
        fire_ids = unique_ids([f"fire:{x}:{y}" for x, y in fire_pos.astype(np.int64).tolist()])
        return graph_fields(self, tc, agent_pos, fire_pos, counts, fire_stale, cluster, threat,
                            threat_time, fb, search_age, search_value, fire_ids,
                            int(counts.sum()))  # fmt: skip

    def _finish(
        self,
        team: Any,
        tc: _TeamConsts,
        tick: int,
        agent_pos: np.ndarray,
        tile: tuple[float, float],
        fields: dict[str, Any],
        views: dict[str, Any],
    ) -> TaskGraph:
        """The graph from its task fields and views: the agent and facility fields added."""
        consts = self._consts
        fields.update(
            tick=tick,
            time_s=tick / self._tps,
            world_size=self.scenario.world_size,
            depot_pos=consts.depot_pos,
            agent_ids=team.ids,
            agent_role=tc.role,
            agent_pos=agent_pos,
            agent_z=team.z.copy(),
            agent_alt_range=tc.alt_range,
            agent_speed=tc.speed,
            agent_range=team.range_px(),
            agent_full_range=tc.full_range,
            agent_battery=team.battery.copy(),
            agent_tank=team.tank.copy(),
            agent_tank_capacity=tc.tank_capacity,
            agent_mode=team.mode.copy(),
            agent_home=tc.home,
            agent_can_sense=tc.can_sense,
            agent_can_act=tc.can_act,
            facility_kinds=consts.fac_kinds,
            facility_pos=consts.fac_pos,
            facility_rect=consts.fac_rect,
            facility_penalty=consts.fac_pen,
            tile_px=(float(tile[0]), float(tile[1])),
            comm_range=self.scenario.comm_range,
        )
        views["shared_memo"] = tc.memo
        return new_frozen(TaskGraph, fields, views)


def build_task_graph(
    scenario: Any, team: Any, belief: Any, params: TaskGraphParams | None = None
) -> TaskGraph:
    """Build the task graph from the scenario, the team's own state and the belief.

    ``TaskGraphBuilder(scenario, params).build(team, belief)`` with a builder of its own: to
    build the graphs of a whole episode, keep one :class:`TaskGraphBuilder` (the constants are
    then computed once and shared by its graphs).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    team : fcplan.team.Team
        The agents' own states.
    belief : fcplan.belief.Belief
        What the team knows about the fire and what it has covered.
    params : TaskGraphParams, optional

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> from fcplan.belief import Belief
    >>> world = World().reset(load_scenario(1), seed=0)
    >>> g = build_task_graph(world.scenario, world.team, Belief(world.scenario))
    >>> g.fire_tasks.size, g.n_tasks  # nothing sensed yet: the 12 x 12 search blocks
    (0, 144)
    """
    return TaskGraphBuilder(scenario, params).build(team, belief)


# ---------------------------------------------------------------------- helpers
def _frozen(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only (shared between graphs: a consumer writing to it gets an error)."""
    a.flags.writeable = False
    return a


def _columns(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.stack([a, b], axis=1)`` for two 1-D arrays of the same dtype, cheaper."""
    out = np.empty((len(a), 2), dtype=a.dtype)
    out[:, 0] = a
    out[:, 1] = b
    return out


def _cat_int(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Concatenation as int64 (as ``np.r_[a, b].astype(np.int64)``)."""
    return np.concatenate([a, b]).astype(np.int64, copy=False)


def penalty_weighted(close: np.ndarray, pen: np.ndarray) -> np.ndarray:
    """(P,) threat ``sum_f close[:, f] * pen[f]``, the facilities added in their order with one
    multiply and one add each.

    Not ``close @ pen``: a matrix product runs the CPU's BLAS kernel, whose order of additions,
    fused multiply-adds and alignment-dependent paths differ between machines, so the threats'
    last bits (and the traces' exact digests) differed on an AMD EPYC from the ones recorded on
    another AVX-512 machine with the same numpy (2026-12-02); elementwise IEEE operations are
    the same everywhere.

    Examples
    --------
    >>> penalty_weighted(np.array([[0.5, 1.0], [0.0, 0.25]]), np.array([2.0, 4.0])).tolist()
    [5.0, 1.0]
    """
    out = np.zeros(close.shape[0])
    for f, w in enumerate(pen.tolist()):
        out += close[:, f] * w
    return out


def _rect_distance(points: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(P, F) distance from points to axis-aligned rectangles (0 inside)."""
    x, y = points[:, 0, None], points[:, 1, None]
    # per axis max(lo - p, p - hi, 0): the gap to the rectangle's span (0 inside it)
    dx = np.maximum(rects[:, 0] - x, x - rects[:, 1])
    np.maximum(dx, 0.0, out=dx)
    dy = np.maximum(rects[:, 2] - y, y - rects[:, 3])
    np.maximum(dy, 0.0, out=dy)
    return np.hypot(dx, dy, out=dx)


# The functions below depend on their (integer) arguments only: their answers are kept
# (read-only) for the builders of every episode.


@lru_cache(maxsize=16)
def _neighbours(nb: int) -> np.ndarray:
    """(nb * nb, 9) the blocks of the 3 x 3 neighbourhood of each block of an ``nb x nb`` grid
    (flat ``bx * nb + by``); neighbours off the grid are ``nb * nb`` (read-only)."""
    b = np.arange(nb)
    bx, by = np.meshgrid(b, b, indexing="ij")
    d = np.array([-1, 0, 1])
    nx_ = bx.ravel()[:, None, None] + d[None, :, None]
    ny_ = by.ravel()[:, None, None] + d[None, None, :]
    inside = (nx_ >= 0) & (nx_ < nb) & (ny_ >= 0) & (ny_ < nb)
    return _frozen(np.where(inside, nx_ * nb + ny_, nb * nb).reshape(nb * nb, 9))


@lru_cache(maxsize=16)
def _search_ids(nb: int, blk: int) -> tuple[str, ...]:
    """Ids of the ``nb x nb`` search blocks in task order (x-major): the chess name of the grid
    cell for 100-px blocks (``search:D-05``), else the block's indices (``search:3:4``)."""
    if blk == 100:
        return tuple(f"search:{grid_block_name(a, b)}" for a in range(nb) for b in range(nb))
    return tuple(f"search:{a}:{b}" for a in range(nb) for b in range(nb))


@lru_cache(maxsize=16)
def _search_only(n_search: int, n_fac: int) -> dict[str, np.ndarray]:
    """The task fields of a graph without fire tasks that do not depend on the belief
    (read-only)."""
    minus = np.full(n_search, -1, dtype=np.int64)
    return {
        "task_kind": _frozen(np.full(n_search, int(TaskKind.SEARCH), dtype=np.int8)),
        "task_cells": _frozen(np.zeros(n_search, dtype=np.int64)),
        "task_threat": _frozen(np.zeros(n_search)),
        "task_cluster": _frozen(minus),
        "task_block": minus,
        "threat_time_s": _frozen(np.full((0, n_fac), np.inf)),
    }


@lru_cache(maxsize=16)
def _search_grid(w: int, blk: int) -> np.ndarray:
    """(nb * nb, 2) centres of the search blocks (x-major), clipped to the map (read-only)."""
    nb = -(-w // blk)
    gx, gy = np.meshgrid(np.arange(nb), np.arange(nb), indexing="ij")
    bx, by = gx.ravel(), gy.ravel()
    pos = np.stack(
        [np.minimum((bx + 0.5) * blk, w - 1.0), np.minimum((by + 0.5) * blk, w - 1.0)], axis=1
    )
    return _frozen(pos)


def tile_keys(kx: np.ndarray, ky: np.ndarray, tile: tuple[float, float], nty: int) -> np.ndarray:
    """(n,) int64 row-major tile index of cells at whole-px ``(kx, ky)`` for tiles of
    ``tile = (tw, th)`` px (``ty < nty``): integer floor division for whole-px tiles (the
    default; the same as the float one), else the float division."""
    tw, th = tile
    if tw.is_integer() and th.is_integer() and tw >= 1.0 and th >= 1.0:
        key: np.ndarray = kx // int(tw)
        key *= nty
        key += ky // int(th)
        return key
    out: np.ndarray = (kx // tw).astype(np.int64) * nty + (ky // th).astype(np.int64)
    return out


def tile_runs(
    key: np.ndarray, kx: np.ndarray, ky: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cells grouped into runs of equal ``key`` (their tiles): the stable ``order`` of the
    cells, the sorted keys, the ``starts`` of the runs, each run's centre (the middle of its
    cells' bounding box, ``(lo + hi) / 2`` of whole px: exact) and its cell count."""
    order = np.argsort(key, kind="stable")
    ks = key[order]
    first = np.empty(len(ks), dtype=bool)
    first[:1] = True
    np.not_equal(ks[1:], ks[:-1], out=first[1:])
    starts = first.nonzero()[0]
    xs, ys = kx[order], ky[order]
    pos = np.empty((len(starts), 2))
    np.add(np.minimum.reduceat(xs, starts), np.maximum.reduceat(xs, starts), out=pos[:, 0])
    np.add(np.minimum.reduceat(ys, starts), np.maximum.reduceat(ys, starts), out=pos[:, 1])
    pos /= 2.0
    counts = np.empty_like(starts)  # run lengths: gaps between starts
    np.subtract(starts[1:], starts[:-1], out=counts[:-1])
    counts[-1] = len(ks) - starts[-1]
    return order, ks, starts, pos, counts


def unique_ids(ids: Sequence[str]) -> tuple[str, ...]:
    """``ids`` as a tuple, each suffixed with ``#k`` (its position) when two are equal (two fire
    tiles whose positions truncate to the same point)."""
    out = tuple(ids)
    if len(set(out)) != len(out):
        out = tuple(f"{fid}#{k}" for k, fid in enumerate(out))
    return out


def graph_fields(b: TaskGraphBuilder, tc: Any, agent_pos: np.ndarray, fire_pos: np.ndarray,
                 counts: np.ndarray, fire_stale: np.ndarray, cluster: np.ndarray,
                 threat: np.ndarray, threat_time: np.ndarray, fb: np.ndarray,
                 search_age: np.ndarray, search_value: np.ndarray, fire_ids: tuple[str, ...],
                 known_cells: int) -> tuple[dict[str, Any], dict[str, Any]]:  # fmt: skip
    """A graph's task fields (fire tiles, then ``b``'s search blocks) and its distance views,
    from its fire tiles' positions, cells, staleness, clusters, threats and blocks ``fb`` and
    the blocks' ages and values (:meth:`TaskGraphBuilder._fire_fields` and the batched build,
    :func:`fcplan.taskgraph.build_batch.build_graphs`)."""
    n_fire = len(fire_pos)
    search_pos = b._search_pos
    n_search = len(search_pos)
    task_kind = np.full(n_fire + n_search, int(TaskKind.SEARCH), dtype=np.int8)
    task_kind[:n_fire] = int(TaskKind.FIRE)
    minus_s = b._search_only["task_cluster"]
    task_pos = np.concatenate([fire_pos, search_pos])
    # both (A, K) distance tables in one pass, as TaskGraph._agent_distances computes them
    both = pairwise_distance(np.concatenate([agent_pos, tc.home]), task_pos)
    n_a = len(agent_pos)
    fields = dict(
        task_ids=fire_ids + b._search_ids,
        task_kind=task_kind,
        task_pos=task_pos,
        task_value=np.concatenate([counts * (1.0 + threat), search_value]),
        task_cells=_cat_int(counts, b._search_only["task_cells"]),
        task_staleness=np.concatenate([fire_stale, search_age]),
        task_threat=np.concatenate([threat, np.zeros(n_search)]),
        task_cluster=_cat_int(cluster, minus_s),
        task_block=_cat_int(n_fire + fb, minus_s),
        threat_time_s=threat_time,
        known_cells=known_cells,
    )
    return fields, {"agent_task_distance": both[:n_a], "task_home_distance": both[n_a:]}
